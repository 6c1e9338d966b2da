//! The vademecum file: a round trip is lossless, and every kind of bad file is refused with a
//! message that names the file and the problem.

use std::path::PathBuf;

use pgd_surgery_core::fem::Law;
use pgd_surgery_core::pgd::{
    BuildSettings, FORMAT_VERSION, SecantSettings, StepLoads, VademecumError, load, save,
};

use crate::common::{block_mesh, block_model, build_block};

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pgd-file-format-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn a_saved_vademecum_loads_back_identical_and_fits_its_mesh_only() {
    let model = block_model(block_mesh([4, 3, 2]));
    let vademecum = build_block(&model, 4);
    let path = temp("roundtrip.vdm");
    save(&path, &vademecum).unwrap();
    let back = load(&path).unwrap();
    assert_eq!(back, vademecum);
    back.check_mesh(&path, model.mesh()).unwrap();
    let other = block_mesh([4, 3, 3]);
    let err = back.check_mesh(&path, &other).unwrap_err();
    assert!(matches!(err, VademecumError::OtherMesh { .. }), "{err}");
    assert!(err.to_string().contains("roundtrip.vdm") && err.to_string().contains("pgd build"));
    // Built for a 6 mm tool: a trainer with a 12 mm one must not take it.
    back.check_settings(&path, &vademecum.header.settings)
        .unwrap();
    let wider_tool = BuildSettings {
        tool_tip_radius_m: 2.0 * vademecum.header.settings.tool_tip_radius_m,
        ..vademecum.header.settings.clone()
    };
    let err = back.check_settings(&path, &wider_tool).unwrap_err();
    assert!(matches!(err, VademecumError::OtherSettings { .. }), "{err}");
    assert!(err.to_string().contains("tool tip"), "{err}");
}

