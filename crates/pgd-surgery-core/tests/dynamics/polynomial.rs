//! The polynomial reduced KSV force is the full FEM internal force projected on the basis.

use pgd_surgery_core::fem::Law;

use crate::common::{liver_block, lowest_modes, pseudo_random};

/// At coordinates that strain the block by tens of per cent (the nonlinear terms a large part
/// of the force), `Φᵀ f_int(Φ q)` from full KSV FEM and the polynomial force agree to 1e-10
/// relative; the Simo–Tarnow force's work over a finite step is the energy's change (1e-10).
#[test]
fn the_polynomial_force_is_the_projected_fem_force() {
    let model = liver_block([4, 3, 2], Law::KirchhoffSaintVenant);
    let (basis, reduced) = lowest_modes(&model, 8);
    let mut scratch = reduced.scratch();
    for seed in 1..4 {
        let q: Vec<f64> = pseudo_random(8, seed).iter().map(|x| 3e-3 * x).collect();
        let u = basis.displacement(&q);
        let largest = u.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let reference = basis.project(&model.internal_force(&u));
        let mut force = vec![0.0; 8];
        reduced.force(&q, &mut force, &mut scratch);
        let linear: Vec<f64> = (0..8)
            .map(|i| (0..8).map(|j| reduced.stiffness()[i * 8 + j] * q[j]).sum())
            .collect();
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let diff =
            |a: &[f64], b: &[f64]| norm(&a.iter().zip(b).map(|(x, y)| x - y).collect::<Vec<_>>());
        let error = diff(&force, &reference) / norm(&reference);
        let nonlinear = diff(&linear, &reference) / norm(&reference);
        eprintln!(
            "seed {seed}: largest displacement {:.1} mm, error {error:.1e}, nonlinear share {nonlinear:.2}",
            largest * 1e3
        );
        assert!(error < 1e-10, "{error}");
        assert!(
            nonlinear > 0.05,
            "the nonlinear terms should matter: {nonlinear}"
        );

        let q1: Vec<f64> = q
            .iter()
            .zip(pseudo_random(8, seed + 10))
            .map(|(a, b)| a + 2e-3 * b)
            .collect();
        reduced.algorithmic_force((&q, &q1), &mut force, &mut scratch);
        let work: f64 = force
            .iter()
            .zip(q1.iter().zip(&q))
            .map(|(f, (b, a))| f * (b - a))
            .sum();
        let change = reduced.energy(&q1) - reduced.energy(&q);
        assert!(
            (work - change).abs() < 1e-10 * change.abs(),
            "{work} against {change}"
        );
    }
}

/// The neo-Hookean law has no polynomial energy: refused with a message naming the laws that
/// have one.
#[test]
fn a_law_without_a_polynomial_energy_is_refused() {
    let model = liver_block([2, 2, 1], Law::NeoHookean);
    let basis = pgd_surgery_core::dynamics::ModalBasis::ritz(
        &model,
        &crate::common::whole_space(&model),
        4,
    )
    .unwrap();
    let error = pgd_surgery_core::dynamics::ReducedKsv::new(&model, &basis).unwrap_err();
    assert!(
        error.to_string().contains("Kirchhoff–Saint Venant"),
        "{error}"
    );
}

/// The Simo–Tarnow force's Jacobian in `q₁` against central differences (step 1e-7 of the
/// coordinates' scale; 1e-6 relative), at a large step with the nonlinear terms dominant.
#[test]
fn the_algorithmic_jacobian_matches_finite_differences() {
    let model = liver_block([3, 2, 2], Law::KirchhoffSaintVenant);
    let (_, reduced) = lowest_modes(&model, 6);
    let mut scratch = reduced.scratch();
    let q0: Vec<f64> = pseudo_random(6, 21).iter().map(|x| 3e-3 * x).collect();
    let q1: Vec<f64> = pseudo_random(6, 22).iter().map(|x| 3e-3 * x).collect();
    let mut jacobian = vec![0.0; 36];
    reduced.algorithmic_jacobian((&q0, &q1), &mut jacobian, &mut scratch);
    let step = 3e-10;
    let (mut plus, mut minus) = (vec![0.0; 6], vec![0.0; 6]);
    let largest = jacobian.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    for n in 0..6 {
        let mut q = q1.clone();
        q[n] += step;
        reduced.algorithmic_force((&q0, &q), &mut plus, &mut scratch);
        q[n] -= 2.0 * step;
        reduced.algorithmic_force((&q0, &q), &mut minus, &mut scratch);
        for m in 0..6 {
            let fd = (plus[m] - minus[m]) / (2.0 * step);
            let exact = jacobian[m * 6 + n];
            assert!(
                (fd - exact).abs() < 1e-6 * largest,
                "({m}, {n}): {exact} against {fd}"
            );
        }
    }
}
