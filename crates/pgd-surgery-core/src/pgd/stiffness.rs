//! The rest stiffness of a model, assembled and factorized once for a whole build: every PGD
//! R-step, every exact response and every load step of the nonlinear scheme solves with it.

use crate::fem::{DirectSolver, Factorization, FemError, FemModel, TangentSolver};

pub struct RestStiffness<'a> {
    pub model: &'a FemModel,
    values: Vec<f64>,
    factor: Factorization,
}

impl<'a> RestStiffness<'a> {
    pub fn new(model: &'a FemModel) -> Result<Self, FemError> {
        let values = model.rest_stiffness();
        let solver = DirectSolver::new(model.pattern())?;
        let factor = solver.cholesky(&model.pattern().matrix(values.clone()))?;
        Ok(Self {
            model,
            values,
            factor,
        })
    }

    /// `y = K x` over free dofs.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        self.model.pattern().mul(&self.values, x, y);
    }

    /// Solves `K x = b` in place for a column-major block of free-dof right-hand sides.
    pub fn solve_block(&self, rhs: &mut [f64]) {
        self.factor
            .solve_block_in_place(rhs, self.model.dofs().free_count());
    }

    /// Newton's linear solves by conjugate gradients preconditioned with this factor: the
    /// loads the fixed point leaves differ from rest mostly around the tool.
    pub fn newton_solver(&self) -> TangentSolver<'_> {
        TangentSolver::preconditioned(self.model.pattern(), &self.factor)
    }

    pub fn free_count(&self) -> usize {
        self.model.dofs().free_count()
    }

    pub fn full_count(&self) -> usize {
        3 * self.model.mesh().node_count()
    }

    /// Gathers the free entries of a full dof vector.
    pub fn restrict(&self, full: &[f64]) -> Vec<f64> {
        self.model.dofs().restrict(full)
    }

    /// Scatters a free-dof vector into a full one (prescribed dofs zero).
    pub fn extend(&self, free: &[f64]) -> Vec<f64> {
        let mut full = vec![0.0; self.full_count()];
        for (v, &d) in free.iter().zip(&self.model.dofs().free_dofs) {
            full[d] = *v;
        }
        full
    }
}
