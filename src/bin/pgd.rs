//! `pgd`: offline work — organ meshes, vademecum builds, benchmarks.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use pgd_surgery::app::scene::{Detail, SCENE_ORGANS, SceneOrgan, scene_of};
use pgd_surgery::contact::{
    ContactSurface, CouplingSettings, DistanceField, DistanceSettings, PenaltySettings,
    PointshellDensity,
};
use pgd_surgery::fem::{Inclusion, Law, Material, TISSUE_DENSITY_KG_M3};
use pgd_surgery::mesh::io::{ImportOptions, write_vtu};
use pgd_surgery::mesh::organs::{Organ, OrganSettings, region};
use pgd_surgery::mesh::{QualityReport, TetMesh};
use pgd_surgery::pgd::{
    self, BuildReport, BuildSettings, OrganModel, PgdSettings, ValidationReport, ValidationSettings,
};
use pgd_surgery::{bench, cli};

#[derive(Parser)]
#[command(
    name = "pgd",
    version,
    about = "Offline tools of the PGD surgery trainer: organ meshes and benchmarks of the numerical core"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Generate an organ (liver, gallbladder, pancreas, duodenum, cornea) or read a mesh file
    /// (.msh, .vtk, .vtu, or a closed .obj/.stl surface, which is tetrahedralized), and print
    /// its statistics and quality report. Exits with status 1 if the mesh cannot be simulated.
    Mesh {
        #[command(flatten)]
        mesh: MeshArgs,
        /// Also write the mesh (with its regions) as .vtu for ParaView.
        #[arg(long, value_name = "FILE.vtu")]
        out: Option<PathBuf>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Build the vademecum of an organ or of a mesh file with `clamped` and `accessible`
    /// regions: exact local responses, PGD global modes, and the brute-force baseline measured
    /// in the same run. Writes vademecums/<name>.vdm unless --out says otherwise.
    Build {
        #[command(flatten)]
        mesh: MeshArgs,
        #[command(flatten)]
        material: MaterialArgs,
        #[command(flatten)]
        build: BuildArgs,
        /// Where to write the vademecum.
        #[arg(long, value_name = "FILE.vdm")]
        out: Option<PathBuf>,
        /// Also precompute the organ's distance field for organ-against-organ contact, as
        /// a scene's contact master needs it (the gallbladder by default), and write it beside
        /// the vademecum (FILE.vdf). The trainer otherwise builds it on first use.
        #[arg(long)]
        distance_field: bool,
        /// Print the build report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Check a vademecum against full FEM on the same mesh at random loads it was not built on:
    /// felt-force and displacement errors (mean, p50, p95), and the build's convergence
    /// curves as CSV and PNG.
    Validate {
        #[command(flatten)]
        mesh: MeshArgs,
        /// The vademecum (default: vademecums/<source>.vdm).
        #[arg(long, value_name = "FILE.vdm")]
        vademecum: Option<PathBuf>,
        /// Number of random loads.
        #[arg(long, default_value_t = ValidationSettings::default().samples)]
        samples: usize,
        /// Seed of the random loads.
        #[arg(long, default_value_t = ValidationSettings::default().seed)]
        sample_seed: u64,
        /// Largest indentation of the random loads, in millimetres (default: 10/3 of the
        /// organ's tool radius, 20 for the abdominal organs; the smallest is a tenth of it).
        #[arg(long)]
        max_indentation_mm: Option<f64>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Time the numerical core and print medians (and ratios to a baseline run alongside).
    Bench {
        #[command(subcommand)]
        what: BenchTarget,
    },
}

/// Where the mesh comes from.
#[derive(Args)]
struct MeshArgs {
    /// An organ (liver, gallbladder, pancreas, duodenum, cornea) or a mesh file.
    source: String,
    /// Organs: multiplies the node count (1 = the papers' sizes).
    #[arg(long, default_value_t = 1.0)]
    resolution: f64,
    /// Organs: varies proportions deterministically (another patient).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Files: multiplies coordinates (0.001 for files in millimetres).
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    /// Surfaces (.obj, .stl): target node count of the tetrahedralization.
    #[arg(long, default_value_t = 4000)]
    nodes: usize,
}

impl MeshArgs {
    fn load(&self) -> Result<(Option<Organ>, TetMesh), String> {
        cli::load_source(&cli::MeshSource {
            name: &self.source,
            organ: OrganSettings {
                resolution: self.resolution,
                seed: self.seed,
            },
            import: ImportOptions {
                scale: self.scale,
                surface_nodes: self.nodes,
            },
        })
    }

    /// The file name a vademecum of this source gets by default.
    fn stem(&self) -> String {
        Path::new(&self.source)
            .file_stem()
            .map_or_else(|| self.source.clone(), |s| s.to_string_lossy().into_owned())
    }
}

/// The material law of a build.
#[derive(Clone, Copy, clap::ValueEnum)]
enum LawArg {
    /// Linear elasticity: one load step.
    Linear,
    /// Kirchhoff–Saint Venant by load steps: stiffens as the tool presses deeper.
    Ksv,
}

impl LawArg {
    fn law(self) -> Law {
        match self {
            LawArg::Linear => Law::Linear,
            LawArg::Ksv => Law::KirchhoffSaintVenant,
        }
    }
}

#[derive(Args)]
struct MaterialArgs {
    /// Material law.
    #[arg(long, value_enum, default_value = "linear")]
    law: LawArg,
    /// Young's modulus in Pa (default: the organ's, or the liver's 1.6 kPa for mesh files).
    #[arg(long)]
    young_pa: Option<f64>,
    /// Poisson's ratio.
    #[arg(long, default_value_t = pgd::organ::POISSON)]
    poisson: f64,
    /// A stiffer (or softer) sphere in the tissue, such as a tumour to find by palpation:
    /// its centre and radius in millimetres and its Young's modulus over the organ's, as
    /// `X,Y,Z,RADIUS,RATIO` (e.g. `10,-5,30,7,6`). Repeat for several.
    #[arg(long, value_name = "X,Y,Z,RADIUS,RATIO", value_parser = cli::parse_inclusion)]
    inclusion: Vec<Inclusion>,
}

impl MaterialArgs {
    fn material(&self, organ: Option<Organ>) -> Result<Material, String> {
        let law = self.law.law();
        let young_pa = self
            .young_pa
            .unwrap_or_else(|| pgd::organ::young_pa(organ.unwrap_or(Organ::Liver)));
        Material::new(law, young_pa, self.poisson, TISSUE_DENSITY_KG_M3).map_err(|e| e.to_string())
    }
}

#[derive(Args)]
struct BuildArgs {
    /// Radius of the tool tip's contact patch, in millimetres: loads are spread over it
    /// (default: 0.5 for the cornea, 6 for the other organs and mesh files).
    #[arg(long)]
    tool_radius_mm: Option<f64>,
    /// Radius around each loaded node, in millimetres, where its exact response is stored
    /// (default: the watched region plus the tool radius, 2.5 for the cornea, 26 for the
    /// other organs and mesh files).
    #[arg(long)]
    local_radius_mm: Option<f64>,
    /// Target of the estimator: each node-centred load's relative L2 error of the field (global
    /// modes + exact near field), root mean square over the loads.
    #[arg(long, default_value_t = BuildSettings::default().target_error)]
    target_error: f64,
    /// At most this many PGD modes per load step.
    #[arg(long, default_value_t = PgdSettings::default().max_modes)]
    max_modes: usize,
    /// KSV: indentation under the tool at each load step after the linear one, in
    /// millimetres, increasing. The deepest is the range the vademecum is valid over.
    #[arg(long, value_delimiter = ',', default_values_t = pgd::DEFAULT_LOAD_STEPS_M.map(|m| m * 1e3))]
    load_steps_mm: Vec<f64>,
}

impl BuildArgs {
    fn settings(&self, organ: Option<Organ>) -> Result<BuildSettings, String> {
        let defaults = BuildSettings::for_organ(organ);
        let steps = &self.load_steps_mm;
        if steps.iter().any(|s| !(s.is_finite() && *s > 0.0))
            || steps.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(format!(
                "--load-steps-mm {steps:?}: expected positive indentations in increasing order"
            ));
        }
        Ok(BuildSettings {
            tool_tip_radius_m: self
                .tool_radius_mm
                .map_or(defaults.tool_tip_radius_m, |mm| mm * 1e-3),
            local_radius_m: self
                .local_radius_mm
                .map_or(defaults.local_radius_m, |mm| mm * 1e-3),
            target_error: self.target_error,
            pgd: PgdSettings {
                max_modes: self.max_modes,
                ..PgdSettings::default()
            },
            load_steps_m: steps.iter().map(|s| s * 1e-3).collect(),
            ..defaults
        })
    }
}

#[derive(Subcommand)]
enum BenchTarget {
    /// The organ-contact stage: one pair's tick with the organs apart and with the master
    /// pressed until at least 400 pointshell nodes push, against parry's brute-force check of
    /// every node against the deformed master surface.
    Contact {
        /// Ticks timed per case.
        #[arg(long, default_value_t = 2000)]
        ticks: usize,
        /// The coarse scene (quarter-node organs, built in seconds) instead of the full one.
        #[arg(long)]
        coarse: bool,
        /// Where the organs' vademecums are kept (missing or stale ones are rebuilt).
        #[arg(long, default_value = "vademecums")]
        vademecums: PathBuf,
        /// A dense pointshell (nodes and triangle centres) instead of the boundary nodes.
        #[arg(long, conflicts_with_all = ["subdivide", "sparse"])]
        dense: bool,
        /// A pointshell of the centres of each surface triangle cut N times along each edge
        /// (N² points a triangle) instead of the boundary nodes.
        #[arg(long, value_name = "N", value_parser = cli::parse_subdivisions, conflicts_with = "sparse")]
        subdivide: Option<u8>,
        /// A sparse pointshell: the boundary nodes kept at least MM millimetres apart.
        #[arg(long, value_name = "MM", value_parser = cli::parse_spacing)]
        sparse: Option<u8>,
        /// How many times stiffer than the tissue each node's penalty is: 1000 (the
        /// trainer's) cuts an overlap to 0.1 %; 1 leaves half of it, as a one-pass penalty
        /// does, so that far more nodes stay inside and push.
        #[arg(
            long,
            value_name = "RATIO",
            default_value_t = PenaltySettings::default().stiffness_ratio,
            value_parser = cli::parse_stiffness_ratio
        )]
        stiffness_ratio: f64,
        /// The cases to time (all by default): apart, pressed (the master free), held (a
        /// rigid master, settled), sliding (the held master moved sideways at 10 mm/s).
        #[arg(long = "case", value_enum, value_name = "CASE")]
        cases: Vec<bench::contact::Case>,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// The haptic loop on the four-organ scene: tick compute time over a scripted sweep (all
    /// organs, then each), the same press by full FEM, and real-time punctuality per timer.
    Haptics {
        /// Sweeps run per figure; the median is reported.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Seconds of real-time ticking per timer.
        #[arg(long, default_value_t = 5.0)]
        realtime_seconds: f64,
        /// Where the organs' vademecums are kept (missing or stale ones are rebuilt).
        #[arg(long, default_value = "vademecums")]
        vademecums: PathBuf,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Assembly, factorization and solve on a liver-sized mesh (~4,300 nodes, ~21,000 tets).
    Fem {
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// How many times each step is timed; the median is reported.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Cubes along x, y, z of the benchmark box (six tets each).
        #[arg(long, num_args = 3, value_names = ["NX", "NY", "NZ"])]
        cells: Option<Vec<usize>>,
    },
    /// Build time and peak memory of an organ's vademecum (linear and KSV), and the online
    /// evaluations: displacement under the tool, felt force, whole field, file load.
    Vademecum {
        /// The organ (liver, gallbladder, pancreas, duodenum, cornea).
        #[arg(default_value = "liver")]
        organ: String,
        /// Material laws to build, in order (peak memory is the process's, so it only grows).
        #[arg(long, value_enum, value_delimiter = ',', default_values = ["linear", "ksv"])]
        laws: Vec<LawArg>,
        /// Batches timed for each online evaluation; the median is reported.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Mesh { mesh, out, json } => match mesh.load() {
            Ok((_, m)) => report_mesh(&mesh.source, &m, out.as_deref(), json),
            Err(e) => fail("pgd mesh", &e),
        },
        Command::Build {
            mesh,
            material,
            build,
            out,
            distance_field,
            json,
        } => {
            let out = out.unwrap_or_else(|| default_vademecum(&mesh));
            match build_vademecum(&mesh, &material, &build, &out, distance_field) {
                Ok(report) if json => print_json(&report),
                Ok(report) => {
                    print_build_report(&report, &out);
                    ExitCode::SUCCESS
                }
                Err(e) => fail("pgd build", &e),
            }
        }
        Command::Validate {
            mesh,
            vademecum,
            samples,
            sample_seed,
            max_indentation_mm,
            json,
        } => {
            let file = vademecum.unwrap_or_else(|| default_vademecum(&mesh));
            let settings = |organ| {
                let defaults = ValidationSettings {
                    samples,
                    seed: sample_seed,
                    ..ValidationSettings::for_organ(organ)
                };
                match max_indentation_mm {
                    Some(mm) => defaults.deepest_indentation(mm * 1e-3),
                    None => defaults,
                }
            };
            match validate_vademecum(&mesh, &file, settings) {
                Ok(report) if json => print_json(&report),
                Ok(report) => {
                    print_validation(&report);
                    ExitCode::SUCCESS
                }
                Err(e) => fail("pgd validate", &e),
            }
        }
        Command::Bench {
            what:
                BenchTarget::Vademecum {
                    organ,
                    laws,
                    repeats,
                    json,
                },
        } => {
            let Some(organ) = Organ::from_name(&organ) else {
                return fail(
                    "pgd bench vademecum",
                    &format!(
                        "{organ}: not an organ (liver, gallbladder, pancreas, duodenum, cornea)"
                    ),
                );
            };
            let laws: Vec<Law> = laws.into_iter().map(LawArg::law).collect();
            print_report(
                "pgd bench vademecum",
                bench::vademecum::run(organ, &laws, repeats),
                json,
            )
        }
        Command::Bench {
            what:
                BenchTarget::Contact {
                    ticks,
                    coarse,
                    vademecums,
                    dense,
                    subdivide,
                    sparse,
                    stiffness_ratio,
                    cases,
                    json,
                },
        } => {
            let detail = if coarse { Detail::Coarse } else { Detail::Full };
            let coupling = CouplingSettings {
                pointshell: match (dense, subdivide, sparse) {
                    (_, Some(n), _) => PointshellDensity::Subdivided(n),
                    (_, _, Some(mm)) => PointshellDensity::Sparse(mm),
                    (true, ..) => PointshellDensity::Dense,
                    (false, ..) => PointshellDensity::Nodes,
                },
                penalty: PenaltySettings {
                    stiffness_ratio,
                    ..PenaltySettings::default()
                },
                ..CouplingSettings::default()
            };
            let organs = SCENE_ORGANS.map(SceneOrgan::from);
            let scene = match scene_of(
                &organs,
                None,
                &coupling,
                &vademecums,
                detail,
                cli::OnStale::Rebuild,
            ) {
                Ok(scene) => scene,
                Err(e) => return fail("pgd bench contact", &e),
            };
            print_report(
                "pgd bench contact",
                bench::contact::run(&scene, &coupling, ticks, &cases),
                json,
            )
        }
        Command::Bench {
            what:
                BenchTarget::Haptics {
                    repeats,
                    realtime_seconds,
                    vademecums,
                    json,
                },
        } => {
            let scene = match pgd_surgery::app::scene::default_scene(
                &vademecums,
                Detail::Full,
                cli::OnStale::Rebuild,
            ) {
                Ok(scene) => scene,
                Err(e) => return fail("pgd bench haptics", &e),
            };
            print_report(
                "pgd bench haptics",
                bench::haptics::run(&scene, repeats, realtime_seconds),
                json,
            )
        }
        Command::Bench {
            what:
                BenchTarget::Fem {
                    json,
                    repeats,
                    cells,
                },
        } => {
            let cells = cells.map_or(bench::fem::LIVER_SIZED_CELLS, |c| [c[0], c[1], c[2]]);
            print_report("pgd bench fem", bench::fem::run(cells, repeats), json)
        }
    }
}

