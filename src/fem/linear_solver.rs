//! Sparse direct solves over the free-dof pattern, with the symbolic analysis done once.

use faer::linalg::solvers::Solve;
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::LltError;
use faer::sparse::{
    SparseColMat,
    linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu},
};
use faer::{MatMut, Side};

use super::FemError;
use super::cavity::RankOne;
use super::pattern::FreePattern;
use crate::dense_sums::dot;

/// Symbolic factorizations of one pattern, reused for every numeric factorization.
pub struct DirectSolver {
    llt: SymbolicLlt<usize>,
    lu: Option<SymbolicLu<usize>>,
    /// Cholesky failed on an earlier matrix: the next ones of the same solve, as far from
    /// rest, go to LU at once rather than pay for a failing Cholesky first.
    indefinite: bool,
}

/// A numeric factorization ready to solve: of a sparse matrix, or of a sparse matrix plus a
/// rank-one term (a fluid cavity's, [`RankOne`]) by the Sherman–Morrison formula.
pub struct Factorization {
    sparse: SparseFactor,
    update: Option<Update>,
}

enum SparseFactor {
    /// Cholesky, for symmetric positive definite matrices (every stable elastic state).
    Llt(Llt<usize, f64>),
    /// LU, the fallback for a tangent that is indefinite under strong compression.
    Lu(Box<Lu<usize, f64>>),
}

/// `A + c v vᵀ` solved from `A`'s factor: `x = A⁻¹b − A⁻¹v · c (v · A⁻¹b) / (1 + c v · A⁻¹v)`.
struct Update {
    rank_one: RankOne,
    /// `A⁻¹ v`.
    solved: Vec<f64>,
    /// `1 + c v · A⁻¹v`.
    denominator: f64,
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
            Ok(llt) => Ok(Factorization::sparse(SparseFactor::Llt(llt))),
            Err(LltError::Numeric(_)) => Err(FemError::NotPositiveDefinite),
            Err(e) => Err(FemError::Factorization(format!("{e:?}"))),
        }
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
            .map(|lu| Factorization::sparse(SparseFactor::Lu(Box::new(lu))))
            .map_err(|_| FemError::NotPositiveDefinite)
    }
}

impl Factorization {
    fn sparse(sparse: SparseFactor) -> Self {
        Self {
            sparse,
            update: None,
        }
    }

    /// The factorization of this matrix plus `rank_one`: one more solve now, and a dot
    /// product and a vector update per right-hand side later. Replaces any earlier update.
    pub fn with_rank_one(mut self, rank_one: RankOne) -> Self {
        self.update = None;
        let mut solved = rank_one.vector.clone();
        self.solve_in_place(&mut solved);
        let denominator = 1.0 + rank_one.coefficient * dot(&rank_one.vector, &solved);
        self.update = Some(Update {
            rank_one,
            solved,
            denominator,
        });
        self
    }

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
    pub fn solve_mat_in_place(&self, mut rhs: MatMut<'_, f64>) {
        match &self.sparse {
            SparseFactor::Llt(f) => f.solve_in_place(rhs.rb_mut()),
            SparseFactor::Lu(f) => f.solve_in_place(rhs.rb_mut()),
        }
        let Some(update) = &self.update else {
            return;
        };
        let (c, v) = (update.rank_one.coefficient, &update.rank_one.vector);
        for j in 0..rhs.ncols() {
            let projection: f64 = v.iter().enumerate().map(|(i, vi)| vi * rhs[(i, j)]).sum();
            let scale = c * projection / update.denominator;
            for (i, y) in update.solved.iter().enumerate() {
                rhs[(i, j)] -= scale * y;
            }
        }
    }
}
