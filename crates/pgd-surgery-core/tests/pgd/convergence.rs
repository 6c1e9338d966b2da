//! The vademecum against full FEM at loads it was not built on, and the PGD against the
//! best separated sum of as many terms (Eckart–Young).

use nalgebra::Vector3;
use pgd_surgery_core::fem::{Dirichlet, FemModel, Law, Loads, Material, NewtonSettings};
use pgd_surgery_core::mesh::box_mesh;
use pgd_surgery_core::pgd::{
    BuildSettings, Silent, Vademecum, ValidationSettings, WIDE_NEAR_FIELD_SHARE, build, validate,
};

use crate::common::{block_mesh, block_model, build_block, organ, settings};

fn off_node_loads() -> ValidationSettings {
    ValidationSettings {
        samples: 12,
        near_radius_m: 0.015,
        indentation_range_m: (1e-3, 5e-3),
        ..ValidationSettings::default()
    }
}

/// By linearity the local compliances make the felt force exact for a tool patch centred
/// anywhere, up to the f32 storage: stated tolerance 1e-4.
pub fn assert_felt_force_exact(model: &FemModel, vademecum: &Vademecum) {
    let report = validate(model, vademecum, &off_node_loads(), &Silent).unwrap();
    assert!(
        report.force_error.max < 1e-4,
        "felt-force error {:?}",
        report.force_error
    );
}

#[test]
fn the_felt_force_matches_full_fem_off_the_nodes() {
    let model = block_model(block_mesh([6, 4, 3]));
    assert_felt_force_exact(&model, &build_block(&model, 8));
}

/// A near field as wide as the watched region plus the tool radius holds every node a patch
/// loads to its exact response over the whole watched region, so there the field is full
/// FEM's for a patch anywhere, with only 3 modes (f32 storage: tolerance 1e-4). As wide as the
/// watched region alone, the nodes at the patch's edge miss part of it (measured: 13.5 % at
/// worst, against 1.3e-7).
#[test]
fn a_near_field_of_the_watched_region_plus_the_patch_is_exact_there() {
    let model = block_model(block_mesh([6, 4, 3]));
    let loads = off_node_loads();
    let with = |local_radius_m: f64| -> f64 {
        let settings = BuildSettings {
            local_radius_m,
            ..settings(3, 1e-9)
        };
        let (vademecum, _) = build(&organ(&model), &settings, &Silent).unwrap();
        validate(&model, &vademecum, &loads, &Silent)
            .unwrap()
            .near_field_error
            .max
    };
    let tool_m = settings(3, 1e-9).tool_tip_radius_m;
    let (watched, widened) = (
        with(loads.near_radius_m),
        with(loads.near_radius_m + tool_m),
    );
    eprintln!(
        "field error within the watched region, max: {watched:.4} narrow, {widened:.2e} wide"
    );
    assert!(widened < 1e-4, "{widened}");
    assert!(watched > 100.0 * widened, "{watched} against {widened}");
}

/// A 12 mm tool on a 3 mm wall pushes only the face it touches: no load position lies on the
/// far face, and the felt force still matches full FEM (whose patch keeps to the pressed face
/// too) off the nodes.
#[test]
fn on_a_thin_wall_the_tool_loads_only_the_face_it_presses() {
    let mesh = box_mesh([0.06, 0.04, 0.003], [12, 8, 1]).unwrap();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("x0").unwrap()).unwrap();
    let model = FemModel::new(mesh, Material::liver(Law::Linear), dirichlet).unwrap();
    let wall = pgd_surgery_core::pgd::OrganModel {
        clamped_region: "x0".into(),
        ..organ(&model)
    };
    let (vademecum, _) = build(&wall, &settings(8, 1e-9), &Silent).unwrap();
    let far_face = vademecum
        .positions
        .iter()
        .filter(|&&n| model.mesh().nodes()[n as usize].z < 1e-9)
        .count();
    assert_eq!(far_face, 0, "load positions on the far face");
    assert_felt_force_exact(&model, &vademecum);
}

/// More modes, smaller field error; with the near-field correction the field near the tool is
/// within 10 % (p95) with few modes (measured 7.7 % with 3, 2.9 % with 40), and with as many
/// modes as parameters the whole field is full FEM's up to f32 storage (tolerance 1e-3).
#[test]
fn the_field_converges_to_full_fem_with_the_number_of_modes() {
    let model = block_model(block_mesh([6, 4, 3]));
    let few = validate(&model, &build_block(&model, 3), &off_node_loads(), &Silent).unwrap();
    let many = validate(&model, &build_block(&model, 40), &off_node_loads(), &Silent).unwrap();
    let full = build_block(&model, 1000);
    let all = validate(&model, &full, &off_node_loads(), &Silent).unwrap();
    eprintln!(
        "field error p95: {:.4} with 3 modes, {:.4} with 40, {:.2e} with {}; near the tool {:.4}, {:.4}",
        few.field_error.p95,
        many.field_error.p95,
        all.field_error.p95,
        full.modes(0),
        few.near_field_error.p95,
        many.near_field_error.p95
    );
    assert!(many.field_error.p95 < 0.5 * few.field_error.p95);
    assert!(many.near_field_error.p95 < 0.1);
    assert!(all.field_error.p95 < 1e-3);
}

