//! `pgd fit`: a uniaxial test read from CSV and fitted, or refused naming the file and line.
//! (The fit itself against full FEM is the core's, `fem` tests.)

use pgd_surgery::fem::{Law, Material, uniaxial_nominal_stress_pa};

const STIFFENING: f64 = 3.0;
const POISSON: f64 = 0.45;

/// Exponential tissue of 3 kPa stiffening at 3, compressed to 70 % in six stretches.
fn tissue() -> Material {
    Material::new(Law::Exponential, 3.0e3, POISSON, 1000.0)
        .and_then(|m| m.with_stiffening(STIFFENING))
        .unwrap()
}

fn stretches() -> Vec<f64> {
    (1..=6).map(|i| 1.0 - 0.05 * i as f64).collect()
}

/// `pgd fit` reads a test from CSV and fits it; a bad row is refused naming the file and line.
#[test]
fn a_test_file_is_read_and_fitted_or_refused_by_line() {
    let dir = std::env::temp_dir().join(format!("pgd-fit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("test.csv");
    let rows: String = stretches()
        .into_iter()
        .map(|s| format!("{s}, {}\n", uniaxial_nominal_stress_pa(&tissue(), s)))
        .collect();
    std::fs::write(&good, format!("stretch, nominal_stress_pa\n{rows}")).unwrap();
    let report = pgd_surgery::cli::fit_uniaxial_test(&good, POISSON).unwrap();
    assert_eq!(report.points, 6);
    assert!(
        (report.fit.stiffening / STIFFENING - 1.0).abs() < 1e-6,
        "{:?}",
        report.fit
    );

    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "stretch,nominal_stress_pa\n0.9,-100\n0.8,soft\n").unwrap();
    let error = pgd_surgery::cli::fit_uniaxial_test(&bad, POISSON).unwrap_err();
    assert!(
        error.contains("bad.csv") && error.contains("line 3"),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
