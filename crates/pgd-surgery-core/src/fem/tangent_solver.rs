//! How Newton solves with each tangent: a factorization of it, or conjugate gradients
//! preconditioned by a factorization the caller already holds.
//!
//! A PGD build holds the rest stiffness's Cholesky factor for its whole run. The loads its
//! fixed point leaves to Newton differ from rest mostly around the tool, so the preconditioned
//! tangent is the identity plus a perturbation of the nodes that stiffened: conjugate
//! gradients then converge in about ten iterations on the liver (20 to 50 beside the coarse
//! pancreas's clamped attachment, and on the neo-Hookean liver), each a pair of triangular
//! solves and a sparse product, where a direct solve factorizes every tangent anew (LU once a
//! tangent has been indefinite, several times the cost of a Cholesky). Newton only needs each
//! direction to a relative residual that shrinks with its own (an inexact Newton method,
//! Eisenstat and Walker's), so the early directions cost fewer iterations still. Where a
//! tangent is indefinite (an iterate far from equilibrium), the iterations stop at the first
//! direction of negative curvature and Newton takes the descent direction they had reached.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::conjugate_gradient::{
    CgError, CgParams, conjugate_gradient, conjugate_gradient_scratch,
};
use faer::matrix_free::{InitialGuessStatus, LinOp, Precond};
use faer::sparse::SparseColMat;
use faer::{MatMut, MatRef, Par};
use serde::{Deserialize, Serialize};

use super::FemError;
use super::linear_solver::{DirectSolver, Factorization};
use super::pattern::FreePattern;

/// Conjugate-gradient iterations allowed for one Newton direction before the solve gives up
/// on them and factorizes.
const MAX_CG_ITERATIONS: usize = 400;

// The costs of Newton's parts in triangular solves with the rest factor, on the liver-sized
// box of `pgd bench fem` (one run, 13.3 ms a pair of solves): a neo-Hookean tangent's
// product (its two-ring pattern, four mat-vecs' worth: 3.3 ms), its assembly (70 ms) and its
// Cholesky factorization (844 ms; LU, past a limit point, costs more still).
const PRODUCT_SOLVES: f64 = 0.25;
const ASSEMBLY_SOLVES: f64 = 5.3;
const FACTORIZATION_SOLVES: f64 = 63.0;

/// Solves Newton's linear systems `K_t du = r`.
pub enum TangentSolver<'a> {
    /// Factorizes each tangent: Cholesky, LU past a limit point.
    Direct(DirectSolver),
    /// Conjugate gradients preconditioned by a fixed factorization, cut short at negative
    /// curvature, factorizing only where the iterations do not converge.
    Preconditioned(Preconditioned<'a>),
}

/// Conjugate gradients on the tangent, preconditioned by a factorization of a nearby matrix.
pub struct Preconditioned<'a> {
    preconditioner: &'a Factorization,
    pattern: &'a FreePattern,
    /// Made on the first tangent conjugate gradients do not solve.
    direct: Option<DirectSolver>,
    statistics: KrylovStatistics,
}

/// What the preconditioned solves cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct KrylovStatistics {
    /// Newton directions found by conjugate gradients.
    pub directions: usize,
    /// Their conjugate-gradient iterations, all together.
    pub iterations: usize,
    /// Of those, directions cut short at negative curvature (an indefinite tangent).
    pub truncated: usize,
    /// Tangents factorized where conjugate gradients did not converge.
    pub factorizations: usize,
}

impl KrylovStatistics {
    /// Both costs together.
    pub fn merge(self, other: Self) -> Self {
        Self {
            directions: self.directions + other.directions,
            iterations: self.iterations + other.iterations,
            truncated: self.truncated + other.truncated,
            factorizations: self.factorizations + other.factorizations,
        }
    }