/// The separated part is within 1.5× the optimal rank-n error at every n (the target),
/// its energy error never rises, and the estimator stops at its target.
#[test]
fn pgd_is_near_the_optimal_separated_sum_and_stops_at_the_target() {
    let model = block_model(block_mesh([6, 4, 3]));
    let target = 0.05;
    let (vademecum, report) = build(&organ(&model), &settings(200, target), &Silent).unwrap();
    let curve = &report.steps[0].curve;
    for (n, (pgd, best)) in curve.separated.iter().zip(&curve.optimal).enumerate() {
        assert!(
            *pgd <= 1.5 * best + 1e-9,
            "{} modes: PGD {pgd:.4} vs optimal {best:.4}",
            n + 1
        );
    }
    for pair in curve.separated.windows(2) {
        assert!(pair[1] <= pair[0] * (1.0 + 1e-9), "{:?}", curve.separated);
    }
    let last = *curve.field.last().unwrap();
    let before = curve.field[curve.field.len().saturating_sub(2)];
    assert!(last <= target, "stopped at {last} above the target");
    assert!(
        curve.field.len() == 1 || before > target,
        "went on past the target"
    );
    assert_eq!(vademecum.modes(0), curve.field.len());
}

/// The estimator is what it says: recomputed from full FEM solves of every unit nodal load
/// and the vademecum's answer to each (its modes plus its near field), the area-weighted root
/// mean square of the loads' own relative errors and their 95th percentile agree with the
/// build's figures to 1e-4 (f32 storage).
#[test]
fn the_estimator_is_each_loads_own_error_against_full_fem() {
    let model = block_model(block_mesh([6, 4, 3]));
    let (vademecum, report) = build(&organ(&model), &settings(4, 1e-9), &Silent).unwrap();
    let curve = &report.steps[0].curve;
    let (mut squares, mut area, mut own) = (0.0, 0.0, Vec::new());
    for (m, &node) in vademecum.positions.iter().enumerate() {
        for d in 0..3 {
            let mut loads = Loads::new(model.mesh().node_count());
            let mut unit = [0.0; 3];
            unit[d] = 1.0;
            loads.add_nodal_force(node as usize, unit).unwrap();
            let exact = model
                .solve_static(&loads, &NewtonSettings::default())
                .unwrap()
                .displacement_m;
            let mut answer = vec![0.0; exact.len()];
            vademecum.add_patch_field(&[(m, 1.0)], &Vector3::from(unit), &mut answer);
            let error: f64 = exact
                .iter()
                .zip(&answer)
                .map(|(e, a)| (e - a).powi(2))
                .sum();
            let relative = (error / exact.iter().map(|e| e * e).sum::<f64>()).sqrt();
            let weight = f64::from(vademecum.position_areas_m2[m]);
            squares += weight * relative * relative;
            area += weight;
            own.push(relative);
        }
    }
    own.sort_by(f64::total_cmp);
    let p95 = own[(0.95 * (own.len() - 1) as f64).round() as usize];
    let rms = (squares / area).sqrt();
    let (built_rms, built_p95) = (curve.field[3], curve.field_p95[3]);
    eprintln!("rms {rms:.5} (build {built_rms:.5}), p95 {p95:.5} (build {built_p95:.5})");
    assert!(
        (rms - built_rms).abs() < 1e-4 * built_rms.max(1e-3),
        "{rms} against {built_rms}"
    );
    assert!(
        (p95 - built_p95).abs() < 1e-4 * built_p95.max(1e-3),
        "{p95} against {built_p95}"
    );
}

/// The build reports how much of the organ a load's near field holds: all of it when the
/// radius exceeds the organ (the cornea under the abdominal radii kept one mode and 3.7 GB),
/// which it flags; a fraction with the block's own radius.
#[test]
fn the_build_reports_a_near_field_too_wide_for_the_organ() {
    let model = block_model(block_mesh([6, 4, 3]));
    let share = |local_radius_m: f64| {
        let settings = BuildSettings {
            local_radius_m,
            ..settings(2, 1e-9)
        };
        build(&organ(&model), &settings, &Silent)
            .unwrap()
            .1
            .near_field_share
    };
    let (own, whole) = (share(0.015), share(1.0));
    eprintln!("near-field share: {own:.3} with 15 mm, {whole:.3} with 1 m");
    assert!(own < WIDE_NEAR_FIELD_SHARE, "{own}");
    assert!((whole - 1.0).abs() < 1e-12, "{whole}");
}
