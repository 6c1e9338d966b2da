//! The exponential law's fit to uniaxial tests: stresses from full FEM of a compressed cube
//! give back the modulus and stiffening they were made with.

use pgd_surgery_core::fem::{FemError, UniaxialPoint, fit_exponential, uniaxial_nominal_stress_pa};

use crate::hyperelastic::end_stress_pa;
use crate::uniaxial::{POISSON, STIFFENING, YOUNG_PA, stretches, tissue};

/// The closed-form uniaxial stress (lateral stretch by bisection) is what full FEM of a cube on
/// rollers carries, to 1e-8.
#[test]
fn the_uniaxial_stress_is_the_fem_cubes() {
    for stretch in [0.7, 1.2] {
        let fem = end_stress_pa(tissue(), stretch);
        let closed = uniaxial_nominal_stress_pa(&tissue(), stretch);
        assert!(
            (fem - closed).abs() <= 1e-8 * fem.abs(),
            "stretch {stretch}: FEM {fem} Pa, closed form {closed} Pa"
        );
    }
}

/// From the FEM cube's stresses the fit returns E and b to 1e-6, with a residual far below the
/// neo-Hookean law's best.
#[test]
fn the_fit_recovers_the_law_from_fem_stresses() {
    let points: Vec<UniaxialPoint> = stretches()
        .into_iter()
        .map(|stretch| UniaxialPoint {
            stretch,
            nominal_stress_pa: end_stress_pa(tissue(), stretch),
        })
        .collect();
    let fit = fit_exponential(&points, POISSON).unwrap();
    assert!(
        (fit.young_pa / YOUNG_PA - 1.0).abs() < 1e-6
            && (fit.stiffening / STIFFENING - 1.0).abs() < 1e-6,
        "{fit:?}"
    );
    assert!(fit.rms_pa < 1e-3 * fit.neo_hookean_rms_pa, "{fit:?}");
}

/// With ±3 % alternating noise on the stresses, the fit stays within 10 % on both.
#[test]
fn the_fit_tolerates_measurement_noise() {
    let points: Vec<UniaxialPoint> = stretches()
        .into_iter()
        .enumerate()
        .map(|(i, stretch)| UniaxialPoint {
            stretch,
            nominal_stress_pa: uniaxial_nominal_stress_pa(&tissue(), stretch)
                * if i % 2 == 0 { 1.03 } else { 0.97 },
        })
        .collect();
    let fit = fit_exponential(&points, POISSON).unwrap();
    assert!(
        (fit.young_pa / YOUNG_PA - 1.0).abs() < 0.1
            && (fit.stiffening / STIFFENING - 1.0).abs() < 0.1,
        "{fit:?}"
    );
}

#[test]
fn the_fit_refuses_too_few_or_impossible_points() {
    let point = |stretch, nominal_stress_pa| UniaxialPoint {
        stretch,
        nominal_stress_pa,
    };
    let refused = |points: &[UniaxialPoint], what: &str| {
        let error = fit_exponential(points, POISSON).unwrap_err();
        assert!(
            matches!(&error, FemError::InvalidInput { what: w, .. } if w.contains(what)),
            "{error}"
        );
    };
    refused(&[point(0.9, -100.0)], "point count");
    refused(&[point(0.9, -100.0), point(-0.1, -50.0)], "stretch");
    refused(&[point(0.9, -100.0), point(1.0, 0.0)], "stretch");
    refused(
        &[point(0.9, -100.0), point(0.8, f64::NAN)],
        "nominal stress",
    );
}
