//! The best separated sum of responses already computed (the method of snapshots): the
//! eigenvectors of their weighted energy Gram give the modes that minimize the energy error
//! over the parameter space for every number of terms (Eckart–Young).
//!
//! A nonlinear step's corrections `D` are known column by column before they are separated,
//! and their right-hand side `K D` is dense: greedy enrichment would stream the whole of `D`
//! twice per fixed-point iteration of every mode, where the Gram `Dᵀ K D` (needed anyway for
//! the optimal error curve) holds all the modes at once.

use faer::{Mat, MatRef, Side};

use super::error_curve::{tail_errors, weighted_gram};
use super::responses::Responses;
use super::separated::SeparatedField;
use super::stiffness::RestStiffness;

/// The eigen-decomposition of `W^½ G W^½`, largest eigenvalue first.
pub struct WeightedGram {
    /// All eigenvalues, decreasing (negative rounding clamped to zero).
    pub eigenvalues: Vec<f64>,
    /// `W^½ v_k` for the leading eigenvectors `v_k`, one column each (parameters × kept).
    scaled_vectors: Mat<f64>,
}

impl WeightedGram {
    /// Decomposes the Gram `gram` (column-major, parameters × parameters) with parameter
    /// weights `weights`, keeping the `max_modes` leading eigenvectors.
    pub fn new(gram: &[f64], weights: &[f64], max_modes: usize) -> Self {
        let n = weights.len();
        let eigen = weighted_gram(gram, weights)
            .self_adjoint_eigen(Side::Lower)
            .expect("a symmetric matrix has an eigen-decomposition");
        // faer sorts them increasing.
        let values = eigen.S().column_vector();
        let eigenvalues: Vec<f64> = (0..n).rev().map(|i| values[i].max(0.0)).collect();
        let vectors = eigen.U();
        let scaled_vectors = Mat::from_fn(n, max_modes.min(n), |i, k| {
            weights[i].sqrt() * vectors[(i, n - 1 - k)]
        });
        Self {
            eigenvalues,
            scaled_vectors,
        }
    }

    /// The relative energy error of the best sum of `1..=max_modes` terms.
    pub fn optimal_errors(&self, max_modes: usize) -> Vec<f64> {
        tail_errors(&self.eigenvalues, max_modes)
    }

    /// The leading modes of `responses` (whose Gram this is): spatial modes of unit energy,
    /// `X_k = U W^½ v_k / √λ_k`, and parametric ones carrying the amplitude, `Y_k = Uᵀ K X_k
    /// = G W^½ v_k / √λ_k`. Modes with no energy are left out.
    pub fn modes(
        &self,
        stiffness: &RestStiffness,
        responses: &Responses,
        gram: &[f64],
    ) -> SeparatedField {
        let n = responses.count();
        let kept = (0..self.scaled_vectors.ncols())
            .take_while(|&k| self.eigenvalues[k] > 0.0)
            .count();
        let vectors = self.scaled_vectors.subcols(0, kept);
        let u = MatRef::from_column_major_slice(&responses.columns, responses.rows, n);
        let g = MatRef::from_column_major_slice(gram, n, n);
        let spatial = u * vectors;
        let parametric = g * vectors;
        let mut field = SeparatedField::default();
        for k in 0..kept {
            let scale = 1.0 / self.eigenvalues[k].sqrt();
            let x: Vec<f64> = spatial.col(k).iter().map(|v| v * scale).collect();
            let y: Vec<f64> = parametric.col(k).iter().map(|v| v * scale).collect();
            field.push(stiffness.extend(&x), y);
        }
        field
    }
}
