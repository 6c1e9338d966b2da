//! A restraint over the kept modes in the energy–momentum step: springs that hold the body
//! where it lies keep the step conservative, and raise a mode's frequency as a spring should.

use pgd_surgery_core::dynamics::{EnergyMomentum, RayleighDamping, ReducedKsv, ReducedState};
use pgd_surgery_core::fem::Law;

use crate::common::{liver_block, lowest_modes, pseudo_random};

const TICK_S: f64 = 1e-3;

/// `T + ½ qᵀ (Λ + K_r) q` of the linear model.
fn energy(reduced: &ReducedKsv, restraint: &[f64], state: &ReducedState) -> f64 {
    let r = state.q.len();
    let held: f64 = (0..r)
        .map(|i| {
            (0..r)
                .map(|j| state.q[i] * restraint[i * r + j] * state.q[j])
                .sum::<f64>()
        })
        .sum();
    state.kinetic_energy() + reduced.energy(&state.q) + 0.5 * held
}

/// The linear block's eight lowest modes held by a dense restraint (`G Gᵀ`, as large as the
/// highest kept mode's stiffness), undamped and thrown: `T + ½ qᵀ (Λ + K_r) q` stays constant
/// to 1e-9 relative over 20,000 ticks solved to round-off, the restraint's off-diagonal terms
/// included.
#[test]
fn a_restrained_body_conserves_its_energy() {
    let model = liver_block([4, 3, 2], Law::Linear);
    let (basis, reduced) = lowest_modes(&model, 8);
    let r = basis.len();
    let g = pseudo_random(r * r, 7);
    let scale = basis.omega2[r - 1] / r as f64;
    let restraint: Vec<f64> = (0..r * r)
        .map(|ij| {
            let (i, j) = (ij / r, ij % r);
            scale * (0..r).map(|k| g[i * r + k] * g[j * r + k]).sum::<f64>()
        })
        .collect();
    let mut step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, RayleighDamping::NONE);
    step.to_round_off = true;
    step.set_restraint(&restraint);
    let mut state = ReducedState {
        q: vec![0.0; r],
        v: pseudo_random(r, 3).iter().map(|x| 0.01 * x).collect(),
    };
    let external = vec![0.0; r];
    let start = energy(&reduced, &restraint, &state);
    let mut drift = 0.0_f64;
    for _ in 0..20_000 {
        step.step(&reduced, &mut state, &external).unwrap();
        drift = drift.max((energy(&reduced, &restraint, &state) - start).abs() / start);
    }
    eprintln!("restrained energy drift {drift:.1e}");
    assert!(drift < 1e-9, "{drift}");
}

/// The lowest mode held by a spring `k = 3 ω₀²` and let go from a displacement, undamped:
/// it swings at the midpoint rule's frequency for `√(ω₀² + k)`, `(2/h) atan(h ω / 2)`, to 1e-4
/// (the period from 40 zero crossings); unrestrained, at `ω₀`'s.
#[test]
fn a_spring_on_a_mode_raises_its_frequency_as_it_should() {
    let model = liver_block([4, 3, 2], Law::Linear);
    let (basis, reduced) = lowest_modes(&model, 8);
    let r = basis.len();
    let w0 = basis.omega2[0];
    for k in [0.0, 3.0 * w0] {
        let mut restraint = vec![0.0; r * r];
        restraint[0] = k;
        let mut step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, RayleighDamping::NONE);
        step.to_round_off = true;
        step.set_restraint(&restraint);
        let mut state = ReducedState::at_rest(r);
        state.q[0] = 1e-4;
        let external = vec![0.0; r];
        let mut crossings = Vec::new();
        let mut t = 0.0;
        while crossings.len() < 41 {
            let before = state.q[0];
            step.step(&reduced, &mut state, &external).unwrap();
            if before * state.q[0] < 0.0 {
                crossings.push(t + TICK_S * before / (before - state.q[0]));
            }
            t += TICK_S;
        }
        let period = (crossings[40] - crossings[0]) / 20.0;
        let omega = (w0 + k).sqrt();
        let expected =
            2.0 * std::f64::consts::PI / ((2.0 / TICK_S) * (TICK_S * omega / 2.0).atan());
        let error = (period - expected).abs() / expected;
        eprintln!("k = {k:.1}: period {period:.6} s against {expected:.6} s ({error:.1e})");
        assert!(error < 1e-4, "{error}");
    }
}
