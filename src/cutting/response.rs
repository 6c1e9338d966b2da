//! The uncut organ's response to loads, `K⁻¹ f`: what the cut state condenses the cut onto.
//! The exact answer is a sparse factorization of the rest stiffness; a vademecum whose load
//! positions cover the region where cuts are allowed answers the same question from its modes.

use crate::fem::{DirectSolver, Factorization, FemError, FemModel};

/// Solves the uncut organ for loads given as full nodal vectors (three per node; held dofs
/// ignored, returned as zero).
pub trait UncutResponse {
    fn node_count(&self) -> usize;

    /// Overwrites each of the `columns` full vectors in `loads` (column-major) with the
    /// displacement they cause.
    fn respond(&self, loads: &mut [f64], columns: usize);
}

/// The exact response: the rest stiffness factorized once.
pub struct ExactResponse {
    factor: Factorization,
    free_dofs: Vec<usize>,
    node_count: usize,
}

impl ExactResponse {
    pub fn new(model: &FemModel) -> Result<Self, FemError> {
        let solver = DirectSolver::new(model.pattern())?;
        let stiffness = model.pattern().matrix(model.rest_stiffness());
        Ok(Self {
            factor: solver.cholesky(&stiffness)?,
            free_dofs: model.dofs().free_dofs.clone(),
            node_count: model.mesh().node_count(),
        })
    }
}

impl UncutResponse for ExactResponse {
    fn node_count(&self) -> usize {
        self.node_count
    }

    fn respond(&self, loads: &mut [f64], columns: usize) {
        let (full, free) = (3 * self.node_count, self.free_dofs.len());
        let mut block = vec![0.0; free * columns];
        for c in 0..columns {
            for (i, &d) in self.free_dofs.iter().enumerate() {
                block[c * free + i] = loads[c * full + d];
            }
        }
        self.factor.solve_block_in_place(&mut block, free);
        loads.fill(0.0);
        for c in 0..columns {
            for (i, &d) in self.free_dofs.iter().enumerate() {
                loads[c * full + d] = block[c * free + i];
            }
        }
    }
}
