//! The linear vademecum by greedy enrichment: one product `R(x) S(p)` per step, each found by
//! an alternating-directions fixed point (paper 002, eq. 3).
//!
//! In matrix form the problem is `K U W = F W`, with `K` the stiffness over free dofs, `F` the
//! regularized unit loads (one column per parameter) and `W` the parameter space's quadrature
//! weights (the accessible surface area of each load position). With `U_n = Σ X^k Y^kᵀ` known:
//! - `S` fixed: `K R = (F W S − K U_n W S) / (Sᵀ W S)` — one solve with the factorization of
//!   `K`, computed once for the whole build;
//! - `R` fixed: `S = (Fᵀ R − U_nᵀ K R) / (Rᵀ K R)` — closed form, no solve.

use super::load_patches::LoadOperator;
use super::separated::SeparatedField;
use super::stiffness::RestStiffness;
use crate::dense_sums::dot;
use crate::fem::FemError;

/// How the enrichment proceeds and when it stops.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PgdSettings {
    /// Stop once a new mode's amplitude falls below this fraction of the first mode's: a guard
    /// for a representation that is already exact. The build's error estimator decides first.
    pub tolerance: f64,
    /// At most this many modes.
    pub max_modes: usize,
    /// The fixed point has converged when the product changes by less than this (relative).
    pub fixed_point_tolerance: f64,
    pub max_fixed_point_iterations: usize,
}

impl Default for PgdSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-7,
            max_modes: 60,
            fixed_point_tolerance: 1e-3,
            max_fixed_point_iterations: 15,
        }
    }
}

/// One enrichment step, as reported to the user and to the convergence curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeReport {
    pub fixed_point_iterations: usize,
    pub fixed_point_converged: bool,
    /// `√(Rᵀ K R) · √(Sᵀ W S)`: the energy the mode carries.
    pub amplitude: f64,
    /// Amplitude relative to the first mode's: the stopping criterion.
    pub relative_amplitude: f64,
}

/// Builds the separated representation of `K⁻¹ F` for the loads `F` of `loads`, with parameter
/// quadrature weights `weights`. `progress` is called after each mode with its number and
/// report; the enrichment stops at the tolerance, the cap, or when `progress` returns false
/// (the caller's error estimator is satisfied).
pub fn enrich(
    stiffness: &RestStiffness,
    loads: &dyn LoadOperator,
    weights: &[f64],
    settings: &PgdSettings,
    progress: &mut dyn FnMut(&SeparatedField, &ModeReport) -> bool,
) -> Result<(SeparatedField, Vec<ModeReport>), FemError> {
    let mut field = SeparatedField::default();
    // K X^k over free dofs, kept so the S-step needs no product with K per old mode.
    let mut stiff_modes: Vec<Vec<f64>> = Vec::new();
    let mut reports = Vec::new();
    let mut first_amplitude = None;
    let free_dofs = &stiffness.model.dofs().free_dofs;
    while field.modes() < settings.max_modes {
        let mut s = starting_guess(loads.parameter_count(), field.modes());
        let mut r_free = vec![0.0; stiffness.free_count()];
        let mut iterations = 0;
        let mut converged = false;
        while iterations < settings.max_fixed_point_iterations {
            iterations += 1;
            let (previous_r, previous_s) = (r_free.clone(), s.clone());
            // R-step: one solve.
            let ws: Vec<f64> = s.iter().zip(weights).map(|(a, w)| a * w).collect();
            let alpha = dot(&s, &ws);
            let mut load = vec![0.0; stiffness.full_count()];
            loads.apply(&ws, &mut load);
            let mut r = stiffness.restrict(&load);
            stiffness.solve_block(&mut r);
            for (k, y) in field.parametric.iter().enumerate() {
                let c = dot(y, &ws);
                let x = &field.spatial[k];
                for (ri, &d) in r.iter_mut().zip(free_dofs) {
                    *ri -= c * x[d];
                }
            }
            r.iter_mut().for_each(|v| *v /= alpha);
            r_free = r;
            // S-step: closed form.
            let mut kr = vec![0.0; stiffness.free_count()];
            stiffness.mul(&r_free, &mut kr);
            let beta = dot(&r_free, &kr);
            loads.apply_transpose(&stiffness.extend(&r_free), &mut s);
            for (y, kx) in field.parametric.iter().zip(&stiff_modes) {
                let c = dot(kx, &r_free);
                for (si, yi) in s.iter_mut().zip(y) {
                    *si -= c * yi;
                }
            }
            s.iter_mut().for_each(|v| *v /= beta);
            if product_change(&r_free, &s, &previous_r, &previous_s)
                < settings.fixed_point_tolerance
            {
                converged = true;
                break;
            }
        }
        let mut kr = vec![0.0; stiffness.free_count()];
        stiffness.mul(&r_free, &mut kr);
        let energy_r = dot(&r_free, &kr).sqrt();
        let energy_s = s
            .iter()
            .zip(weights)
            .map(|(a, w)| a * a * w)
            .sum::<f64>()
            .sqrt();
        let amplitude = energy_r * energy_s;
        let first = *first_amplitude.get_or_insert(amplitude);
        let report = ModeReport {
            fixed_point_iterations: iterations,
            fixed_point_converged: converged,
            amplitude,
            relative_amplitude: if first > 0.0 { amplitude / first } else { 0.0 },
        };
        if !amplitude.is_finite() {
            return Err(FemError::NonFiniteMode {
                mode: field.modes() + 1,
            });
        }
        if energy_r == 0.0 {
            // Nothing left that the loads can excite: the representation is exact.
            break;
        }
        // Store X with unit energy and the amplitude in Y, so mode sizes are comparable.
        let scale = 1.0 / energy_r;
        let x: Vec<f64> = stiffness
            .extend(&r_free)
            .iter()
            .map(|v| v * scale)
            .collect();
        field.push(x, s.iter().map(|v| v * energy_r).collect());
        stiff_modes.push(kr.iter().map(|v| v * scale).collect());
        reports.push(report);
        let go_on = progress(&field, &report);
        if !go_on || report.relative_amplitude < settings.tolerance {
            break;
        }
    }
    Ok((field, reports))
}

/// A deterministic, non-degenerate start for the fixed point, different for every mode.
fn starting_guess(len: usize, mode: usize) -> Vec<f64> {
    let mut rng = fastrand::Rng::with_seed(mode as u64);
    (0..len).map(|_| rng.f64() + 0.5).collect()
}

/// `‖R Sᵀ − R₀ S₀ᵀ‖ / ‖R Sᵀ‖` in the Frobenius norm, from inner products only.
fn product_change(r: &[f64], s: &[f64], r0: &[f64], s0: &[f64]) -> f64 {
    let now = dot(r, r) * dot(s, s);
    let before = dot(r0, r0) * dot(s0, s0);
    let cross = dot(r, r0) * dot(s, s0);
    let diff = (now + before - 2.0 * cross).max(0.0);
    if now > 0.0 {
        (diff / now).sqrt()
    } else {
        f64::INFINITY
    }
}
