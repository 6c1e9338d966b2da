//! A small symmetric positive definite matrix over an organ's kept modes, factored anew each
//! tick in the same storage: the haptic tick allocates nothing.

use nalgebra::{Cholesky, DMatrix, DVectorViewMut, Dyn};

/// `A` factored as `L Lᵀ`, its storage kept from one factoring to the next.
#[derive(Clone, Debug)]
pub struct SmallSpd {
    factor: Cholesky<f64, Dyn>,
}

impl SmallSpd {
    /// The identity of size `r`.
    pub fn identity(r: usize) -> Self {
        Self {
            factor: Cholesky::pack_dirty(DMatrix::identity(r, r)),
        }
    }

    /// Factors the matrix that `fill` writes over the old storage (every entry it needs,
    /// the lower triangle at least). The caller guarantees it positive definite: a
    /// positive diagonal plus a positive semi-definite part.
    pub fn refactor(&mut self, fill: impl FnOnce(&mut DMatrix<f64>)) {
        let empty = Cholesky::pack_dirty(DMatrix::zeros(0, 0));
        let mut matrix = std::mem::replace(&mut self.factor, empty).unpack_dirty();
        fill(&mut matrix);
        self.factor = Cholesky::new_unchecked(matrix);
    }

    /// `x ← A⁻¹ x`.
    pub fn solve(&self, x: &mut [f64]) {
        let n = x.len();
        let mut view = DVectorViewMut::from_slice(x, n);
        self.factor.solve_mut(&mut view);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_what_it_factored_and_refactors_in_place() {
        let mut spd = SmallSpd::identity(3);
        let a = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0]);
        for scale in [1.0, 10.0] {
            spd.refactor(|m| m.copy_from(&(&a * scale)));
            let b = [1.0, -2.0, 0.5];
            let mut x = b;
            spd.solve(&mut x);
            let back = &a * scale * nalgebra::DVector::from_column_slice(&x);
            for (got, want) in back.iter().zip(b) {
                assert!((got - want).abs() < 1e-12, "{got} against {want}");
            }
        }
    }
}
