//! The load side of the vademecum: a regularized unit point load at every accessible surface
//! node, in each of the three directions.
//!
//! Parameter `p = 3m + d` is "a unit force in direction `d` at accessible node `m`". Its nodal
//! force vector is sparse (the nodes of the patch around `m`), so the load matrix `F` (dofs ×
//! parameters) is never formed: it is applied, and transposed, patch by patch.

use crate::fem::{FemError, PatchKernel};
use crate::mesh::{NOT_ON_SURFACE, Surface, TetMesh};

/// A load matrix `F` (full dofs × parameters) that can be applied and transposed: the PGD's
/// right-hand side, whether unit point loads or a step's nonlinear loads.
pub trait LoadOperator {
    fn parameter_count(&self) -> usize;
    /// `out += F · s` (full dofs), for parameter weights `s`.
    fn apply(&self, s: &[f64], out: &mut [f64]);
    /// `out = Fᵀ · r` for a full dof vector `r`.
    fn apply_transpose(&self, r: &[f64], out: &mut [f64]);
}

pub struct LoadPatches {
    /// The accessible surface nodes (volume numbering), one per load position.
    pub positions: Vec<usize>,
    /// Per position, the nodes of its patch and their share of a unit load (summing to 1).
    pub patches: Vec<Vec<(usize, f64)>>,
    /// Per position, its lumped surface area (m²): the quadrature weight of the parameter space.
    pub areas_m2: Vec<f64>,
}

impl LoadPatches {
    /// Regularizes a unit load with `kernel` around each of `positions` (surface nodes).
    pub fn new(
        mesh: &TetMesh,
        surface: &Surface,
        kernel: &PatchKernel,
        positions: Vec<usize>,
    ) -> Result<Self, FemError> {
        let mut patches = Vec::with_capacity(positions.len());
        let mut areas_m2 = Vec::with_capacity(positions.len());
        for &node in &positions {
            let local = surface.surface_index_of[node];
            if local == NOT_ON_SURFACE {
                return Err(FemError::InvalidInput {
                    what: "load position (node index)",
                    value: node as f64,
                    problem: "not a surface node",
                });
            }
            areas_m2.push(kernel.area_m2(local));
            patches.push(kernel.shares(mesh.nodes()[node])?);
        }
        Ok(Self {
            positions,
            patches,
            areas_m2,
        })
    }

    /// Quadrature weight of every parameter: its position's area, once per direction.
    pub fn weights(&self) -> Vec<f64> {
        self.areas_m2.iter().flat_map(|&a| [a; 3]).collect()
    }

    /// The nodal force vector of parameter `p` (full dofs).
    pub fn column(&self, p: usize, node_count: usize) -> Vec<f64> {
        let mut f = vec![0.0; 3 * node_count];
        for &(node, share) in &self.patches[p / 3] {
            f[3 * node + p % 3] = share;
        }
        f
    }
}

impl LoadOperator for LoadPatches {
    fn parameter_count(&self) -> usize {
        3 * self.positions.len()
    }

    fn apply(&self, s: &[f64], out: &mut [f64]) {
        for (m, patch) in self.patches.iter().enumerate() {
            for d in 0..3 {
                let weight = s[3 * m + d];
                if weight != 0.0 {
                    for &(node, share) in patch {
                        out[3 * node + d] += share * weight;
                    }
                }
            }
        }
    }

    fn apply_transpose(&self, r: &[f64], out: &mut [f64]) {
        for (m, patch) in self.patches.iter().enumerate() {
            for d in 0..3 {
                out[3 * m + d] = patch
                    .iter()
                    .map(|&(node, share)| share * r[3 * node + d])
                    .sum();
            }
        }
    }
}
