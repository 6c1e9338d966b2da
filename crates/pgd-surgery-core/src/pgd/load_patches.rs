//! The load side of the vademecum: a unit nodal force at every load position, in each of the
//! three directions.
//!
//! Parameter `p = 3m + d` is "a unit force in direction `d` at position `m`". The tool's
//! regularized load at any point `s` is a combination of these, `Σ_m β_m(s) e_m`, with the
//! shares `β` of its contact patch, so by linearity the vademecum answers for the patch centred
//! exactly at `s`, not for an interpolation of patches centred on nodes. The load matrix `F`
//! (dofs × parameters) is never formed: it is applied, and transposed, node by node.

use nalgebra::Vector3;

use crate::fem::{FemError, Loads, PatchKernel};
use crate::mesh::{NOT_ON_SURFACE, Surface};

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
    /// Per position, its quadrature weight in the parameter space: the lumped surface area (m²)
    /// of a tool's position, the lumped volume (m³) of a node a cut may load.
    pub weights: Vec<f64>,
}

impl LoadPatches {
    /// Unit loads at `positions` (surface nodes), weighted by their lumped areas in `kernel`.
    pub fn new(
        surface: &Surface,
        kernel: &PatchKernel,
        positions: Vec<usize>,
    ) -> Result<Self, FemError> {
        let mut weights = Vec::with_capacity(positions.len());
        for &node in &positions {
            let local = surface.surface_index_of[node];
            if local == NOT_ON_SURFACE {
                return Err(FemError::InvalidInput {
                    what: "load position (node index)",
                    value: node as f64,
                    problem: "not a surface node",
                });
            }
            weights.push(kernel.area_m2(local));
        }
        Ok(Self { positions, weights })
    }

    /// Quadrature weight of every parameter: its position's, once per direction.
    pub fn parameter_weights(&self) -> Vec<f64> {
        self.weights.iter().flat_map(|&a| [a; 3]).collect()
    }
}

impl LoadOperator for LoadPatches {
    fn parameter_count(&self) -> usize {
        3 * self.positions.len()
    }

    fn apply(&self, s: &[f64], out: &mut [f64]) {
        for (m, &node) in self.positions.iter().enumerate() {
            for d in 0..3 {
                out[3 * node + d] += s[3 * m + d];
            }
        }
    }

    fn apply_transpose(&self, r: &[f64], out: &mut [f64]) {
        for (m, &node) in self.positions.iter().enumerate() {
            out[3 * m..3 * m + 3].copy_from_slice(&r[3 * node..3 * node + 3]);
        }
    }
}

/// The nodal shares of each load parameter's unit force: what a nonlinear step applies to one
/// parameter and what a full Newton solve of it is given.
pub trait UnitLoads: Sync {
    /// The volume nodes the unit force of parameter `p` acts on, with the share each carries.
    fn nodal_shares(&self, p: usize) -> impl Iterator<Item = (usize, f64)>;

    /// The unit vector parameter `p`'s force is along: axis `p % 3` unless said otherwise.
    fn direction(&self, p: usize) -> Vector3<f64> {
        Vector3::ith(p % 3, 1.0)
    }
}

impl UnitLoads for LoadPatches {
    fn nodal_shares(&self, p: usize) -> impl Iterator<Item = (usize, f64)> {
        std::iter::once((self.positions[p / 3], 1.0))
    }
}

/// The nodal forces of a unit load's `nodal_shares` at a magnitude along `direction`, in a
/// model of `node_count` nodes.
pub(super) fn parameter_load(
    node_count: usize,
    nodal_shares: impl Iterator<Item = (usize, f64)>,
    direction: Vector3<f64>,
    magnitude_n: f64,
) -> Result<Loads, FemError> {
    let mut nodal = Loads::new(node_count);
    for (node, share) in nodal_shares {
        let force_n = direction * (share * magnitude_n);
        nodal.add_nodal_force(node, force_n.into())?;
    }
    Ok(nodal)
}
