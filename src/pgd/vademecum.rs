//! The computational vademecum of one organ, as the trainer evaluates it: for a force at any
//! point of the accessible surface, the displacement under the tool, the felt force for an
//! indentation, and the whole displacement field, each in O(modes + local entries).

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::BuildSettings;
use super::local::LocalPart;
use crate::fem::Material;

/// What the vademecum was built from and how: enough to refuse a stale file and to say how it
/// was made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The organ name or mesh file it was built for.
    pub source: String,
    /// [`super::mesh_hash`] of the mesh and its regions.
    pub mesh_hash: String,
    pub node_count: usize,
    pub tet_count: usize,
    pub material: Material,
    /// The node set held fixed.
    pub clamped_region: String,
    /// The face set the tool may load.
    pub accessible_region: String,
    /// Loads are unit forces along these axes at every position.
    pub load_directions: [[f64; 3]; 3],
    pub settings: BuildSettings,
    /// Per load step: the indentation (m) its loads make under the tool (0 for the linear step).
    pub indentation_levels_m: Vec<f64>,
    pub modes_per_step: Vec<usize>,
    pub build_seconds: f64,
}

/// One load step's response per unit force: a separated global part plus the local part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Step {
    /// Spatial modes, one after another, each over all `3 × node_count` dofs.
    pub spatial: Vec<f32>,
    /// Parametric modes, one after another, each over all `3 × positions` parameters.
    pub parametric: Vec<f32>,
    pub local: LocalPart,
}

/// A point of the accessible surface: a triangle and barycentric weights on its positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub triangle: usize,
    pub barycentric: [f64; 3],
}

#[derive(Clone, Debug, PartialEq)]
pub struct Vademecum {
    pub header: Header,
    /// Volume node of each load position.
    pub positions: Vec<u32>,
    /// The accessible triangles, as position indices.
    pub triangles: Vec<[u32; 3]>,
    /// Per position, the largest self-compliance of the linear step (m/N): turns a force into
    /// the indentation level that selects load steps.
    pub reference_compliance_m_per_n: Vec<f32>,
    /// Load steps in increasing indentation; one for a linear vademecum.
    pub steps: Vec<Step>,
}

impl Vademecum {
    pub fn dof_count(&self) -> usize {
        3 * self.header.node_count
    }

    pub fn parameter_count(&self) -> usize {
        3 * self.positions.len()
    }

    pub fn modes(&self, step: usize) -> usize {
        self.steps[step].parametric.len() / self.parameter_count()
    }

    /// The deepest indentation (m) the load steps cover: beyond it a nonlinear vademecum is
    /// extrapolated, and the trainer must keep the tool shallower.
    pub fn valid_indentation_m(&self) -> f64 {
        self.header
            .indentation_levels_m
            .last()
            .copied()
            .unwrap_or(0.0)
    }

    fn vertices(&self, at: &SurfacePoint) -> [(usize, f64); 3] {
        let t = self.triangles[at.triangle];
        [0, 1, 2].map(|k| (t[k] as usize, at.barycentric[k]))
    }

    /// Weights of the load steps for a force of `force_n` at `at`: piecewise linear in the
    /// indentation level, held at the last step beyond it.
    fn step_weights(&self, at: &SurfacePoint, force_n: &Vector3<f64>) -> Vec<f64> {
        let levels = &self.header.indentation_levels_m;
        let mut weights = vec![0.0; levels.len()];
        if levels.len() == 1 {
            weights[0] = 1.0;
            return weights;
        }
        let compliance: f64 = self
            .vertices(at)
            .iter()
            .map(|&(i, l)| l * self.reference_compliance_m_per_n[i] as f64)
            .sum();
        let level = force_n.norm() * compliance;
        match levels.iter().position(|&l| l >= level) {
            Some(0) => weights[0] = 1.0,
            Some(k) => {
                let t = (level - levels[k - 1]) / (levels[k] - levels[k - 1]);
                weights[k - 1] = 1.0 - t;
                weights[k] = t;
            }
            None => *weights.last_mut().expect("at least one step") = 1.0,
        }
        weights
    }