#[test]
fn truncated_corrupted_foreign_and_old_files_are_refused() {
    let model = block_model(block_mesh([4, 3, 2]));
    let path = temp("good.vdm");
    save(&path, &build_block(&model, 2)).unwrap();
    let bytes = std::fs::read(&path).unwrap();

    let truncated = temp("truncated.vdm");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let err = load(&truncated).unwrap_err();
    assert!(matches!(err, VademecumError::Truncated { .. }), "{err}");
    assert!(err.to_string().contains("truncated.vdm"));

    let mut flipped = bytes.clone();
    let middle = flipped.len() - 100;
    flipped[middle] ^= 1;
    let corrupted = temp("corrupted.vdm");
    std::fs::write(&corrupted, &flipped).unwrap();
    let err = load(&corrupted).unwrap_err();
    assert!(matches!(err, VademecumError::Corrupted { .. }), "{err}");

    let mut old = bytes.clone();
    old[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let other_version = temp("version.vdm");
    std::fs::write(&other_version, &old).unwrap();
    let err = load(&other_version).unwrap_err();
    assert!(matches!(err, VademecumError::Version { .. }), "{err}");

    let foreign = temp("foreign.vdm");
    std::fs::write(&foreign, b"solid cube\nendsolid cube\n").unwrap();
    let err = load(&foreign).unwrap_err();
    assert!(matches!(err, VademecumError::NotAVademecum { .. }), "{err}");

    let missing = load(&temp("missing.vdm")).unwrap_err();
    assert!(matches!(missing, VademecumError::Io { .. }), "{missing}");
}

/// A header holding a non-finite number would be written as JSON `null` and never load again:
/// it is refused before anything is written, and an older good file in its place is kept.
#[test]
fn a_vademecum_that_would_not_load_back_is_not_written() {
    let model = block_model(block_mesh([4, 3, 2]));
    let mut vademecum = build_block(&model, 2);
    let path = temp("unwritable.vdm");
    save(&path, &vademecum).unwrap();
    let before = std::fs::read(&path).unwrap();
    vademecum.header.build_seconds = f64::NAN;
    let err = save(&path, &vademecum).unwrap_err();
    assert!(matches!(err, VademecumError::Unwritable { .. }), "{err}");
    assert!(err.to_string().contains("unwritable.vdm"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), before);
}

/// A vademecum with a cut section loads back with it, and its compressed responses answer as
/// before; a header announcing a cut section the payload lacks is refused, naming the file.
#[test]
fn a_cut_section_survives_the_round_trip() {
    use pgd_surgery_core::pgd::{RegionSettings, Silent, add_cuts};
    let model = block_model(block_mesh([4, 3, 2]));
    let mut vademecum = build_block(&model, 2);
    let settings = RegionSettings {
        depth_m: 0.02,
        near_radius_m: 0.01,
        modes: 3,
        patch_radius_m: Some(0.005),
    };
    let report = add_cuts(&mut vademecum, &model, &settings, &Silent).unwrap();
    assert!(report.positions > 0 && report.modes > 0, "{report:?}");
    let path = temp("cuts.vdm");
    save(&path, &vademecum).unwrap();
    let back = load(&path).unwrap();
    assert_eq!(back, vademecum);
    let cuts = back.cuts.as_ref().unwrap();
    assert_eq!(
        cuts.patch_radius_m,
        Some(0.005),
        "the patch radius travels in the header"
    );
    let node = cuts.positions[0] as usize;
    let unit = [(3 * node + 2, 1.0)];
    assert_eq!(
        cuts.modal_coefficients(&unit),
        vademecum.cuts.as_ref().unwrap().modal_coefficients(&unit)
    );

    let mut without_payload = vademecum.clone();
    without_payload.cuts = None;
    let lying = temp("lying.vdm");
    save(&lying, &without_payload).unwrap();
    let err = load(&lying).unwrap_err();
    assert!(matches!(err, VademecumError::Malformed { .. }), "{err}");
    assert!(err.to_string().contains("lying.vdm"), "{err}");
}

/// The web form expands to a vademecum of the same mesh and header whose felt force is within
/// 0.2 % of the full file's at every triangle (each value is rounded by at most 2^-11 of
/// itself); deflated, it is at most half the file.
#[test]
fn the_web_form_is_smaller_and_feels_the_same() {
    use pgd_surgery_core::pgd::{decode, encode, web_form};
    let model = block_model(block_mesh([6, 4, 3]));
    let vademecum = build_block(&model, 6);
    let path = std::path::Path::new("block.vdm.web");
    let web = web_form::vademecum(&vademecum);
    let back = decode(path, &web_form::expand(path, &web).unwrap()).unwrap();
    assert_eq!(back.header, vademecum.header);
    assert_eq!(back.position_coords_m, vademecum.position_coords_m);
    back.check_mesh(path, model.mesh()).unwrap();
    let changes = web_form::felt_force_changes(&vademecum, &back);
    assert_eq!(changes.len(), vademecum.triangles.len());
    let worst = changes.iter().copied().fold(0.0, f64::max);
    assert!(worst > 0.0 && worst < 2e-3, "felt force changed by {worst}");
    let full = encode(&vademecum).len();
    assert!(
        2 * web.len() <= full,
        "web form {} bytes of {full}",
        web.len()
    );
}

/// A header written before the fixed point's Anderson acceleration, damping, Newton fallback
/// and per-position range existed reads them as what it was built with (the plain, undamped
/// iteration, no Newton, every position reaching each step), not as today's defaults: such a
/// file is seen as built otherwise, and rebuilt.
#[test]
fn settings_missing_from_an_older_header_read_as_what_it_was_built_with() {
    let older = r#"{"tolerance": 0.001, "max_iterations": 40, "max_unconverged_fraction": 0.005}"#;
    let read: SecantSettings = serde_json::from_str(older).unwrap();
    assert_eq!(
        (
            read.anderson_depth,
            read.mixing,
            read.newton_budget,
            read.min_reached_share
        ),
        (0, 1.0, 0.0, 1.0)
    );
    assert_ne!(read, SecantSettings::default());
    let current = serde_json::to_string(&SecantSettings::default()).unwrap();
    let round_trip: SecantSettings = serde_json::from_str(&current).unwrap();
    assert_eq!(round_trip, SecantSettings::default());
}

/// The fixed point's settings count only for a vademecum built by load steps: a linear one
/// built with other ones is taken, a neo-Hookean one is refused, its message naming them.
#[test]
fn fixed_point_settings_count_for_nonlinear_vademecums_only() {
    let model = block_model(block_mesh([4, 3, 2]));
    let linear = build_block(&model, 4);
    let path = temp("fixed-point.vdm");
    let damped_otherwise = BuildSettings {
        secant: SecantSettings {
            mixing: 0.25,
            ..linear.header.settings.secant
        },
        load_steps_m: vec![2e-3],
        ..linear.header.settings.clone()
    };
    linear.check_settings(&path, &damped_otherwise).unwrap();
    let mut nonlinear = linear.clone();
    nonlinear.header.material.law = Law::NeoHookean;
    let err = nonlinear
        .check_settings(&path, &damped_otherwise)
        .unwrap_err();
    assert!(matches!(err, VademecumError::OtherSettings { .. }), "{err}");
    assert!(err.to_string().contains("mixing 0.25"), "{err}");
}

/// A vademecum whose nonlinear steps were built from nodal loads (files from before the steps
/// loaded the tool's patch, which read as nodal) or from the tool's patch along each axis is
/// refused with a message that says to rebuild it; the same file with steps of the tool's
/// patch pushed along the inward normal, and a linear file of any kind, load.
#[test]
fn nonlinear_steps_built_otherwise_are_refused() {
    let model = block_model(block_mesh([4, 3, 2]));
    let linear = build_block(&model, 4);
    let mut nonlinear = linear.clone();
    nonlinear.header.material.law = Law::NeoHookean;
    nonlinear.steps.push(linear.steps[0].clone());
    nonlinear.header.indentation_levels_m.push(1e-3);
    nonlinear
        .header
        .modes_per_step
        .push(linear.header.modes_per_step[0]);
    nonlinear
        .header
        .convergence
        .push(linear.header.convergence[0].clone());
    for (vademecum, name) in [(&linear, "linear"), (&nonlinear, "nonlinear")] {
        for step_loads in [
            StepLoads::Nodal,
            StepLoads::ToolPatch,
            StepLoads::InwardToolPatch,
        ] {
            let mut file = vademecum.clone();
            file.header.step_loads = step_loads;
            let path = temp(&format!("{name}-{step_loads:?}.vdm"));
            save(&path, &file).unwrap();
            let loaded = load(&path);
            if name == "nonlinear" && step_loads != StepLoads::InwardToolPatch {
                let err = loaded.unwrap_err();
                assert!(
                    matches!(err, VademecumError::OlderLoadSteps { .. }),
                    "{err}"
                );
                assert!(err.to_string().contains("rebuild it"), "{err}");
            } else {
                assert_eq!(loaded.unwrap().header.step_loads, step_loads);
            }
        }
    }
}
