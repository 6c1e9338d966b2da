//! What the energy–momentum step conserves: energy over 10⁵ ticks with the nonlinear terms
//! large, momentum of a free body, and both at a step far longer than the model's periods.

use nalgebra::{DVector, Vector3};
use pgd_surgery_core::dynamics::{EnergyMomentum, RayleighDamping, ReducedKsv, ReducedState};
use pgd_surgery_core::fem::{Law, Material, TISSUE_DENSITY_KG_M3};

use crate::common::{block, dense, liver_block, lowest_modes, pseudo_random};

const TICK_S: f64 = 1e-3;

/// Runs `steps` undamped, unloaded steps from `state` (solved to round-off or to the
/// real-time tolerance); returns the largest relative change of `T + W` and the largest
/// nonlinear share of the strain energy seen.
fn energy_drift(
    reduced: &ReducedKsv,
    omega2: &[f64],
    (state, to_round_off): (&mut ReducedState, bool),
    steps: usize,
) -> (f64, f64) {
    let mut step = EnergyMomentum::new(reduced, omega2, TICK_S, RayleighDamping::NONE);
    step.to_round_off = to_round_off;
    let external = vec![0.0; reduced.len()];
    let energy = |s: &ReducedState| s.kinetic_energy() + reduced.energy(&s.q);
    let start = energy(state);
    let (mut drift, mut nonlinear) = (0.0_f64, 0.0_f64);
    for _ in 0..steps {
        step.step(reduced, state, &external).unwrap();
        drift = drift.max((energy(state) - start).abs() / start);
        let w = reduced.energy(&state.q);
        let quadratic: f64 = 0.5
            * (0..state.q.len())
                .map(|i| {
                    state.q[i]
                        * (0..state.q.len())
                            .map(|j| reduced.stiffness()[i * state.q.len() + j] * state.q[j])
                            .sum::<f64>()
                })
                .sum::<f64>();
        if w > 0.1 * start {
            nonlinear = nonlinear.max((w - quadratic).abs() / w);
        }
    }
    (drift, nonlinear)
}

/// Undamped, unloaded, thrown with a velocity that strains the block by tens of per cent:
/// solved to round-off, `T + W` stays constant to 1e-9 relative over 10⁵ ticks (100 s;
/// measured 3.8e-14), while the nonlinear terms carry over 5 % of the strain energy at times.
/// At the real-time default tolerance (1e-9 per step) the drift stays below 1e-6 (measured
/// 6.1e-8).
#[test]
fn energy_is_conserved_over_a_hundred_thousand_ticks() {
    let model = liver_block([4, 3, 2], Law::KirchhoffSaintVenant);
    let (basis, reduced) = lowest_modes(&model, 8);
    let thrown = || ReducedState {
        q: vec![0.0; 8],
        v: pseudo_random(8, 3).iter().map(|x| 0.3 * x).collect(),
    };
    let (drift, nonlinear) = energy_drift(&reduced, &basis.omega2, (&mut thrown(), true), 100_000);
    let (real_time, _) = energy_drift(&reduced, &basis.omega2, (&mut thrown(), false), 100_000);
    eprintln!(
        "energy drift {drift:.1e} (to round-off), {real_time:.1e} (real-time tolerance); nonlinear share up to {nonlinear:.2}"
    );
    assert!(drift < 1e-9, "{drift}");
    assert!(real_time < 1e-6, "{real_time}");
    assert!(nonlinear > 0.05, "{nonlinear}");
}

/// Linear and angular momentum of the body (consistent mass; positions as deformed).
fn momenta(
    model: &pgd_surgery_core::fem::FemModel,
    mass: &nalgebra::DMatrix<f64>,
    u: &[f64],
    v: &[f64],
) -> (Vector3<f64>, Vector3<f64>) {
    let p = mass * DVector::from_column_slice(v);
    let (mut linear, mut angular) = (Vector3::zeros(), Vector3::zeros());
    for (a, node) in model.mesh().nodes().iter().enumerate() {
        let pa = Vector3::new(p[3 * a], p[3 * a + 1], p[3 * a + 2]);
        let x = node.coords + Vector3::new(u[3 * a], u[3 * a + 1], u[3 * a + 2]);
        linear += pa;
        angular += x.cross(&pa);
    }
    (linear, angular)
}