fn default_vademecum(mesh: &MeshArgs) -> PathBuf {
    PathBuf::from("vademecums").join(format!("{}.vdm", mesh.stem()))
}

fn validate_vademecum(
    mesh: &MeshArgs,
    file: &Path,
    settings: impl Fn(Option<Organ>) -> ValidationSettings,
) -> Result<ValidationReport, String> {
    let vademecum = pgd::load(file).map_err(|e| e.to_string())?;
    write_convergence(file, &vademecum.header)?;
    let (organ, tet_mesh) = mesh.load()?;
    vademecum
        .check_mesh(file, &tet_mesh)
        .map_err(|e| e.to_string())?;
    let model = pgd::organ::clamped_model(tet_mesh, vademecum.header.material)
        .and_then(|model| model.with_inclusions(&vademecum.header.inclusions))
        .map_err(|e| format!("{}: {e}", mesh.source))?;
    pgd::validate(&model, &vademecum, &settings(organ), &cli::Bar::default())
        .map_err(|e| format!("{}: {e}", mesh.source))
}

/// Writes the build's convergence curves beside the vademecum (to stderr, so `--json` output
/// stays parseable).
fn write_convergence(vademecum: &Path, header: &pgd::Header) -> Result<(), String> {
    let [csv, png] = cli::write_of_header(vademecum, header)?;
    eprintln!(
        "convergence curves: {} and {}",
        csv.display(),
        png.display()
    );
    Ok(())
}

