//! The tissue the fit's tests make their uniaxial tests from, shared by the core's fit tests
//! and `pgd fit`'s: exponential, 3 kPa, stiffening at 3, compressed to 70 % in six stretches.

use pgd_surgery_core::fem::{Law, Material};

pub const YOUNG_PA: f64 = 3.0e3;
pub const STIFFENING: f64 = 3.0;
pub const POISSON: f64 = 0.45;

pub fn tissue() -> Material {
    Material::new(Law::Exponential, YOUNG_PA, POISSON, 1000.0)
        .and_then(|m| m.with_stiffening(STIFFENING))
        .unwrap()
}

/// Compression to 70 %, as tissue tests go, in six stretches.
pub fn stretches() -> Vec<f64> {
    (1..=6).map(|i| 1.0 - 0.05 * i as f64).collect()
}
