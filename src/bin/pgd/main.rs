//! `pgd`: offline work — organ meshes, vademecum builds and their validation, benchmarks. The
//! options are in `args.rs`; the work is the library's.

mod args;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use args::{
    BenchTarget, BuildArgs, Cli, Command, ContactBenchArgs, HapticsBenchArgs, MaterialArgs,
    MeshArgs, SceneBenchArgs, ValidateArgs,
};
use clap::Parser;
use pgd_surgery::app::scene::{Detail, SCENE_ORGANS, SceneOrgan, press_targets, scene_of};
use pgd_surgery::cli::{self, LoadedMesh, fail, print_json, print_report};
use pgd_surgery::contact::CouplingSettings;
use pgd_surgery::cutting::CutValidationSettings;
use pgd_surgery::cutting::keratotomy::{Cornea, Keratotomy};
use pgd_surgery::devices::PressMotion;
use pgd_surgery::fem::Law;
use pgd_surgery::mesh::organs::Organ;
use pgd_surgery::pgd::{self, ValidationSettings};
use pgd_surgery::scenario::default_law;
use pgd_surgery::store::{Bar, BuildJob, OnStale};
use pgd_surgery::{app, bench};

fn indent_command(
    mesh: &MeshArgs,
    material: &MaterialArgs,
    laws: &[args::LawArg],
    request: &cli::IndentRequest,
    plot: Option<std::path::PathBuf>,
    json: bool,
) -> ExitCode {
    let plot = plot.unwrap_or_else(|| format!("{}-indentation.png", mesh.stem()).into());
    let report = mesh.load().and_then(|loaded| {
        let base = material.material(loaded.organ)?;
        let materials: Vec<_> = laws.iter().map(|law| base.with_law(law.law())).collect();
        let report = cli::indent_organ(loaded, &materials, request, &Bar::default())?;
        cli::plot_indentation(&report, &plot)?;
        Ok(report)
    });
    match report {
        Ok(report) if json => print_json(&report),
        Ok(report) => {
            cli::print_indentation(&report);
            println!("curves drawn in {}", plot.display());
            ExitCode::SUCCESS
        }
        Err(e) => fail("pgd indent", &e),
    }
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Mesh {
            mesh,
            out,
            preview,
            json,
        } => match mesh.load() {
            Ok(loaded) => cli::report_mesh(&cli::MeshReport {
                source: &mesh.source,
                loaded: &loaded,
                out: out.as_deref(),
                preview: preview.as_deref(),
                json,
            }),
            Err(e) => fail("pgd mesh", &e),
        },
        Command::Build {
            mesh,
            material,
            build,
            out,
            distance_field,
            shard,
            json,
        } => {
            let out = out.unwrap_or_else(|| args::default_vademecum(&mesh, material.law.law()));
            if let Some(shard) = shard {
                let command = args::shard_command(std::env::args().skip(1));
                let part = job(&mesh, &material, &build)
                    .and_then(|job| cli::build_part(job, shard, command, &out));
                return print_report("pgd build --shard", part, json);
            }
            let built = job(&mesh, &material, &build)
                .and_then(|job| cli::build_vademecum(job, &out, distance_field));
            print_build("pgd build", built, &out, json)
        }
        Command::Merge {
            parts,
            out,
            distance_field,
            json,
        } => merge_command(&parts, out, distance_field, json),
        Command::Validate(options) => validate_command(options),
        Command::Cut {
            organ,
            incisions,
            optical_zone_mm,
            depth_fraction,
            resolution,
            cornea_layers,
            json,
        } => {
            if organ != "cornea" {
                return fail(
                    "pgd cut",
                    &format!("{organ}: radial keratotomy is defined on the cornea only"),
                );
            }
            let plan = Keratotomy {
                incisions,
                optical_zone_m: optical_zone_mm * 1e-3,
                depth_fraction,
            };
            let report =
                Cornea::new(resolution, cornea_layers).and_then(|cornea| cornea.cut(&plan));
            print_report("pgd cut cornea", report, json)
        }
        Command::Indent {
            mesh,
            material,
            laws,
            at,
            depth_mm,
            steps,
            plot,
            json,
        } => {
            let request = cli::IndentRequest {
                source: &mesh.source,
                at_mm: at,
                depth_mm,
                steps,
            };
            indent_command(&mesh, &material, &laws, &request, plot, json)
        }
        Command::Fit {
            data,
            poisson,
            plot,
            json,
        } => fit_command(&data, poisson, plot, json),
        Command::Bench { what } => bench_command(what),
    }
}