fn print_validation(report: &ValidationReport) {
    println!(
        "{} random loads against full FEM       mean       p50       p95       max",
        report.samples.len()
    );
    let near = format!(
        "displacement field, within {} mm",
        report.near_radius_m * 1e3
    );
    for (name, s) in [
        ("felt force for the same indentation", &report.force_error),
        ("displacement field, whole organ", &report.field_error),
        (near.as_str(), &report.near_field_error),
    ] {
        println!(
            "  {name:<36} {:>7.3} % {:>7.3} % {:>7.3} % {:>7.3} %",
            100.0 * s.mean,
            100.0 * s.p50,
            100.0 * s.p95,
            100.0 * s.max
        );
    }
}

fn build_vademecum(
    mesh: &MeshArgs,
    material: &MaterialArgs,
    build: &BuildArgs,
    out: &Path,
    distance_field: bool,
) -> Result<BuildReport, String> {
    let (organ, tet_mesh) = mesh.load()?;
    let inclusions = &material.inclusion;
    let material = material.material(organ)?;
    let model = pgd::organ::clamped_model(tet_mesh, material)
        .and_then(|model| model.with_inclusions(inclusions))
        .map_err(|e| format!("{}: {e}", mesh.source))?;
    let organ_model = OrganModel {
        source: mesh.source.clone(),
        model: &model,
        clamped_region: region::CLAMPED.into(),
        accessible_region: region::ACCESSIBLE.into(),
    };
    let (vademecum, report) =
        pgd::build(&organ_model, &build.settings(organ)?, &cli::Bar::default())
            .map_err(|e| format!("{}: {e}", mesh.source))?;
    pgd::save(out, &vademecum).map_err(|e| e.to_string())?;
    write_convergence(out, &vademecum.header)?;
    if distance_field {
        write_distance_field(&vademecum, &out.with_extension("vdf"))?;
    }
    Ok(report)
}

