//! The best separated sum of responses already computed (the method of snapshots): the
//! eigenvectors of their weighted energy Gram give the modes that minimize the energy error
//! over the parameter space for every number of terms (Eckart–Young).
//!
//! A nonlinear step's corrections `D` are known column by column before they are separated,
//! and their right-hand side `K D` is dense: greedy enrichment would stream the whole of `D`
//! twice per fixed-point iteration of every mode, where the Gram `Dᵀ K D` (needed anyway for
//! the optimal error curve) holds all the modes at once.

use faer::{MatRef, Side};

use super::error_curve::{tail_errors, weighted_gram};
use super::responses::Responses;
use super::separated::SeparatedField;
use super::stiffness::RestStiffness;

/// The leading modes of some responses, and the error of the best sum of each number of them.
pub struct SnapshotModes {
    /// The relative energy error of the best sum of `1..=max_modes` terms.
    pub optimal: Vec<f64>,
    /// Spatial modes of unit energy, `X_k = U W^½ v_k / √λ_k`, and parametric ones carrying
    /// the amplitude, `Y_k = Uᵀ K X_k = G W^½ v_k / √λ_k`, for the eigenpairs `(λ_k, v_k)` of
    /// `W^½ G W^½`, largest first; modes with no energy are left out.
    pub field: SeparatedField,
}

impl SnapshotModes {
    /// The `max_modes` leading modes of `responses`, whose energy Gram is `gram`
    /// (column-major, parameters × parameters), with parameter weights `weights`.
    pub fn new(
        stiffness: &RestStiffness,
        responses: &Responses,
        gram: &[f64],
        weights: &[f64],
        max_modes: usize,
    ) -> Self {
        let n = weights.len();
        let eigen = weighted_gram(gram, weights)
            .self_adjoint_eigen(Side::Lower)
            .expect("a symmetric matrix has an eigen-decomposition");
        // faer sorts them increasing.
        let values = eigen.S().column_vector();
        let eigenvalues: Vec<f64> = (0..n).rev().map(|i| values[i].max(0.0)).collect();
        let kept = eigenvalues
            .iter()
            .take(max_modes)
            .take_while(|&&l| l > 0.0)
            .count();
        let vectors = eigen.U();
        let scaled =
            faer::Mat::from_fn(n, kept, |i, k| weights[i].sqrt() * vectors[(i, n - 1 - k)]);
        let u = MatRef::from_column_major_slice(&responses.columns, responses.rows, n);
        let g = MatRef::from_column_major_slice(gram, n, n);
        let (spatial, parametric) = (u * &scaled, g * &scaled);
        let mut field = SeparatedField::default();
        for (k, l) in eigenvalues.iter().take(kept).enumerate() {
            let scale = 1.0 / l.sqrt();
            let x: Vec<f64> = spatial.col(k).iter().map(|v| v * scale).collect();
            let y: Vec<f64> = parametric.col(k).iter().map(|v| v * scale).collect();
            field.push(stiffness.extend(&x), y);
        }
        Self {
            optimal: tail_errors(&eigenvalues, max_modes),
            field,
        }
    }
}