/// A free cube of liver tissue (no boundary condition, all 24 modes kept: the reduced model
/// is the full one), thrown spinning and deforming: linear and angular momentum stay at their
/// start, over 5,000 ticks while it turns by more than a radian, to what the step's solve
/// leaves: it stops where an update no longer halves below 1e-12 relative (round-off in the
/// polynomial force, whose linear and quadratic terms are each of order one at a radian's
/// rotation and cancel), so the bound is 5,000 × 1e-12 (measured 2.3e-9 at 2.1 rad).
#[test]
fn a_free_body_conserves_linear_and_angular_momentum() {
    let model = block([1, 1, 1], Material::liver(Law::KirchhoffSaintVenant), false);
    let (basis, reduced) = lowest_modes(&model, 24);
    let mass = dense(&model, &model.consistent_mass());
    let mut state = ReducedState::at_rest(24);
    state.v = pseudo_random(24, 5).iter().map(|x| 0.01 * x).collect();
    let mut step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, RayleighDamping::NONE);
    step.to_round_off = true;
    let external = vec![0.0; 24];
    let now = |s: &ReducedState| {
        momenta(
            &model,
            &mass,
            &basis.displacement(&s.q),
            &basis.displacement(&s.v),
        )
    };
    let (p0, l0) = now(&state);
    let (mut turned, mut drift) = (0.0_f64, 0.0_f64);
    for _ in 0..5000 {
        step.step(&reduced, &mut state, &external).unwrap();
        let (p, l) = now(&state);
        drift = drift
            .max((p - p0).norm() / p0.norm())
            .max((l - l0).norm() / l0.norm());
        let u = basis.displacement(&state.q);
        let (a, b) = (
            model.mesh().nodes()[0].coords,
            model.mesh().nodes()[7].coords,
        );
        let ua = Vector3::new(u[0], u[1], u[2]);
        let ub = Vector3::new(u[21], u[22], u[23]);
        let (rest, now) = (b - a, b + ub - a - ua);
        turned = turned.max(
            (rest.dot(&now) / (rest.norm() * now.norm()))
                .clamp(-1.0, 1.0)
                .acos(),
        );
    }
    eprintln!("momenta drift {drift:.1e}; the diagonal turned up to {turned:.2} rad");
    assert!(drift < 5000.0 * 1e-12, "{drift}");
    assert!(turned > 1.0, "{turned}");
}

/// A block of a 1 GPa material (600,000 times the liver's modulus): its 20 kept modes have
/// periods from 0.22 ms down to 0.05 ms, four to twenty of them per 1 ms step, yet the step
/// keeps the energy to 1e-9 and the coordinates within what that energy allows over 10⁴
/// ticks.
#[test]
fn a_step_longer_than_every_period_stays_bounded() {
    let material =
        Material::new(Law::KirchhoffSaintVenant, 1e9, 0.3, TISSUE_DENSITY_KG_M3).unwrap();
    let model = block([3, 2, 2], material, true);
    let (basis, reduced) = lowest_modes(&model, 20);
    let periods: Vec<f64> = basis
        .omega2
        .iter()
        .map(|w2| 2.0 * std::f64::consts::PI / w2.sqrt())
        .collect();
    eprintln!(
        "periods from {:.2e} s to {:.2e} s",
        periods[0],
        periods[periods.len() - 1]
    );
    assert!(periods[0] < 0.25 * TICK_S && periods[periods.len() - 1] < 0.06 * TICK_S);
    let mut state = ReducedState::at_rest(20);
    state.v = pseudo_random(20, 9).iter().map(|x| 0.5 * x).collect();
    let energy = state.kinetic_energy();
    let (drift, _) = energy_drift(&reduced, &basis.omega2, (&mut state, true), 10_000);
    eprintln!("energy drift {drift:.1e}");
    assert!(drift < 1e-9, "{drift}");
    let bound = (2.0 * energy / basis.omega2[0]).sqrt() * 1.01;
    assert!(
        state.q.iter().all(|q| q.abs() <= bound),
        "{:?} beyond {bound}",
        state.q
    );
}
