//! Fitting the exponential law to uniaxial tests of tissue: Young's modulus `E` and stiffening
//! `b` from measured nominal stress against stretch.
//!
//! A bar with free sides, stretched (or compressed) by `a` along its axis, takes the lateral
//! stretch `t` that leaves its sides free of stress, `μ e^{b x} (t − 1/t) + λ ln(a t²) / t = 0`
//! with `x = a² + 2t² − 3 − 2 ln(a t²)`, and carries the nominal stress
//! `P₁₁ = μ e^{b x} (a − 1/a) + λ ln(a t²) / a`. At a fixed Poisson's ratio, λ and μ scale with
//! `E` and `t` does not depend on it, so `P₁₁ = E p(a; b)`: for each `b` the best `E` is a
//! linear least-squares fit, and `b` is the one-dimensional minimum of what remains.

use serde::{Deserialize, Serialize};

use super::{FemError, Law, Material, TISSUE_DENSITY_KG_M3};

/// One measurement of a uniaxial test (a row of `pgd fit`'s CSV).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
pub struct UniaxialPoint {
    /// Deformed over reference length along the load (below 1 in compression).
    pub stretch: f64,
    /// Force over reference area (Pa), negative in compression.
    pub nominal_stress_pa: f64,
}

/// The exponential law that fits a uniaxial test best in least squares.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ExponentialFit {
    pub young_pa: f64,
    pub stiffening: f64,
    pub poisson: f64,
    /// Root mean square of the stress residuals (Pa).
    pub rms_pa: f64,
    /// The neo-Hookean law's best fit (b = 0) to the same points, for comparison.
    pub neo_hookean_young_pa: f64,
    pub neo_hookean_rms_pa: f64,
}

impl ExponentialFit {
    /// The fitted material.
    pub fn material(&self) -> Result<Material, FemError> {
        exponential(self.young_pa, self.poisson, self.stiffening)
    }
}

/// The largest stiffening the fit considers: `e^{b x}` overflows beyond any measured range.
const MAX_STIFFENING: f64 = 50.0;

/// Nominal stress (Pa) of a bar of `material` (neo-Hookean or exponential) with free sides at
/// axial `stretch`.
pub fn uniaxial_nominal_stress_pa(material: &Material, stretch: f64) -> f64 {
    let (lambda, mu) = material.lame();
    let b = match material.law {
        Law::Exponential => material.stiffening,
        _ => 0.0,
    };
    let state = |t: f64| {
        let log_j = (stretch * t * t).ln();
        let x = stretch * stretch + 2.0 * t * t - 3.0 - 2.0 * log_j;
        (mu * (b * x).exp(), lambda * log_j)
    };
    // The lateral stress grows with t: bisect for its zero.
    let lateral = |t: f64| {
        let (shear, volume) = state(t);
        shear * (t - 1.0 / t) + volume / t
    };
    let (mut low, mut high): (f64, f64) = (1e-2, 1e2);
    for _ in 0..200 {
        let mid = (low * high).sqrt();
        if lateral(mid) > 0.0 {
            high = mid;
        } else {
            low = mid;
        }
    }
    let (shear, volume) = state((low * high).sqrt());
    shear * (stretch - 1.0 / stretch) + volume / stretch
}

/// Fits `E` and `b` at Poisson's ratio `poisson` to `points` (at least two, with finite values
/// and positive stretches other than 1).
pub fn fit_exponential(points: &[UniaxialPoint], poisson: f64) -> Result<ExponentialFit, FemError> {
    check_points(points)?;
    exponential(1.0, poisson, 0.0)?;
    let misfit = |b: f64| best_modulus(points, poisson, b);
    // A coarse scan first (the misfit need not be unimodal over the whole range), then a golden
    // section search in the bracket around the scan's best.
    let grid: Vec<f64> = (0..=100)
        .map(|i| MAX_STIFFENING * (i as f64 / 100.0).powi(2))
        .collect();
    let squares: Vec<f64> = grid.iter().map(|&b| misfit(b).1).collect();
    let best = (0..grid.len())
        .min_by(|&i, &j| squares[i].total_cmp(&squares[j]))
        .expect("the grid is not empty");
    let low = grid[best.saturating_sub(1)];
    let high = grid[(best + 1).min(grid.len() - 1)];
    let stiffening = golden_section(low, high, |b| misfit(b).1);
    let (young_pa, squares) = misfit(stiffening);
    let (neo_hookean_young_pa, neo_hookean_squares) = misfit(0.0);
    let n = points.len() as f64;
    Ok(ExponentialFit {
        young_pa,
        stiffening,
        poisson,
        rms_pa: (squares / n).sqrt(),
        neo_hookean_young_pa,
        neo_hookean_rms_pa: (neo_hookean_squares / n).sqrt(),
    })
}

fn exponential(young_pa: f64, poisson: f64, stiffening: f64) -> Result<Material, FemError> {
    Material::new(Law::Exponential, young_pa, poisson, TISSUE_DENSITY_KG_M3)?
        .with_stiffening(stiffening)
}

/// The least-squares modulus at stiffening `b`, and its sum of squared residuals.
fn best_modulus(points: &[UniaxialPoint], poisson: f64, b: f64) -> (f64, f64) {
    let unit = exponential(1.0, poisson, b).expect("checked by the caller");
    let shapes: Vec<f64> = points
        .iter()
        .map(|p| uniaxial_nominal_stress_pa(&unit, p.stretch))
        .collect();
    let along: f64 = points
        .iter()
        .zip(&shapes)
        .map(|(p, s)| p.nominal_stress_pa * s)
        .sum();
    let norm: f64 = shapes.iter().map(|s| s * s).sum();
    let young_pa = along / norm;
    let squares = points
        .iter()
        .zip(&shapes)
        .map(|(p, s)| (p.nominal_stress_pa - young_pa * s).powi(2))
        .sum::<f64>();
    match squares.is_finite() {
        true => (young_pa, squares),
        false => (young_pa, f64::INFINITY),
    }
}

/// The minimum of `f` on `[low, high]` to a relative width of 1e-10.
fn golden_section(mut low: f64, mut high: f64, f: impl Fn(f64) -> f64) -> f64 {
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let mut a = high - ratio * (high - low);
    let mut b = low + ratio * (high - low);
    let (mut fa, mut fb) = (f(a), f(b));
    while high - low > 1e-10 * high.max(1e-3) {
        if fa < fb {
            high = b;
            (b, fb) = (a, fa);
            a = high - ratio * (high - low);
            fa = f(a);
        } else {
            low = a;
            (a, fa) = (b, fb);
            b = low + ratio * (high - low);
            fb = f(b);
        }
    }
    0.5 * (low + high)
}

fn check_points(points: &[UniaxialPoint]) -> Result<(), FemError> {
    if points.len() < 2 {
        return Err(FemError::InvalidInput {
            what: "uniaxial test: point count",
            value: points.len() as f64,
            problem: "too few to fit a modulus and a stiffening (two at least)",
        });
    }
    for p in points {
        if !(p.stretch.is_finite() && p.stretch > 0.0 && p.stretch != 1.0) {
            return Err(FemError::InvalidInput {
                what: "uniaxial test: stretch",
                value: p.stretch,
                problem: "not a positive, finite stretch other than 1",
            });
        }
        if !p.nominal_stress_pa.is_finite() {
            return Err(FemError::InvalidInput {
                what: "uniaxial test: nominal stress",
                value: p.nominal_stress_pa,
                problem: "not finite",
            });
        }
    }
    Ok(())
}