/// Precomputes the distance field of `vademecum` on the default lattice and writes it.
fn write_distance_field(vademecum: &pgd::Vademecum, path: &Path) -> Result<(), String> {
    let started = std::time::Instant::now();
    let surface = ContactSurface::new(vademecum).map_err(|e| e.to_string())?;
    let field = DistanceField::build(vademecum, &surface, &DistanceSettings::default());
    field.save(path).map_err(|e| e.to_string())?;
    eprintln!(
        "distance field: {} lattice nodes, {} modes, built in {:.1} s, written to {}",
        field.node_count(),
        vademecum.total_modes(),
        started.elapsed().as_secs_f64(),
        path.display()
    );
    Ok(())
}

fn print_build_report(report: &BuildReport, out: &Path) {
    println!(
        "{} load positions x 3 directions = {} parameters, {} free dofs; a load's near field \
         holds {:.1} % of the nodes on average",
        report.positions,
        report.parameters,
        report.free_dofs,
        100.0 * report.near_field_share
    );
    for (k, step) in report.steps.iter().enumerate() {
        let n = step.modes_kept;
        let pgd_error = step.curve.separated.last().copied().unwrap_or(f64::NAN);
        let optimal = step
            .curve
            .optimal
            .get(n.wrapping_sub(1))
            .copied()
            .unwrap_or(f64::NAN);
        println!(
            "step {k} (indentation {:.1} mm): {n} modes, global-part energy error {:.1} % \
             (optimal rank-{n}: {:.1} %, ratio {:.2})",
            step.indentation_m * 1e3,
            100.0 * pgd_error,
            100.0 * optimal,
            pgd_error / optimal
        );
        let field = |curve: &[f64]| curve.last().map_or(f64::NAN, |e| 100.0 * e);
        println!(
            "  vademecum field error (global + near field) of each node-centred load: {:.1} % \
             rms, {:.1} % p95",
            field(&step.curve.field),
            field(&step.curve.field_p95)
        );
        println!(
            "  time: PGD {:.1} s, brute force (solves + SVD) {:.1} s (PGD/brute force {:.2}), local part {:.1} s",
            step.pgd_seconds,
            step.brute_force_seconds,
            step.pgd_seconds / step.brute_force_seconds,
            step.local_seconds
        );
        if let Some(fixed_point) = &step.fixed_point {
            print_fixed_point(fixed_point);
        }
    }
    if let Some(failed) = &report.failed_step {
        println!(
            "KSV step {:.1} mm left out: its fixed point did not converge (the law loses \
             stability under the tool); the vademecum is valid to {:.1} mm",
            failed.indentation_m * 1e3,
            report.steps.last().map_or(0.0, |s| s.indentation_m * 1e3)
        );
        if let Some(fixed_point) = &failed.fixed_point {
            print_fixed_point(fixed_point);
        }
    }
    let size = std::fs::metadata(out).map_or(0, |m| m.len());
    println!(
        "wrote {} ({:.1} MB) in {:.1} s",
        out.display(),
        size as f64 / 1e6,
        report.total_seconds
    );
}