    /// Their cost in triangular solves with the rest stiffness's factor, the unit a secant
    /// fixed point's iterations are counted in: each conjugate-gradient iteration a solve and
    /// a tangent product, each direction a tangent assembly, each factorization the
    /// iterations given up before it and itself.
    pub fn cost_in_solves(&self) -> f64 {
        let iteration = 1.0 + PRODUCT_SOLVES;
        let abandoned = MAX_CG_ITERATIONS as f64 * iteration + FACTORIZATION_SOLVES;
        iteration * self.iterations as f64
            + ASSEMBLY_SOLVES * self.directions as f64
            + abandoned * self.factorizations as f64
    }

    /// Conjugate-gradient iterations per Newton direction they found.
    pub fn iterations_per_direction(&self) -> f64 {
        self.iterations as f64 / self.directions.max(1) as f64
    }
}

impl<'a> TangentSolver<'a> {
    pub fn direct(pattern: &FreePattern) -> Result<Self, FemError> {
        DirectSolver::new(pattern).map(Self::Direct)
    }

    /// Conjugate gradients preconditioned by `preconditioner`, a factorization of a matrix
    /// of `pattern`'s free dofs (the rest stiffness).
    pub fn preconditioned(pattern: &'a FreePattern, preconditioner: &'a Factorization) -> Self {
        Self::Preconditioned(Preconditioned {
            preconditioner,
            pattern,
            direct: None,
            statistics: KrylovStatistics::default(),
        })
    }

    /// Any factorization to come tries Cholesky first again (see
    /// [`DirectSolver::expect_definite`]).
    pub fn expect_definite(&mut self) {
        match self {
            Self::Direct(solver) => solver.expect_definite(),
            Self::Preconditioned(p) => p.direct.iter_mut().for_each(DirectSolver::expect_definite),
        }
    }

    /// What the preconditioned solves cost so far (all zero for a direct solver).
    pub fn statistics(&self) -> KrylovStatistics {
        match self {
            Self::Direct(_) => KrylovStatistics::default(),
            Self::Preconditioned(p) => p.statistics,
        }
    }

    /// Overwrites `rhs` with `tangent⁻¹ rhs`; an iterative solve stops at a residual of
    /// `forcing` relative to `rhs`.
    pub(super) fn solve(
        &mut self,
        tangent: &SparseColMat<usize, f64>,
        rhs: &mut [f64],
        forcing: f64,
    ) -> Result<(), FemError> {
        match self {
            Self::Direct(solver) => {
                solver.cholesky_or_lu(tangent)?.solve_in_place(rhs);
                Ok(())
            }
            Self::Preconditioned(p) => p.solve(tangent, rhs, forcing),
        }
    }
}

