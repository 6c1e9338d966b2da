//! A field in separated form, `u(x, p) ≈ Σ_k X^k(x) · Y^k(p)`: the computational vademecum.

use crate::dense_sums::dot;

/// Spatial modes over all dofs (prescribed ones zero) and parametric modes over the load
/// parameters, pairwise.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeparatedField {
    pub spatial: Vec<Vec<f64>>,
    pub parametric: Vec<Vec<f64>>,
}

impl SeparatedField {
    pub fn modes(&self) -> usize {
        self.spatial.len()
    }

    /// The modal coefficients `c_k = Y^k · s` of a load given as parameter weights `s`: the
    /// O(modes × nonzeros of s) step a haptic tick performs.
    pub fn coefficients(&self, s: &[f64]) -> Vec<f64> {
        self.parametric.iter().map(|y| dot(y, s)).collect()
    }

    /// The displacement field `Σ_k c_k X^k` for modal coefficients `c`.
    pub fn field(&self, coefficients: &[f64]) -> Vec<f64> {
        let mut u = vec![0.0; self.spatial.first().map_or(0, Vec::len)];
        for (x, &c) in self.spatial.iter().zip(coefficients) {
            for (ui, xi) in u.iter_mut().zip(x) {
                *ui += c * xi;
            }
        }
        u
    }

    /// Appends a mode.
    pub fn push(&mut self, spatial: Vec<f64>, parametric: Vec<f64>) {
        self.spatial.push(spatial);
        self.parametric.push(parametric);
    }
}