/// A build's report as JSON or as its table, or its error.
fn print_build(
    command: &str,
    built: Result<pgd::BuildReport, String>,
    out: &Path,
    json: bool,
) -> ExitCode {
    match built {
        Ok(report) if json => print_json(&report),
        Ok(report) => {
            cli::print_build_report(&report, out);
            ExitCode::SUCCESS
        }
        Err(e) => fail(command, &e),
    }
}

/// `pgd merge`: the parts read, the model made again from the build arguments they keep, and
/// the vademecum joined from them.
fn merge_command(
    parts: &[PathBuf],
    out: Option<PathBuf>,
    distance_field: bool,
    json: bool,
) -> ExitCode {
    let loaded = match parts
        .iter()
        .map(|p| pgd::load_part(p))
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(loaded) => loaded,
        Err(e) => return fail("pgd merge", &e.to_string()),
    };
    let command = &loaded[0].part.header.command;
    let arguments = std::iter::once("pgd").chain(command.iter().map(String::as_str));
    let Ok(Cli {
        command:
            Command::Build {
                mesh,
                material,
                build,
                ..
            },
    }) = Cli::try_parse_from(arguments)
    else {
        let message = format!(
            "{}: its build arguments ({}) are not a `pgd build` command this version reads; \
             build the parts again",
            parts[0].display(),
            command.join(" ")
        );
        return fail("pgd merge", &message);
    };
    let out = out.unwrap_or_else(|| args::default_vademecum(&mesh, material.law.law()));
    let merged = job(&mesh, &material, &build)
        .and_then(|job| cli::merge_vademecum(job, loaded, &out, distance_field));
    print_build("pgd merge", merged, &out, json)
}

/// `pgd validate`: a vademecum against full FEM, or its cut section against full X-FEM.
fn validate_command(options: ValidateArgs) -> ExitCode {
    let ValidateArgs {
        mesh,
        vademecum,
        law,
        samples,
        sample_seed,
        max_indentation_mm,
        max_tilt_deg,
        curves,
        beyond_range,
        cuts,
        exact_response,
        cut_patch_mm,
        json,
    } = options;
    let file = vademecum.unwrap_or_else(|| args::default_vademecum(&mesh, law.law()));
    if let Some(pattern) = cuts {
        let patch_radius_m = match cut_patch_mm {
            Some(mm) => match args::millimetres("cut-patch-mm", Some(mm), 0.0) {
                Ok(m) => Some(m),
                Err(e) => return fail("pgd validate --cuts", &e),
            },
            None => None,
        };
        let settings = CutValidationSettings {
            pattern,
            samples: samples.unwrap_or(CutValidationSettings::default().samples),
            seed: sample_seed,
            patch_radius_m,
            ..CutValidationSettings::default()
        };
        return validate_cut_section(&mesh, &file, &settings, exact_response, json);
    }
    if !(0.0..90.0).contains(&max_tilt_deg) {
        let problem = format!("--max-tilt-deg {max_tilt_deg}: not in 0 to 90 degrees");
        return fail("pgd validate", &problem);
    }
    let settings = |organ| {
        let defaults = ValidationSettings::for_organ(organ);
        let defaults = ValidationSettings {
            samples: samples.unwrap_or(defaults.samples),
            seed: sample_seed,
            curves,
            max_tilt_deg,
            beyond_range,
            ..defaults
        };
        match max_indentation_mm {
            Some(mm) => defaults.deepest_indentation(mm * 1e-3),
            None => defaults,
        }
    };
    let validated = mesh
        .load()
        .and_then(|loaded| cli::validate_vademecum(&mesh.source, loaded, &file, settings));
    let report = match validated {
        Ok(report) => report,
        Err(e) => return fail("pgd validate", &e),
    };
    match cli::plot_force_depth(&report, &file) {
        Ok(Some(png)) => eprintln!("force-depth curves: {}", png.display()),
        Ok(None) => {}
        Err(e) => return fail("pgd validate", &e),
    }
    if json {
        return print_json(&report);
    }
    cli::print_validation(&report);
    cli::print_force_depth(&report);
    ExitCode::SUCCESS
}

fn fit_command(
    data: &Path,
    poisson: f64,
    plot: Option<std::path::PathBuf>,
    json: bool,
) -> ExitCode {
    let plot = plot.unwrap_or_else(|| data.with_extension("").with_extension("fit.png"));
    let report = cli::fit_uniaxial_test(data, poisson)
        .and_then(|report| cli::plot_fit(&report, &plot).map(|()| report));
    match report {
        Ok(report) if json => print_json(&report),
        Ok(report) => {
            print!("{report}");
            println!("fit drawn in {}", plot.display());
            ExitCode::SUCCESS
        }
        Err(e) => fail("pgd fit", &e),
    }
}

