//! The reduced dynamics in the vademecum's basis against full FEM: it settles under a held
//! load onto the static answer, and it swings at the organ's lowest eigenfrequency.

use nalgebra::{DVector, SymmetricEigen, Vector3};
use pgd_surgery_core::dynamics::{EnergyMomentum, RayleighDamping, ReducedState};
use pgd_surgery_core::fem::{FemModel, Law, Loads, NewtonSettings};

use crate::common::{KEEP, dense, liver_block, vademecum_basis};

const TICK_S: f64 = 1e-3;

/// The lowest eigenpair of the full model (`K φ = ω² M φ`, dense, by Cholesky of `M`): ω²
/// and the mode over free dofs.
fn full_lowest_mode(model: &FemModel) -> (f64, DVector<f64>) {
    let k = dense(model, &model.rest_stiffness());
    let m = dense(model, &model.consistent_mass());
    let l = m.cholesky().unwrap().l();
    let l_inv = l.clone().try_inverse().unwrap();
    let a = &l_inv * k * l_inv.transpose();
    let eigen = SymmetricEigen::new(0.5 * (&a + a.transpose()));
    let lowest = (0..eigen.eigenvalues.len())
        .min_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]))
        .unwrap();
    let mode = l_inv.transpose() * eigen.eigenvectors.column(lowest);
    (eigen.eigenvalues[lowest], mode)
}

/// The top node that the lowest mode moves most, and the direction it moves it.
fn pull_point(model: &FemModel, mode: &DVector<f64>) -> (usize, Vector3<f64>) {
    let dofs = model.dofs();
    let at = |n: usize| {
        Vector3::from_fn(|c, _| match dofs.free_index[3 * n + c] {
            pgd_surgery_core::fem::PRESCRIBED => 0.0,
            i => mode[i],
        })
    };
    let top = model.mesh().node_set("z1").unwrap();
    let node = *top
        .iter()
        .max_by(|&&a, &&b| at(a).norm().total_cmp(&at(b).norm()))
        .unwrap();
    (node, at(node).normalize())
}

/// A force at `node` along `direction` (N) over all dofs.
fn point_force(model: &FemModel, node: usize, force: Vector3<f64>) -> Vec<f64> {
    let mut f = vec![0.0; 3 * model.mesh().node_count()];
    for c in 0..3 {
        f[3 * node + c] = force[c];
    }
    f
}

/// Pulled sideways at the top node that the lowest mode moves most and let go with no
/// damping, the block swings at the lowest eigenfrequency of the full model within 5 %
/// (measured from the zero crossings of the top face's mean displacement over 2 s); the
/// basis's lowest frequency is the full model's within 0.1 %.
#[test]
fn released_it_swings_at_the_lowest_eigenfrequency() {
    let model = liver_block([6, 4, 3], Law::Linear);
    let (omega2, mode) = full_lowest_mode(&model);
    let full_hz = omega2.sqrt() / (2.0 * std::f64::consts::PI);
    let (basis, reduced) = vademecum_basis(&model);
    let (node, direction) = pull_point(&model, &mode);
    let pull = basis.project(&point_force(&model, node, direction * 0.02));
    let mut state = ReducedState::at_rest(KEEP);
    state.q = basis.static_coordinates(&pull);
    let mut step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, RayleighDamping::NONE);
    // The top face's mean displacement along the pull: the local modes a point load also
    // excites average out of it.
    let top = model.mesh().node_set("z1").unwrap();
    let along = |q: &[f64]| {
        let u = basis.displacement(q);
        let sum: f64 = top
            .iter()
            .map(|&n| Vector3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]).dot(&direction))
            .sum();
        sum / top.len() as f64
    };
    let mut signal = Vec::new();
    for _ in 0..2000 {
        step.step(&reduced, &mut state, &[0.0; KEEP]).unwrap();
        signal.push(along(&state.q));
    }
    let mean = signal.iter().sum::<f64>() / signal.len() as f64;
    let crossings: Vec<f64> = signal
        .windows(2)
        .enumerate()
        .filter(|(_, w)| (w[0] - mean) * (w[1] - mean) < 0.0)
        .map(|(k, w)| (k as f64 + (mean - w[0]) / (w[1] - w[0])) * TICK_S)
        .collect();
    let swing_hz =
        (crossings.len() - 1) as f64 / (2.0 * (crossings[crossings.len() - 1] - crossings[0]));
    let ritz_hz = basis.omega2[0].sqrt() / (2.0 * std::f64::consts::PI);
    eprintln!(
        "full FEM {full_hz:.3} Hz, Ritz {ritz_hz:.3} Hz, swing {swing_hz:.3} Hz ({} crossings)",
        crossings.len()
    );
    assert!(crossings.len() > 10);
    assert!(
        (ritz_hz - full_hz).abs() < 1e-3 * full_hz,
        "the basis's lowest mode: {ritz_hz} Hz"
    );
    assert!(
        (swing_hz - full_hz).abs() < 0.05 * full_hz,
        "{swing_hz} Hz against {full_hz} Hz"
    );
}

/// Damped (Rayleigh, 10 % of critical at the lowest and highest kept modes) under a held
/// load, the block settles within 3 s onto the static answer: the kept modes at their static
/// coordinates, plus the static remainder they miss, equal the full FEM solve at the loaded
/// node within 1 %.
#[test]
fn damped_under_a_held_load_it_settles_onto_the_static_answer() {
    let model = liver_block([6, 4, 3], Law::Linear);
    let (basis, reduced) = vademecum_basis(&model);
    let top = model.mesh().node_set("z1").unwrap();
    let node = top[top.len() / 2];
    let force = Vector3::new(0.005, 0.0, -0.02);
    let full = point_force(&model, node, force);
    let mut loads = Loads::new(model.mesh().node_count());
    loads.add_nodal_force(node, force.into()).unwrap();
    let exact = model
        .solve_static(&loads, &NewtonSettings::default())
        .unwrap()
        .displacement_m;
    let generalized = basis.project(&full);
    let omega = |k: usize| basis.omega2[k].sqrt();
    let damping = RayleighDamping::with_ratio(0.1, omega(0), omega(KEEP - 1));
    let mut step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, damping);
    let mut state = ReducedState::at_rest(KEEP);
    for _ in 0..3000 {
        step.step(&reduced, &mut state, &generalized).unwrap();
    }
    let static_part = basis.displacement(&basis.static_coordinates(&generalized));
    let dynamic_part = basis.displacement(&state.q);
    let at = |u: &[f64]| Vector3::new(u[3 * node], u[3 * node + 1], u[3 * node + 2]);
    let settled = at(&dynamic_part) + at(&exact) - at(&static_part);
    let error = (settled - at(&exact)).norm() / at(&exact).norm();
    let share = at(&static_part).norm() / at(&exact).norm();
    eprintln!(
        "settled {settled:?} against {:?}: {error:.1e}; the kept modes carry {share:.2} of it",
        at(&exact)
    );
    assert!(error < 0.01, "{error}");
}
