//! The load side of the vademecum: a regularized unit point load at every accessible surface
//! node, in each of the three directions.
//!
//! Parameter `p = 3m + d` is "a unit force in direction `d` at accessible node `m`". Its nodal
//! force vector is sparse (the nodes of the patch around `m`), so the load matrix `F` (dofs ×
//! parameters) is never formed: it is applied, and transposed, patch by patch.

use nalgebra::Point3;

use crate::fem::{FemError, Loads};
use crate::mesh::{Surface, TetMesh};

pub struct LoadPatches {
    /// The accessible surface nodes (volume numbering), one per load position.
    pub positions: Vec<usize>,
    /// Per position, the nodes of its patch and their share of a unit load (summing to 1).
    patches: Vec<Vec<(usize, f64)>>,
    /// Per position, its lumped surface area (m²): the quadrature weight of the parameter space.
    pub areas_m2: Vec<f64>,
}

impl LoadPatches {
    /// Regularizes a unit load over `radius_m` around each of `positions` (surface nodes).
    pub fn new(
        mesh: &TetMesh,
        surface: &Surface,
        positions: Vec<usize>,
        radius_m: f64,
    ) -> Result<Self, FemError> {
        let vertex_areas = surface.vertex_areas(mesh);
        let mut patches = Vec::with_capacity(positions.len());
        let mut areas_m2 = Vec::with_capacity(positions.len());
        for &node in &positions {
            let local = surface.surface_index_of[node];
            if local == crate::mesh::NOT_ON_SURFACE {
                return Err(FemError::InvalidInput {
                    what: "load position (node index)",
                    value: node as f64,
                    problem: "not a surface node",
                });
            }
            areas_m2.push(vertex_areas[local]);
            let mut loads = Loads::new(mesh.node_count());
            let point: Point3<f64> = mesh.nodes()[node];
            loads.add_point_load(mesh, surface, point, [1.0, 0.0, 0.0], radius_m)?;
            let patch = loads
                .as_slice()
                .chunks_exact(3)
                .enumerate()
                .filter(|(_, f)| f[0] != 0.0)
                .map(|(n, f)| (n, f[0]))
                .collect();
            patches.push(patch);
        }
        Ok(Self {
            positions,
            patches,
            areas_m2,
        })
    }

    /// Number of parameters: three directions per position.
    pub fn parameter_count(&self) -> usize {
        3 * self.positions.len()
    }

    /// `out += F · s` (full dofs), for parameter weights `s`.
    pub fn apply(&self, s: &[f64], out: &mut [f64]) {
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

    /// `out = Fᵀ · r` for a full dof vector `r`.
    pub fn apply_transpose(&self, r: &[f64], out: &mut [f64]) {
        for (m, patch) in self.patches.iter().enumerate() {
            for d in 0..3 {
                out[3 * m + d] = patch
                    .iter()
                    .map(|&(node, share)| share * r[3 * node + d])
                    .sum();
            }
        }
    }

    /// The nodal force vector of parameter `p` (full dofs).
    pub fn column(&self, p: usize, node_count: usize) -> Vec<f64> {
        let mut s = vec![0.0; self.parameter_count()];
        s[p] = 1.0;
        let mut f = vec![0.0; 3 * node_count];
        self.apply(&s, &mut f);
        f
    }
}
