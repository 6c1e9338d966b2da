//! The condensed system's lower Cholesky factor `L` (`L Lᵀ = S`), grown by bordering as a cut
//! adds unknowns: the old rows stay as they are, so the responses already divided by them
//! (`Ẑ = Z L⁻ᵀ`) stay valid, and `k` new unknowns on `n` cost `O(n² k)` rather than a new
//! factorization's `O(n³)`. faer does the triangular solves, the product and the new block's
//! factorization.

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, ColMut, Mat, Par, Side};

/// `S` was not positive definite with the new unknowns: the factor is left as it was.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotPositiveDefinite;

/// The lower factor, zero above its diagonal.
#[derive(Clone, Debug)]
pub struct GrowingCholesky {
    l: Mat<f64>,
}

impl Default for GrowingCholesky {
    /// Nothing factored yet.
    fn default() -> Self {
        Self {
            l: Mat::zeros(0, 0),
        }
    }
}

impl GrowingCholesky {
    /// The unknowns factored so far.
    pub fn len(&self) -> usize {
        self.l.nrows()
    }

    /// `L`'s entry at `(row, column)`.
    pub fn at(&self, row: usize, column: usize) -> f64 {
        self.l[(row, column)]
    }

    /// Extends `L` by the new columns `[C; D]` of `S` (each holding every row, old then new):
    /// `L X = C`, then `L_D L_Dᵀ = D − Xᵀ X`, and `L` becomes `[L 0; Xᵀ L_D]`.
    pub fn border(&mut self, columns: &[Vec<f64>]) -> Result<(), NotPositiveDefinite> {
        let (old, new) = (self.len(), columns.len());
        let mut x = Mat::from_fn(old, new, |i, j| columns[j][i]);
        solve_lower_triangular_in_place(self.l.as_ref(), x.as_mut(), Par::Seq);
        let mut schur = Mat::from_fn(new, new, |i, j| columns[j][old + i]);
        matmul(
            schur.as_mut(),
            Accum::Add,
            x.transpose(),
            x.as_ref(),
            -1.0,
            Par::Seq,
        );
        let llt = schur.llt(Side::Lower).map_err(|_| NotPositiveDefinite)?;
        let l_d = llt.L();
        if !(0..new).all(|i| l_d[(i, i)].is_finite() && l_d[(i, i)] > 0.0) {
            return Err(NotPositiveDefinite);
        }
        self.l.resize_with(old + new, old + new, |_, _| 0.0);
        self.l
            .as_mut()
            .submatrix_mut(old, 0, new, old)
            .copy_from(x.transpose());
        for j in 0..new {
            for i in j..new {
                self.l[(old + i, old + j)] = l_d[(i, j)];
            }
        }
        Ok(())
    }

    /// `x ← L⁻¹ x`.
    pub fn forward(&self, x: &mut [f64]) {
        let x = ColMut::from_slice_mut(x).as_mat_mut();
        solve_lower_triangular_in_place(self.l.as_ref(), x, Par::Seq);
    }

    /// `x ← L⁻ᵀ x`.
    pub fn backward(&self, x: &mut [f64]) {
        let x = ColMut::from_slice_mut(x).as_mat_mut();
        solve_upper_triangular_in_place(self.l.transpose(), x, Par::Seq);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bordered one column and then three at a time, the factor is the whole matrix's
    /// Cholesky factor, and its solves invert the matrix; a block that breaks positive
    /// definiteness is refused and leaves the factor as it was.
    #[test]
    fn bordering_gives_the_whole_factor_and_refuses_an_indefinite_block() {
        let n = 7;
        let a = Mat::from_fn(n, n, |i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let s = Mat::from_fn(n, n, |i, j| {
            (0..n).map(|k| a[(i, k)] * a[(j, k)]).sum::<f64>() + f64::from(u8::from(i == j))
        });
        let column = |j: usize| (0..=j).map(|i| s[(i, j)]).collect::<Vec<_>>();
        let mut factor = GrowingCholesky::default();
        factor.border(&[column(0)]).unwrap();
        for block in [1..4, 4..7] {
            let end = block.end;
            let columns: Vec<Vec<f64>> = block
                .map(|j| (0..end).map(|i| s[(i, j)]).collect())
                .collect();
            factor.border(&columns).unwrap();
        }
        let whole = s.llt(Side::Lower).unwrap();
        for i in 0..n {
            for j in 0..=i {
                assert!(
                    (factor.at(i, j) - whole.L()[(i, j)]).abs() < 1e-12,
                    "({i}, {j})"
                );
            }
        }
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut x = b.clone();
        factor.forward(&mut x);
        factor.backward(&mut x);
        for i in 0..n {
            let sx: f64 = (0..n).map(|j| s[(i, j)] * x[j]).sum();
            assert!((sx - b[i]).abs() < 1e-10, "row {i}: {sx} for {}", b[i]);
        }
        let indefinite = vec![vec![0.0; n + 1]];
        assert_eq!(factor.border(&indefinite), Err(NotPositiveDefinite));
        assert_eq!(factor.len(), n);
    }
}
