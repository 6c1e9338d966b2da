//! Sparse direct solves over the free-dof pattern, with the symbolic analysis done once.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::LltError;
use faer::sparse::{
    SparseColMat,
    linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu},
};
use faer::{MatMut, Side};

use super::FemError;
use super::pattern::FreePattern;

/// Symbolic factorizations of one pattern, reused for every numeric factorization.
pub struct DirectSolver {
    llt: SymbolicLlt<usize>,
    lu: Option<SymbolicLu<usize>>,
    /// Cholesky failed on an earlier matrix: the next ones of the same solve, as far from
    /// rest, go to LU at once rather than pay for a failing Cholesky first.
    indefinite: bool,
}

/// A numeric factorization ready to solve.
pub enum Factorization {
    /// Cholesky, for symmetric positive definite matrices (every stable elastic state).
    Llt(Llt<usize, f64>),
    /// LU, the fallback for a tangent that is indefinite under strong compression.
    Lu(Box<Lu<usize, f64>>),
}

impl DirectSolver {
    pub fn new(pattern: &FreePattern) -> Result<Self, FemError> {
        let llt = SymbolicLlt::try_new(pattern.symbolic().as_ref(), Side::Lower)
            .map_err(|e| FemError::Factorization(format!("{e:?}")))?;
        Ok(Self {
            llt,
            lu: None,
            indefinite: false,
        })
    }

    /// Cholesky factorization; fails with [`FemError::NotPositiveDefinite`] on a singular or
    /// unstable matrix.
    pub fn cholesky(&self, matrix: &SparseColMat<usize, f64>) -> Result<Factorization, FemError> {
        match Llt::try_new_with_symbolic(self.llt.clone(), matrix.as_ref(), Side::Lower) {
            Ok(llt) => Ok(Factorization::Llt(llt)),
            Err(LltError::Numeric(_)) => Err(FemError::NotPositiveDefinite),
            Err(e) => Err(FemError::Factorization(format!("{e:?}"))),
        }
    }

    /// Tries Cholesky first again on the next matrix: for a new solve that starts at or near
    /// an equilibrium, where the tangent is positive definite again (an indentation's next
    /// depth or multiplier update), which LU would factorize several times slower.
    pub fn expect_definite(&mut self) {
        self.indefinite = false;
    }

    /// Cholesky when the matrix allows it, LU otherwise (Newton tangents past a limit point),
    /// and LU from then on.
    pub fn cholesky_or_lu(
        &mut self,
        matrix: &SparseColMat<usize, f64>,
    ) -> Result<Factorization, FemError> {
        if self.indefinite {
            return self.lu(matrix);
        }
        match self.cholesky(matrix) {
            Err(FemError::NotPositiveDefinite) => {
                self.indefinite = true;
                self.lu(matrix)
            }
            other => other,
        }
    }

    fn lu(&mut self, matrix: &SparseColMat<usize, f64>) -> Result<Factorization, FemError> {
        if self.lu.is_none() {
            let symbolic = SymbolicLu::try_new(matrix.symbolic())
                .map_err(|e| FemError::Factorization(format!("{e:?}")))?;
            self.lu = Some(symbolic);
        }
        let symbolic = self.lu.clone().expect("set above");
        Lu::try_new_with_symbolic(symbolic, matrix.as_ref())
            .map(|lu| Factorization::Lu(Box::new(lu)))
            .map_err(|_| FemError::NotPositiveDefinite)
    }
}

impl Factorization {
    /// Overwrites `rhs` with the solution.
    pub fn solve_in_place(&self, rhs: &mut [f64]) {
        let n = rhs.len();
        self.solve_mat_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
    }

    /// Overwrites the column-major block `rhs` (`rows` rows) with the solutions: one pass over
    /// the factor for all columns, much faster than column by column.
    pub fn solve_block_in_place(&self, rhs: &mut [f64], rows: usize) {
        let cols = rhs.len() / rows;
        self.solve_mat_in_place(MatMut::from_column_major_slice_mut(rhs, rows, cols));
    }

    /// Overwrites the columns of `rhs` with the solutions.
    pub fn solve_mat_in_place(&self, rhs: MatMut<'_, f64>) {
        match self {
            Self::Llt(f) => f.solve_in_place(rhs),
            Self::Lu(f) => f.solve_in_place(rhs),
        }
    }
}
