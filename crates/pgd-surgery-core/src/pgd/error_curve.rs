//! Errors of a separated representation in the energy norm over the parameter space,
//! `‖U − X Yᵀ‖² = tr(W Uᵀ K U) − 2 tr(W Fᵀ X Yᵀ) + tr(W Y Xᵀ K X Yᵀ)` (using `K U = F`), so they
//! need the compliance Gram `G = Fᵀ U` and the modes, never the response fields themselves.
//! The optimal rank-n error in the same norm (Eckart–Young) comes from the eigenvalues of
//! `W^½ G W^½`: the best ANY n-term separated sum can reach on these loads.

use faer::{Mat, Side};
use rayon::prelude::*;

use super::load_patches::LoadOperator;
use super::responses::Responses;
use super::separated::SeparatedField;
use super::statistics::Statistics;
use super::stiffness::RestStiffness;
use crate::dense_sums::dot;

/// Relative errors by number of modes, index `n − 1` for `n` modes.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorCurve {
    /// Energy error of the PGD's separated sum.
    pub separated: Vec<f64>,
    /// The best energy error any separated sum of as many terms can reach (Eckart–Young).
    pub optimal: Vec<f64>,
    /// The estimator: each node-centred load's relative L2 error of the whole vademecum
    /// (separated sum + exact near field), their root mean square weighted by area.
    pub field: Vec<f64>,
    /// The 95th percentile over the node-centred loads of each load's own relative L2 error
    /// (absent in files written before it was recorded).
    #[serde(default)]
    pub field_p95: Vec<f64>,
}

/// Tracks the energy error of a separated field as modes are added, for the error estimator.
pub struct EnergyError {
    weights: Vec<f64>,
    total: f64,
    /// Running `Σ_{k,l} M_kl N_kl − 2 Σ_k a_k`.
    captured: f64,
    stiff_modes: Vec<Vec<f64>>,
}

impl EnergyError {
    /// `self_compliance[p] = G_pp`: only the diagonal of the Gram is needed for the total.
    pub fn new(weights: &[f64], self_compliance: &[f64]) -> Self {
        Self {
            weights: weights.to_vec(),
            total: dot(weights, self_compliance),
            captured: 0.0,
            stiff_modes: Vec::new(),
        }
    }

    /// Accounts for the newest mode of `field` and returns the relative error with all modes.
    pub fn add_mode(
        &mut self,
        field: &SeparatedField,
        stiffness: &RestStiffness,
        loads: &dyn LoadOperator,
    ) -> f64 {
        let k = field.modes() - 1;
        let x = &field.spatial[k];
        let y = &field.parametric[k];
        let x_free = stiffness.restrict(x);
        let mut kx = vec![0.0; x_free.len()];
        stiffness.mul(&x_free, &mut kx);
        let mut ftx = vec![0.0; loads.parameter_count()];
        loads.apply_transpose(x, &mut ftx);
        let wy: Vec<f64> = y.iter().zip(&self.weights).map(|(a, w)| a * w).collect();
        let mut delta = -2.0 * dot(&wy, &ftx) + dot(&kx, &x_free) * dot(y, &wy);
        for (l, kxl) in self.stiff_modes.iter().enumerate() {
            delta += 2.0 * dot(kxl, &x_free) * dot(&field.parametric[l], &wy);
        }
        self.stiff_modes.push(kx);
        self.captured += delta;
        self.relative()
    }

    pub fn relative(&self) -> f64 {
        ((self.total + self.captured).max(0.0) / self.total).sqrt()
    }
}

/// Optimal relative errors for 1..=`max_modes` terms, from the Gram `G` (column-major).
pub fn optimal_errors(gram: &[f64], weights: &[f64], max_modes: usize) -> Vec<f64> {
    let mut eigenvalues = weighted_gram(gram, weights)
        .self_adjoint_eigenvalues(Side::Lower)
        .expect("a symmetric matrix has real eigenvalues");
    eigenvalues.sort_by(|a, b| b.total_cmp(a));
    tail_errors(&eigenvalues, max_modes)
}

/// `W^½ G W^½` for the Gram `G` (column-major), symmetrized: its eigenvalues are the energies
/// of the best separated sum's terms.
pub(super) fn weighted_gram(gram: &[f64], weights: &[f64]) -> Mat<f64> {
    let n = weights.len();
    let root: Vec<f64> = weights.iter().map(|w| w.sqrt()).collect();
    Mat::from_fn(n, n, |i, j| {
        0.5 * (gram[j * n + i] + gram[i * n + j]) * root[i] * root[j]
    })
}

