//! The uncut organ's response to loads, `K⁻¹ f`: what the cut state condenses the cut onto.
//! The exact answer is a sparse factorization of the rest stiffness; a cut vademecum
//! ([`RegionResponse`]) answers the same question over the region where cuts are allowed from
//! its modes and near field, with products only.

use super::CutError;
use crate::fem::{DirectSolver, Factorization, FemError, FemModel};
use crate::pgd::{RegionResponse, SparseDofs};

/// `K⁻¹ f` for one sparse load: `X · modal + near`, the modal coefficients of the response's
/// separated sum (none for an exact response) and the rest as sparse dofs.
#[derive(Clone, Debug, Default)]
pub struct Response {
    pub modal: Vec<f64>,
    pub near: SparseDofs,
}

/// The nonzero entries of the full load vector `loads_n`, as a sparse load.
pub(super) fn sparse_load(loads_n: &[f64]) -> SparseDofs {
    loads_n
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(d, &v)| (d, v))
        .collect()
}

/// Solves the uncut organ for sparse loads over full dofs (three per node; held dofs ignored,
/// answered as zero).
pub trait UncutResponse {
    fn node_count(&self) -> usize;

    /// The global modes of the response's separated sum: none for an exact response, whose
    /// enriched functions' responses are exact; with modes, the cut state solves a patch
    /// around each new segment instead (`local.rs`).
    fn modes(&self) -> usize;

    /// Whether a load at `node` is in the region the response answers for.
    fn covers(&self, node: usize) -> bool;

    /// How far the cut state's patch solves reach (m), where the response says.
    fn patch_radius_m(&self) -> Option<f64>;

    /// The responses to `loads`; an error names a loaded node the response does not cover.
    fn respond(&self, loads: &[SparseDofs]) -> Result<Vec<Response>, CutError>;

    /// `Xᵀ v` for a sparse `v`: what `vᵀ` times a response's modal part needs.
    fn spatial_products(&self, v: &[(usize, f64)]) -> Vec<f64>;

    /// `u += X · modal` over all dofs.
    fn add_spatial(&self, modal: &[f64], u: &mut [f64]);
}

/// A response lent to several cut states in turn.
impl<R: UncutResponse + ?Sized> UncutResponse for &R {
    fn node_count(&self) -> usize {
        (**self).node_count()
    }

    fn modes(&self) -> usize {
        (**self).modes()
    }

    fn covers(&self, node: usize) -> bool {
        (**self).covers(node)
    }

    fn patch_radius_m(&self) -> Option<f64> {
        (**self).patch_radius_m()
    }

    fn respond(&self, loads: &[SparseDofs]) -> Result<Vec<Response>, CutError> {
        (**self).respond(loads)
    }

    fn spatial_products(&self, v: &[(usize, f64)]) -> Vec<f64> {
        (**self).spatial_products(v)
    }

    fn add_spatial(&self, modal: &[f64], u: &mut [f64]) {
        (**self).add_spatial(modal, u);
    }
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

    fn modes(&self) -> usize {
        0
    }

    fn covers(&self, _: usize) -> bool {
        true
    }

    fn patch_radius_m(&self) -> Option<f64> {
        None
    }

    fn respond(&self, loads: &[SparseDofs]) -> Result<Vec<Response>, CutError> {
        let free = self.free_dofs.len();
        let mut index = vec![usize::MAX; 3 * self.node_count];
        for (i, &d) in self.free_dofs.iter().enumerate() {
            index[d] = i;
        }
        let mut block = vec![0.0; free * loads.len()];
        for (c, load) in loads.iter().enumerate() {
            for &(d, v) in load {
                if index[d] != usize::MAX {
                    block[c * free + index[d]] += v;
                }
            }
        }
        self.factor.solve_block_in_place(&mut block, free);
        Ok(block
            .chunks_exact(free.max(1))
            .take(loads.len())
            .map(|column| Response {
                modal: Vec::new(),
                near: self
                    .free_dofs
                    .iter()
                    .copied()
                    .zip(column.iter().copied())
                    .collect(),
            })
            .collect())
    }

    fn spatial_products(&self, _: &[(usize, f64)]) -> Vec<f64> {
        Vec::new()
    }

    fn add_spatial(&self, _: &[f64], _: &mut [f64]) {}
}

impl UncutResponse for RegionResponse {
    fn node_count(&self) -> usize {
        RegionResponse::node_count(self)
    }

    fn modes(&self) -> usize {
        RegionResponse::modes(self)
    }

    fn covers(&self, node: usize) -> bool {
        RegionResponse::covers(self, node)
    }

    fn patch_radius_m(&self) -> Option<f64> {
        self.patch_radius_m
    }

    fn respond(&self, loads: &[SparseDofs]) -> Result<Vec<Response>, CutError> {
        let mut scratch = Vec::new();
        loads
            .iter()
            .map(|load| {
                Ok(Response {
                    modal: self
                        .modal_coefficients(load)
                        .map_err(|node| CutError::OutsideRegion { node })?,
                    near: self.near_response(load, &mut scratch),
                })
            })
            .collect()
    }

    fn spatial_products(&self, v: &[(usize, f64)]) -> Vec<f64> {
        RegionResponse::spatial_products(self, v)
    }

    fn add_spatial(&self, modal: &[f64], u: &mut [f64]) {
        RegionResponse::add_spatial(self, modal, u);
    }
}