/// `pgd validate --cuts`: the cut section against full X-FEM.
fn validate_cut_section(
    mesh: &MeshArgs,
    file: &Path,
    settings: &CutValidationSettings,
    exact: bool,
    json: bool,
) -> ExitCode {
    let validated = mesh
        .load()
        .and_then(|loaded| cli::validate_cuts(&mesh.source, loaded, file, settings, exact));
    match validated {
        Ok(report) if json => print_json(&report),
        Ok(report) => {
            cli::print_cut_validation(&report);
            ExitCode::SUCCESS
        }
        Err(e) => fail("pgd validate --cuts", &e),
    }
}

/// The build `pgd build` asks for: the mesh loaded, its material and settings resolved.
fn job<'a>(
    mesh: &'a MeshArgs,
    material: &'a MaterialArgs,
    build: &BuildArgs,
) -> Result<BuildJob<'a>, String> {
    let LoadedMesh {
        organ,
        mesh: tet_mesh,
        ..
    } = mesh.load()?;
    Ok(BuildJob {
        source: &mesh.source,
        mesh: tet_mesh,
        material: material.material(organ)?,
        inclusions: &material.inclusion,
        settings: build.settings(organ, material.law.law())?,
        cuts: build.cut_settings(organ)?,
        newton_samples: build.newton_samples,
    })
}

fn bench_command(what: BenchTarget) -> ExitCode {
    match what {
        BenchTarget::Vademecum {
            organ,
            laws,
            repeats,
            json,
        } => {
            let Some(organ) = Organ::from_name(&organ) else {
                return fail(
                    "pgd bench vademecum",
                    &format!(
                        "{organ}: not an organ (liver, gallbladder, pancreas, duodenum, cornea)"
                    ),
                );
            };
            let laws: Vec<Law> = laws.into_iter().map(args::LawArg::law).collect();
            print_report(
                "pgd bench vademecum",
                bench::vademecum::run(organ, &laws, repeats),
                json,
            )
        }
        BenchTarget::Contact(options) => bench_contact(&options),
        BenchTarget::Dynamics {
            modes,
            scene_modes,
            ticks,
            vademecums,
            plot,
            json,
        } => {
            let request = cli::DynamicsRequest {
                organs: &SCENE_ORGANS,
                modes: &modes,
                scene_modes,
                ticks,
                vademecums: &vademecums,
            };
            let result = cli::bench_dynamics(&request).and_then(|report| {
                if let Some(path) = &plot {
                    cli::plot_energy(&report, path)?;
                    eprintln!("wrote {}", path.display());
                }
                Ok(report)
            });
            print_report("pgd bench dynamics", result, json)
        }
        BenchTarget::Frame {
            frames,
            coarse,
            vademecums,
            json,
        } => bench_frame(frames, coarse, &vademecums, json),
        BenchTarget::Haptics(options) => bench_haptics(options),
        BenchTarget::Operation {
            scenario,
            run,
            baseline,
            baseline_run,
            runs,
        } => {
            let operation = app::bench_operation::ScenarioRun { scenario, run };
            let baseline = app::bench_operation::ScenarioRun {
                scenario: baseline,
                run: baseline_run,
            };
            let detail = if runs.coarse {
                Detail::Coarse
            } else {
                Detail::Full
            };
            let report = app::bench_operation::run(
                &operation,
                &baseline,
                &runs.vademecums,
                detail,
                runs.repeats,
            );
            print_report("pgd bench operation", report, runs.json)
        }
        BenchTarget::Scalpel(runs) => bench_scalpel(&runs),
        BenchTarget::Rods { ticks, json } => {
            print_report("pgd bench rods", bench::rods::run(ticks), json)
        }
        BenchTarget::Import {
            triangles,
            nodes,
            repeats,
            stl_out,
            json,
        } => print_report(
            "pgd bench import",
            bench::import::run(triangles, nodes, repeats, stl_out.as_deref()),
            json,
        ),
        BenchTarget::Cutting { cells, json } => print_report(
            "pgd bench cutting",
            bench::cutting::run([cells[0], cells[1], cells[2]]),
            json,
        ),
        BenchTarget::Fem {
            json,
            repeats,
            cells,
        } => {
            let cells = cells.map_or(bench::fem::LIVER_SIZED_CELLS, |c| [c[0], c[1], c[2]]);
            print_report("pgd bench fem", bench::fem::run(cells, repeats), json)
        }
    }
}

