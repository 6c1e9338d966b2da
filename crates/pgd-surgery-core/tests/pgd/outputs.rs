//! What the offline build hands to users: the convergence table and plot, the refusal of a
//! vademecum that does not fit its organ, and the build in the background. The commands'
//! own outputs (`pgd indent`, `pgd validate`) are the trainer's tests (`tests/commands`).

use pgd_surgery_core::fem::Law;
use pgd_surgery_core::mesh::organs::Organ;
use pgd_surgery_core::pgd::save;
use pgd_surgery_core::report::{self, StepCurve};
use pgd_surgery_core::store::{self, OnStale, VademecumSpec};

use crate::common::{block_mesh, block_model, build_block, temp_dir};

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

/// A vademecum queued for the background is built there, on the builder's thread, once
/// however often it is queued: the builder's status shows it queued or building until it is
/// idle, and the file is then there, good for the organ it was asked for (an organ from a
/// mesh file: the block, clamped underneath, pressed on top, neo-Hookean).
#[test]
fn a_vademecum_queued_for_the_background_is_built_there_once() {
    use pgd_surgery_core::mesh::io::write_vtu;
    use pgd_surgery_core::mesh::organs::region;
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
    let source = store::OrganSource::File(store::MeshFile::with_regions(path));
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