impl Preconditioned<'_> {
    fn solve(
        &mut self,
        tangent: &SparseColMat<usize, f64>,
        rhs: &mut [f64],
        forcing: f64,
    ) -> Result<(), FemError> {
        let (iterations, truncated) = match self.conjugate_gradients(tangent, rhs, forcing) {
            Outcome::Converged(iterations) => (iterations, false),
            Outcome::NegativeCurvature(iterations) => (iterations, true),
            Outcome::Failed => return self.factorized(tangent, rhs),
        };
        self.statistics.directions += 1;
        self.statistics.iterations += iterations;
        self.statistics.truncated += usize::from(truncated);
        Ok(())
    }

    /// Solves with a factorization of `tangent`, where conjugate gradients did not converge.
    fn factorized(
        &mut self,
        tangent: &SparseColMat<usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FemError> {
        let direct = match &mut self.direct {
            Some(direct) => direct,
            none => none.insert(DirectSolver::new(self.pattern)?),
        };
        direct.cholesky_or_lu(tangent)?.solve_in_place(rhs);
        self.statistics.factorizations += 1;
        Ok(())
    }

    /// Conjugate gradients from zero, overwriting `rhs` with the direction they give; on
    /// [`Outcome::Failed`] `rhs` is left as it was.
    ///
    /// Past a limit point, or far from equilibrium, the tangent can be indefinite. The
    /// iterates before the first direction of negative curvature are then still descent
    /// directions of the energy (Steihaug's truncated Newton): the last of them is taken, or,
    /// when the very first direction has negative curvature, the preconditioned residual
    /// `M⁻¹ r` (the fixed point's own step). The line search sizes either; near equilibrium
    /// the tangent is positive definite again and Newton's full steps return.
    fn conjugate_gradients(
        &self,
        tangent: &SparseColMat<usize, f64>,
        rhs: &mut [f64],
        forcing: f64,
    ) -> Outcome {
        let n = rhs.len();
        let precond = FactorPrecond {
            factor: self.preconditioner,
            dim: n,
        };
        let matrix = tangent.as_ref();
        // The zero start is given as a start that may not be zero: faer 0.24's conjugate
        // gradients leave the first residual unset when told the start is zero.
        let params = CgParams {
            initial_guess: InitialGuessStatus::MaybeNonZero,
            rel_tolerance: forcing,
            max_iters: MAX_CG_ITERATIONS,
            ..CgParams::default()
        };
        let mut solution = vec![0.0; n];
        let mut last = vec![0.0; n];
        let mut iterates = 0;
        let mut scratch = MemBuffer::new(conjugate_gradient_scratch(precond, matrix, 1, Par::Seq));
        let result = conjugate_gradient(
            MatMut::from_column_major_slice_mut(&mut solution, n, 1),
            precond,
            matrix,
            MatRef::from_column_major_slice(rhs, n, 1),
            params,
            |x| {
                last.iter_mut()
                    .enumerate()
                    .for_each(|(i, v)| *v = x[(i, 0)]);
                iterates += 1;
            },
            Par::Seq,
            MemStack::new(&mut scratch),
        );
        match result {
            Ok(info) => {
                rhs.copy_from_slice(&solution);
                Outcome::Converged(info.iter_count)
            }
            Err(CgError::NonPositiveDefiniteOperator) if iterates > 0 => {
                rhs.copy_from_slice(&last);
                Outcome::NegativeCurvature(iterates)
            }
            Err(CgError::NonPositiveDefiniteOperator) => {
                self.preconditioner.solve_in_place(rhs);
                Outcome::NegativeCurvature(0)
            }
            Err(CgError::NonPositiveDefinitePreconditioner)
            | Err(CgError::NoConvergence { .. }) => Outcome::Failed,
        }
    }
}

/// How conjugate gradients ended, with the iterations they took.
enum Outcome {
    Converged(usize),
    /// Stopped at a direction of negative curvature; the direction is the iterate before it.
    NegativeCurvature(usize),
    /// No convergence within [`MAX_CG_ITERATIONS`]: the tangent is factorized instead.
    Failed,
}

/// A factorization applied as a preconditioner: `z = M⁻¹ r` by its triangular solves.
#[derive(Clone, Copy)]
struct FactorPrecond<'a> {
    factor: &'a Factorization,
    dim: usize,
}

impl std::fmt::Debug for FactorPrecond<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FactorPrecond({} dofs)", self.dim)
    }
}

impl LinOp<f64> for FactorPrecond<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.dim
    }

    fn ncols(&self) -> usize {
        self.dim
    }

    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _: Par, _: &mut MemStack) {
        out.copy_from(rhs);
        self.factor.solve_mat_in_place(out);
    }

    /// Real matrices: the conjugate is the operator itself.
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, s: &mut MemStack) {
        self.apply(out, rhs, par, s);
    }
}

impl Precond<f64> for FactorPrecond<'_> {
    fn apply_in_place_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn apply_in_place(&self, rhs: MatMut<'_, f64>, _: Par, _: &mut MemStack) {
        self.factor.solve_mat_in_place(rhs);
    }

    fn conj_apply_in_place(&self, rhs: MatMut<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply_in_place(rhs, par, stack);
    }
}
