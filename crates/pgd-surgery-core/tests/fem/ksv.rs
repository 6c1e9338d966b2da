//! Kirchhoff–Saint Venant: its tangent, its small-load limit, and Newton's convergence rate.

use pgd_surgery_core::fem::{FemModel, Law, NewtonSettings, PRESCRIBED};

use crate::beams::{LENGTH_M, cantilever};

/// A deterministic pseudo-random sequence in [−1, 1] (no rand dependency for tests).
fn pseudo_random(seed: u64, len: usize) -> Vec<f64> {
    let mut state = seed;
    (0..len)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

/// `‖K v − (f(u + hv) − f(u − hv)) / 2h‖ / ‖…‖` over free dofs, for a rough random displacement
/// `u` of size `size_m` (element strains of tens of percent, where the nonlinear terms of the
/// tangent matter) and a random direction `v`, both zero on clamped dofs.
pub fn tangent_error(model: &FemModel, size_m: f64) -> f64 {
    let dofs = model.dofs();
    let mut u = pseudo_random(1, 3 * model.mesh().node_count());
    let mut v = pseudo_random(2, u.len());
    for d in 0..u.len() {
        if dofs.free_index[d] == PRESCRIBED {
            u[d] = 0.0;
            v[d] = 0.0;
        }
        u[d] *= size_m;
    }
    let (_, tangent) = model.force_and_tangent(&u);
    let mut kv = vec![0.0; dofs.free_count()];
    model.pattern().mul(&tangent, &dofs.restrict(&v), &mut kv);
    let h = 1e-7;
    let shifted = |sign: f64| -> Vec<f64> {
        let w: Vec<f64> = u.iter().zip(&v).map(|(a, b)| a + sign * h * b).collect();
        dofs.restrict(&model.internal_force(&w))
    };
    let (plus, minus) = (shifted(1.0), shifted(-1.0));
    let (mut diff, mut scale) = (0.0, 0.0);
    for ((k, p), m) in kv.iter().zip(&plus).zip(&minus) {
        let fd = (p - m) / (2.0 * h);
        diff += (k - fd) * (k - fd);
        scale += fd * fd;
    }
    (diff / scale).sqrt()
}

#[test]
fn tangent_matches_finite_differences_of_the_internal_force() {
    let beam = cantilever(1, Law::KirchhoffSaintVenant, 0.45, 0.0);
    let error = tangent_error(&beam.model, 2e-3);
    assert!(
        error < 1e-7,
        "tangent vs central differences: relative error {error:e}"
    );
}

/// ‖u_KSV − u_linear‖ / ‖u_linear‖ for the cantilever under a tip force.
fn nonlinear_departure(tip_force_n: f64) -> f64 {
    let settings = NewtonSettings {
        relative_tolerance: 1e-12,
        ..NewtonSettings::default()
    };
    let linear = cantilever(2, Law::Linear, 0.3, tip_force_n).solve(&settings);
    let ksv = cantilever(2, Law::KirchhoffSaintVenant, 0.3, tip_force_n).solve(&settings);
    let diff: f64 = linear
        .displacement_m
        .iter()
        .zip(&ksv.displacement_m)
        .map(|(a, b)| (a - b).powi(2))
        .sum();
    let size: f64 = linear.displacement_m.iter().map(|a| a * a).sum();
    (diff / size).sqrt()
}

#[test]
fn ksv_equals_linear_elasticity_for_vanishing_loads() {
    // A tip force of 1e-9 N deflects the beam by about 1e-8 of its length.
    let tiny = nonlinear_departure(1e-9);
    let ten_times = nonlinear_departure(1e-8);
    assert!(
        tiny < 1e-6,
        "KSV departs from linear by {tiny:e} at a vanishing load"
    );
    // The departure is a genuine first-order effect of the load, not noise: it scales with it.
    let ratio = ten_times / tiny;
    assert!(
        (5.0..20.0).contains(&ratio),
        "departure should grow ~10× with the load, grew {ratio:.2}×"
    );
}

#[test]
fn newton_converges_quadratically_on_a_large_deflection() {
    // Beam theory would give a tip deflection of 80 % of the length (the locked mesh about half
    // that): large rotations, a truly nonlinear case.
    let beam = cantilever(2, Law::KirchhoffSaintVenant, 0.3, 2.0e-2);
    let settings = NewtonSettings {
        load_steps: 4,
        relative_tolerance: 1e-12,
        ..NewtonSettings::default()
    };
    let solution = beam.solve(&settings);
    let deflection = beam.tip_deflection_m(&solution);
    assert!(
        deflection > 0.1 * LENGTH_M,
        "deflection {deflection} m is not large"
    );
    // Quadratic convergence multiplies the number of correct digits by two per iteration. In
    // the asymptotic range (r_k < 1e-3) and above round-off (r_k+1 > 1e-12) require at least a
    // factor 1.5, r_k+1 ≤ r_k^1.5: a linearly convergent method, r_k+1 = c r_k, fails this as
    // soon as r_k < c².
    let mut pairs = 0;
    for step in &solution.steps {
        let r = &step.relative_residuals;
        for w in r.windows(2).filter(|w| w[0] < 1e-3 && w[1] > 1e-12) {
            pairs += 1;
            assert!(
                w[1] <= w[0].powf(1.5),
                "residual {:.2e} → {:.2e} is not quadratic: {r:?}",
                w[0],
                w[1]
            );
        }
        assert_eq!(
            step.step_lengths.last(),
            Some(&1.0),
            "final iterations must take full steps: {step:?}"
        );
        assert!(*r.last().unwrap() <= 1e-12);
    }
    assert!(
        pairs >= 4,
        "too few iterations in the asymptotic range ({pairs})"
    );
}

/// A displacement that mirrors the beam through a plane across its axis (`x → −x`, J = −1)
/// turns every element inside out; shrinking it to half its length (J = 1/2) turns none, nor
/// does rest. Checked on KSV, whose energy stays finite there.
#[test]
fn a_mirrored_beam_is_inside_out_and_a_shrunk_one_is_not() {
    let beam = cantilever(1, Law::KirchhoffSaintVenant, 0.45, 0.0);
    let model = &beam.model;
    let along_x = |scale: f64| -> Vec<f64> {
        let nodes = model.mesh().nodes();
        let mut u = vec![0.0; 3 * nodes.len()];
        for (n, p) in nodes.iter().enumerate() {
            u[3 * n] = (scale - 1.0) * p.x;
        }
        u
    };
    assert!(model.turns_an_element_inside_out(&along_x(-1.0)));
    assert!(!model.turns_an_element_inside_out(&along_x(0.5)));
    assert!(!model.turns_an_element_inside_out(&along_x(1.0)));
    assert!(
        model
            .internal_force(&along_x(-1.0))
            .iter()
            .all(|f| f.is_finite())
    );
}