    /// The 3 × 3 compliance (m/N) of load step `step` at `at`: the displacement under the tool
    /// per unit force, `Σ_ij λ_i λ_j C_ij`.
    pub fn step_compliance(&self, step: usize, at: &SurfacePoint) -> Matrix3<f64> {
        let local = &self.steps[step].local;
        let vertices = self.vertices(at);
        let mut c = Matrix3::zeros();
        for &(i, li) in &vertices {
            for e in local.neighbours_of(i) {
                let j = local.neighbours[e] as usize;
                if let Some(&(_, lj)) = vertices.iter().find(|(v, _)| *v == j) {
                    let block = &local.compliance[9 * e..9 * e + 9];
                    c += Matrix3::from_row_iterator(block.iter().map(|&v| v as f64)) * (li * lj);
                }
            }
        }
        c
    }

    /// The compliance for a force `force_n` (its load steps blended).
    pub fn compliance(&self, at: &SurfacePoint, force_n: &Vector3<f64>) -> Matrix3<f64> {
        self.step_weights(at, force_n)
            .iter()
            .enumerate()
            .filter(|(_, w)| **w > 0.0)
            .map(|(k, w)| self.step_compliance(k, at) * *w)
            .sum()
    }

    /// Displacement (m) of the surface under the tool for a force (N) at `at`.
    pub fn tool_displacement(&self, at: &SurfacePoint, force_n: &Vector3<f64>) -> Vector3<f64> {
        self.compliance(at, force_n) * force_n
    }

    /// The force (N) that pushes the surface at `at` by `indentation_m`: the force the trainee
    /// feels is its opposite. A secant iteration over the load steps; one solve when linear.
    pub fn force_for_indentation(
        &self,
        at: &SurfacePoint,
        indentation_m: &Vector3<f64>,
    ) -> Vector3<f64> {
        let solve = |c: Matrix3<f64>| {
            c.try_inverse()
                .map_or_else(Vector3::zeros, |inverse| inverse * indentation_m)
        };
        let mut force = solve(self.step_compliance(0, at));
        if self.steps.len() > 1 {
            for _ in 0..SECANT_ITERATIONS {
                force = solve(self.compliance(at, &force));
            }
        }
        force
    }

    /// The displacement field (m, all dofs) for a force (N) at `at`.
    pub fn field(&self, at: &SurfacePoint, force_n: &Vector3<f64>) -> Vec<f64> {
        let mut u = vec![0.0; self.dof_count()];
        for (k, w) in self.step_weights(at, force_n).into_iter().enumerate() {
            if w > 0.0 {
                self.add_step_field(k, at, &(force_n * w), &mut u);
            }
        }
        u
    }

    fn add_step_field(&self, k: usize, at: &SurfacePoint, force_n: &Vector3<f64>, u: &mut [f64]) {
        let step = &self.steps[k];
        let (dofs, params) = (self.dof_count(), self.parameter_count());
        let vertices = self.vertices(at);
        for (x, y) in step
            .spatial
            .chunks_exact(dofs)
            .zip(step.parametric.chunks_exact(params))
        {
            let c: f64 = vertices
                .iter()
                .map(|&(i, l)| {
                    l * (0..3)
                        .map(|d| y[3 * i + d] as f64 * force_n[d])
                        .sum::<f64>()
                })
                .sum();
            for (ui, &xi) in u.iter_mut().zip(x) {
                *ui += c * xi as f64;
            }
        }
        for &(i, l) in &vertices {
            for e in step.local.corrections_of(i) {
                let node = step.local.correction_nodes[e] as usize;
                let r = &step.local.correction[9 * e..9 * e + 9];
                for c in 0..3 {
                    let value: f64 = (0..3).map(|d| r[3 * d + c] as f64 * force_n[d]).sum();
                    u[3 * node + c] += l * value;
                }
            }
        }
    }
}

/// Secant iterations of [`Vademecum::force_for_indentation`] over load steps.
const SECANT_ITERATIONS: usize = 8;