/// The relative error left by the first `1..=max_modes` of `eigenvalues` (decreasing): the
/// square root of the share of the total they leave out.
pub(super) fn tail_errors(eigenvalues: &[f64], max_modes: usize) -> Vec<f64> {
    let total: f64 = eigenvalues.iter().map(|l| l.max(0.0)).sum();
    let mut tail = total;
    eigenvalues
        .iter()
        .take(max_modes)
        .map(|l| {
            tail -= l.max(0.0);
            (tail.max(0.0) / total).sqrt()
        })
        .collect()
}

/// The error estimator of a build: the relative L2 error of the whole vademecum (separated sum
/// plus the exact near field) for every node-centred load, each relative to its own response.
/// It is exact, not estimated: the exact responses are at hand, and are turned into the
/// residual of the separated sum one mode at a time.
pub struct FieldError<'a> {
    weights: &'a [f64],
    near: &'a [Vec<u32>],
    free_index: &'a [usize],
    /// Per load, the squared norm of its exact response.
    totals: Vec<f64>,
}

/// The vademecum's error with the modes so far, from each load's own relative error: a stiff
/// region's loads, whose responses are small, count as much as a soft one's. (The error of
/// all loads together is dominated by the softest regions: on the pancreas it was met with 3
/// modes while loads near its clamped ends were 69 % off, p95.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldErrors {
    /// Root mean square over the loads, weighted by area: the stopping criterion.
    pub rms: f64,
    /// The 95th percentile.
    pub p95: f64,
}

impl<'a> FieldError<'a> {
    pub fn new(
        stiffness: &'a RestStiffness,
        responses: &Responses,
        weights: &'a [f64],
        near: &'a [Vec<u32>],
    ) -> Self {
        let mut estimator = Self {
            weights,
            near,
            free_index: &stiffness.model.dofs().free_index,
            totals: Vec::new(),
        };
        estimator.totals = estimator.squared_norms(responses, false);
        estimator
    }

    /// Subtracts mode `X Yᵀ` (X over all dofs) from `residual`, returns the relative errors.
    pub fn subtract_mode(&self, residual: &mut Responses, x: &[f64], y: &[f64]) -> FieldErrors {
        let x_free: Vec<f64> = self
            .free_index
            .iter()
            .zip(x)
            .filter(|(f, _)| **f != crate::fem::PRESCRIBED)
            .map(|(_, v)| *v)
            .collect();
        let rows = residual.rows;
        residual
            .columns
            .par_chunks_mut(rows)
            .zip(y)
            .for_each(|(r, &yp)| {
                r.iter_mut()
                    .zip(&x_free)
                    .for_each(|(ri, xi)| *ri -= yp * xi);
            });
        self.errors(&self.squared_norms(residual, true))
    }

    fn errors(&self, far: &[f64]) -> FieldErrors {
        let (mut squares, mut area) = (0.0, 0.0);
        let mut own = Vec::with_capacity(far.len());
        for ((f, t), w) in far.iter().zip(&self.totals).zip(self.weights) {
            if *t > 0.0 {
                squares += w * f / t;
                area += w;
                own.push((f / t).sqrt());
            }
        }
        FieldErrors {
            rms: if area > 0.0 {
                (squares / area).sqrt()
            } else {
                0.0
            },
            p95: Statistics::of(own.into_iter()).p95,
        }
    }

    /// Per load, `‖r_p‖²`, leaving out its near field when `far_only`.
    fn squared_norms(&self, columns: &Responses, far_only: bool) -> Vec<f64> {
        (0..columns.count())
            .into_par_iter()
            .map(|p| {
                let r = columns.column(p);
                let mut sum = dot(r, r);
                if far_only {
                    let per_position = columns.count() / self.near.len();
                    for &node in &self.near[p / per_position] {
                        for c in 0..3 {
                            let free = self.free_index[3 * node as usize + c];
                            if free != crate::fem::PRESCRIBED {
                                sum -= r[free] * r[free];
                            }
                        }
                    }
                }
                // |r|² minus its near part cancels to rounding when the near field covers
                // the whole organ: never below zero.
                sum.max(0.0)
            })
            .collect()
    }
}
