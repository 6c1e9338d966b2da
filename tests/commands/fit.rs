//! `pgd fit`: a uniaxial test read from CSV and fitted, or refused naming the file and line.
//! (The fit itself against full FEM is the core's, `fem` tests.)

use pgd_surgery::fem::uniaxial_nominal_stress_pa;

use crate::uniaxial::{POISSON, STIFFENING, stretches, tissue};

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
