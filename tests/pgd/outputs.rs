//! What the offline tools hand to users: the convergence table and plot, the force–depth
//! curves of `pgd indent` and `pgd validate`, and the trainer's refusal of a vademecum that
//! does not fit its organ.

use pgd_surgery::cli::plot_force_depth;
use pgd_surgery::fem::Law;
use pgd_surgery::mesh::organs::Organ;
use pgd_surgery::pgd::{Silent, ValidationSettings, save, validate};
use pgd_surgery::report::{self, StepCurve};
use pgd_surgery::store::{self, OnStale, VademecumSpec};

use crate::common::{block_mesh, block_model, build_block};

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pgd-outputs-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// One CSV row per mode with the curve's own numbers, and a real PNG beside the vademecum.
#[test]
fn the_convergence_curves_are_written_as_csv_and_png() {
    let model = block_model(block_mesh([4, 3, 2]));
    let vademecum = build_block(&model, 5);
    let curve = &vademecum.header.convergence[0];
    let file = temp_dir("curves").join("block.vdm");
    let steps = [StepCurve {
        indentation_m: 0.0,
        curve,
    }];
    let [csv, png] = report::write_convergence(&file, &steps).unwrap();
    let table = std::fs::read_to_string(csv).unwrap();
    let rows: Vec<&str> = table.lines().skip(1).collect();
    assert_eq!(rows.len(), vademecum.modes(0));
    let last: Vec<&str> = rows.last().unwrap().split(',').collect();
    let pgd_error: f64 = last[4].parse().unwrap();
    assert!((pgd_error - curve.separated[rows.len() - 1]).abs() < 1e-6 * pgd_error);
    let bytes = std::fs::read(png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
}

/// A vademecum of another mesh under the liver's name is refused, naming the file, the
/// problem and the command that builds the right one; a missing one too.
#[test]
fn the_trainer_refuses_a_stale_or_missing_vademecum_with_the_command_to_run() {
    let dir = temp_dir("stale");
    let spec = VademecumSpec::default_in(&dir, Organ::Liver, Law::Linear);
    let missing = store::ensure_vademecum(&spec, OnStale::Refuse).unwrap_err();
    assert!(
        missing.contains("liver.vdm") && missing.contains("pgd -- build liver"),
        "{missing}"
    );
    let model = block_model(block_mesh([4, 3, 2]));
    save(&spec.file, &build_block(&model, 2)).unwrap();
    let stale = store::ensure_vademecum(&spec, OnStale::Refuse).unwrap_err();
    assert!(
        stale.contains("another mesh") && stale.contains("pgd -- build liver"),
        "{stale}"
    );
}

/// `pgd indent` on a block with `clamped` and `accessible` regions: one curve per law, rising
/// with depth, the linear law's per-element volumes stiffer than the neo-Hookean nodal ones at
/// ν = 0.48, and the curves drawn as a PNG; a request without steps is refused.
#[test]
fn pgd_indent_gives_a_force_depth_curve_per_law() {
    use pgd_surgery::cli::{IndentRequest, indent_organ, plot_indentation};
    use pgd_surgery::fem::Material;
    use pgd_surgery::mesh::organs::region;

    let mut mesh = block_mesh([6, 4, 3]);
    let clamped = mesh.node_set("z0").unwrap().to_vec();
    let accessible = mesh.face_set("z1").unwrap().to_vec();
    mesh.set_node_set(region::CLAMPED, clamped).unwrap();
    mesh.set_face_set(region::ACCESSIBLE, accessible).unwrap();
    let materials = [Law::Linear, Law::NeoHookean].map(Material::liver);
    let request = IndentRequest {
        source: "block",
        at_mm: Some([30.0, 20.0, 30.0]),
        depth_mm: Some(2.0),
        steps: 4,
    };
    let silent = pgd_surgery::pgd::Silent;
    let report = indent_organ((None, mesh.clone()), &materials, &request, &silent).unwrap();
    assert_eq!(report.point_m, [0.03, 0.02, 0.03]);
    let [linear, neo_hookean] = [&report.curves[0], &report.curves[1]];
    for curve in [linear, neo_hookean] {
        assert_eq!(curve.stopped_at_m, None, "{:?}", curve.stop_reason);
        assert_eq!(curve.force_n.len(), 4);
        assert!(
            curve.force_n.windows(2).all(|w| w[1] > w[0] && w[0] > 0.0),
            "{} forces {:?} N do not rise with depth",
            curve.law,
            curve.force_n
        );
    }
    assert!(linear.force_n[0] > neo_hookean.force_n[0]);
    let png = temp_dir("indent").join("block-indentation.png");
    plot_indentation(&report, &png).unwrap();
    assert_eq!(&std::fs::read(png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");

    let no_steps = IndentRequest {
        steps: 0,
        ..request
    };
    let refused = indent_organ((None, mesh), &materials, &no_steps, &silent).unwrap_err();
    assert!(refused.contains("--steps"), "{refused}");
}

/// `pgd validate` draws its force–depth curves beside the vademecum as a PNG; asked for none
/// (`--curves 0`), it draws nothing rather than an empty chart.
#[test]
fn the_force_depth_plot_is_drawn_only_when_there_are_curves() {
    let model = block_model(block_mesh([4, 3, 2]));
    let vademecum = build_block(&model, 5);
    let file = temp_dir("force-depth").join("block.vdm");
    let checked = |curves: usize| {
        let settings = ValidationSettings {
            samples: 1,
            curves,
            indentation_range_m: (1e-3, 3e-3),
            ..ValidationSettings::default()
        };
        validate(&model, &vademecum, &settings, &Silent).unwrap()
    };
    assert_eq!(plot_force_depth(&checked(0), &file), Ok(None));
    let png = plot_force_depth(&checked(1), &file).unwrap().unwrap();
    assert!(std::fs::read(png).unwrap().starts_with(b"\x89PNG"));
}

/// A vademecum queued for the background is built there, on the builder's thread, once
/// however often it is queued: the builder's status shows it queued or building until it is
/// idle, and the file is then there, good for the organ it was asked for (an organ from a
/// mesh file: the block, clamped underneath, pressed on top, neo-Hookean).
#[test]
fn a_vademecum_queued_for_the_background_is_built_there_once() {
    use pgd_surgery::mesh::io::write_vtu;
    use pgd_surgery::mesh::organs::region;
    use std::time::{Duration, Instant};

    let dir = temp_dir("background");
    let mut mesh = block_mesh([4, 3, 2]);
    let clamped = mesh.node_set("z0").unwrap().to_vec();
    let accessible = mesh.face_set("z1").unwrap().to_vec();
    mesh.set_node_set(region::CLAMPED, clamped).unwrap();
    mesh.set_face_set(region::ACCESSIBLE, accessible).unwrap();
    let path = dir.join("block.vtu");
    write_vtu(&path, &mesh, &[]).unwrap();
    let file = dir.join("block-neo-hookean.vdm");
    let source = store::OrganSource::File(path);
    let mut spec = VademecumSpec::new("block", source, Law::NeoHookean, file.clone());
    spec.build.tool_tip_radius_m = 0.012;
    spec.build.local_radius_m = 0.015;
    spec.build.load_steps_m = vec![0.5e-3];
    store::build_in_background(spec.clone());
    store::build_in_background(spec.clone());
    let status = store::background_status();
    let building = status.building.iter().count();
    assert_eq!(building + status.queued.len(), 1, "{status:?}");
    let started = Instant::now();
    while !store::background_status().is_idle() {
        assert!(
            started.elapsed() < Duration::from_secs(600),
            "still building"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = store::background_status();
    assert!(status.failed.is_empty(), "{status:?}");
    let (vademecum, _) = store::ensure_vademecum(&spec, OnStale::Refuse).unwrap();
    assert_eq!(vademecum.header.material.law, Law::NeoHookean);
    assert_eq!(vademecum.steps.len(), 2);
    let built = std::fs::metadata(&file).unwrap().modified().unwrap();
    store::build_in_background(spec);
    assert!(store::background_status().is_idle());
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(std::fs::metadata(&file).unwrap().modified().unwrap(), built);
}
