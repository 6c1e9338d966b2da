//! The vademecum against full FEM at loads it was not built on, and the PGD against the
//! best separated sum of as many terms (Eckart–Young).

use pgd_surgery::fem::FemModel;
use pgd_surgery::pgd::{Silent, Vademecum, ValidationSettings, build, validate};

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