fn print_fixed_point(report: &pgd::SecantReport) {
    println!(
        "  secant fixed point: {:.1} iterations per load on average, at most {}; \
         {} of {} loads unconverged (largest last change {:.1e})",
        report.mean_iterations(),
        report.max_iterations,
        report.unconverged,
        report.responses,
        report.worst_change
    );
}

/// Prints a mesh's statistics, regions and quality, writes it if asked, and fails if the mesh
/// cannot be simulated.
fn report_mesh(source: &str, mesh: &TetMesh, out: Option<&Path>, json: bool) -> ExitCode {
    let report = QualityReport::measure(mesh.nodes(), mesh.tets());
    let regions = mesh.regions();
    if json {
        print_json(&serde_json::json!({
            "source": source,
            "quality": report,
            "usable": report.refusal().is_none(),
            "node_sets": regions.node_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
            "face_sets": regions.face_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
        }));
    } else {
        println!("{source}\n{report}");
        for (name, nodes) in &regions.node_sets {
            println!("  node set {name}: {} nodes", nodes.len());
        }
        for (name, faces) in &regions.face_sets {
            println!("  face set {name}: {} faces", faces.len());
        }
    }
    if let Some(path) = out {
        if let Err(e) = write_vtu(path, mesh, &[]) {
            return fail("pgd mesh", &format!("{}: {e}", path.display()));
        }
        if !json {
            println!("wrote {}", path.display());
        }
    }
    if report.refusal().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// A benchmark's report as JSON or as its table, or its error.
fn print_report<R, E>(command: &str, result: Result<R, E>, json: bool) -> ExitCode
where
    R: serde::Serialize + std::fmt::Display,
    E: std::fmt::Display,
{
    match result {
        Ok(report) if json => print_json(&report),
        Ok(report) => {
            print!("{report}");
            ExitCode::SUCCESS
        }
        Err(e) => fail(command, &e.to_string()),
    }
}

fn print_json(value: &impl serde::Serialize) -> ExitCode {
    println!(
        "{}",
        serde_json::to_string_pretty(value).expect("plain data serializes")
    );
    ExitCode::SUCCESS
}

fn fail(command: &str, message: &str) -> ExitCode {
    eprintln!("{command}: {message}");
    ExitCode::FAILURE
}