/// `pgd bench frame`: the window's per-frame work on the scene, without a window.
fn bench_frame(frames: usize, coarse: bool, vademecums: &Path, json: bool) -> ExitCode {
    let detail = if coarse { Detail::Coarse } else { Detail::Full };
    let organs = SCENE_ORGANS.map(SceneOrgan::from);
    let scene = match abdomen_scene(&organs, vademecums, detail) {
        Ok(scene) => scene,
        Err(e) => return fail("pgd bench frame", &e),
    };
    let pressed: Vec<_> = scene
        .organs
        .iter()
        .zip(press_targets(&scene))
        .map(|((name, v), t)| (name.clone(), v.as_ref(), t.point_m, t.normal))
        .collect();
    let report = bench::frame::run(&pressed, FRAME_BENCH_PRESS_N, frames);
    print_report("pgd bench frame", Ok::<_, String>(report), json)
}

/// `pgd bench haptics`: the haptic loop's tick on the four-organ scene.
fn bench_haptics(options: HapticsBenchArgs) -> ExitCode {
    let HapticsBenchArgs {
        repeats,
        realtime_seconds,
        vademecums,
        dynamic,
        law,
        coarse,
        depth_mm,
        hands,
        json,
    } = options;
    let motion = match args::millimetres("depth-mm", Some(depth_mm), 0.0) {
        Ok(depth_m) => PressMotion {
            depth_m,
            ..PressMotion::default()
        },
        Err(e) => return fail("pgd bench haptics", &e),
    };
    // Two hands: the left grasps the gallbladder, which moves for it.
    let moves = |organ: Organ| dynamic || (hands == 2 && organ == Organ::Gallbladder);
    let organs = SCENE_ORGANS.map(|organ| SceneOrgan {
        dynamic: moves(organ),
        law: law.map_or(default_law(Some(organ), false, moves(organ)), |l| l.law()),
        ..SceneOrgan::from(organ)
    });
    let detail = if coarse { Detail::Coarse } else { Detail::Full };
    let scene = match abdomen_scene(&organs, &vademecums, detail) {
        Ok(scene) => scene,
        Err(e) => return fail("pgd bench haptics", &e),
    };
    print_report(
        "pgd bench haptics",
        app::bench::run(
            &scene,
            &motion,
            repeats,
            realtime_seconds,
            usize::from(hands),
        ),
        json,
    )
}

/// `pgd bench scalpel`: the haptic loop's tick with a scalpel cutting the liver.
fn bench_scalpel(runs: &SceneBenchArgs) -> ExitCode {
    let SceneBenchArgs {
        repeats,
        coarse,
        ref vademecums,
        json,
    } = *runs;
    let organs = SCENE_ORGANS.map(|organ| SceneOrgan {
        cut_toughness_j_per_m2: (organ == Organ::Liver)
            .then_some(pgd_surgery::cutting::LIVER_TOUGHNESS_J_PER_M2),
        ..SceneOrgan::from(organ)
    });
    let detail = if coarse { Detail::Coarse } else { Detail::Full };
    let mut scene = match abdomen_scene(&organs, vademecums, detail) {
        Ok(scene) => scene,
        Err(e) => return fail("pgd bench scalpel", &e),
    };
    if let Some(cutting) = &mut scene.cutting {
        cutting.blade.edge_m = 0.003;
    }
    print_report(
        "pgd bench scalpel",
        app::bench_scalpel::run(&scene, repeats),
        json,
    )
}

/// The press on each organ in `pgd bench frame` (N): the haptic benchmark's.
const FRAME_BENCH_PRESS_N: f64 = 0.2;

/// `pgd bench contact`: the scene's organs and coupling set up as asked, then timed.
fn bench_contact(options: &ContactBenchArgs) -> ExitCode {
    let detail = if options.coarse {
        Detail::Coarse
    } else {
        Detail::Full
    };
    let coupling = options.coupling();
    let organs = SCENE_ORGANS.map(SceneOrgan::from);
    let scene = match scene_of(
        &organs,
        None,
        &coupling,
        &options.vademecums,
        detail,
        OnStale::Rebuild,
    ) {
        Ok(scene) => scene,
        Err(e) => return fail("pgd bench contact", &e),
    };
    let Some(pairs) = scene.coupling.as_deref() else {
        return fail("pgd bench contact", "the scene has no organ contact");
    };
    print_report(
        "pgd bench contact",
        bench::contact::run(
            &scene.organs,
            pairs,
            &coupling,
            options.ticks,
            &options.cases,
        ),
        options.json,
    )
}

/// The four-organ scene of `organs` at `detail`, with the default contact, its vademecums
/// from `vademecums` (missing or stale ones rebuilt).
fn abdomen_scene(
    organs: &[SceneOrgan],
    vademecums: &Path,
    detail: Detail,
) -> Result<pgd_surgery::app::haptic::HapticScene, String> {
    let coupling = CouplingSettings::default();
    scene_of(
        organs,
        None,
        &coupling,
        vademecums,
        detail,
        OnStale::Rebuild,
    )
}
