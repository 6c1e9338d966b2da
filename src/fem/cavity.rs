//! A closed cavity filled with fluid, such as the gallbladder's bile.
//!
//! The fluid is one pressure over the whole cavity, set by how much its volume has changed:
//! its energy is `κ/(2V₀) (V − V₀)²` with `κ` its bulk modulus, so its pressure is
//! `p = κ (V₀ − V)/V₀` and it pushes on the wall with `p ∂V/∂u`. A thin wall pressed into a
//! cavity of fluid cannot dimple without pushing the same volume out elsewhere, so the fluid
//! carries the wall the way bile carries the gallbladder's.
//!
//! `V` is a sum over the wall's triangles (divergence theorem), so its gradient is local to the
//! wall but its square couples every wall node to every other: the tangent is the wall's
//! sparse part `−p ∂²V/∂u²` plus the dense rank-one part `κ/V₀ g gᵀ`, `g = ∂V/∂u`, which
//! the solvers take apart ([`RankOne`]). Under the linear law the cavity is linearized too:
//! `V ≈ V₀ + g₀ · u`, its energy the rank-one part alone.

use nalgebra::{Point3, Vector3};

use super::pattern::FreePattern;
use super::{DofMap, FemError};
use crate::mesh::TetMesh;

/// The bulk modulus of bile, which is mostly water (Pa).
pub const BILE_BULK_MODULUS_PA: f64 = 2.2e9;

#[derive(Clone, Debug, PartialEq)]
pub struct Cavity {
    /// The wall's triangles, ordered counter-clockwise seen from the cavity (the solid's
    /// outward normal points into the fluid).
    faces: Vec<[usize; 3]>,
    rest_volume_m3: f64,
    bulk_modulus_pa: f64,
}

/// A symmetric rank-one matrix `c v vᵀ` over free dofs: the part of a tangent no sparse
/// pattern holds.
#[derive(Clone, Debug, PartialEq)]
pub struct RankOne {
    pub coefficient: f64,
    pub vector: Vec<f64>,
}

impl RankOne {
    /// `y += c v (v · x)`.
    pub fn add_product(&self, x: &[f64], y: &mut [f64]) {
        let scale = self.coefficient * crate::dense_sums::dot(&self.vector, x);
        for (yi, vi) in y.iter_mut().zip(&self.vector) {
            *yi += scale * vi;
        }
    }
}

impl Cavity {
    /// The cavity bounded by `faces` of `mesh` (the solid's boundary triangles, as
    /// `Surface::extract` orders them), holding fluid of bulk modulus `bulk_modulus_pa`.
    /// Refuses a wall that does not close (every edge in exactly two triangles, once each
    /// way) and one that encloses no volume on its inner side.
    pub fn new(
        mesh: &TetMesh,
        faces: Vec<[usize; 3]>,
        bulk_modulus_pa: f64,
    ) -> Result<Self, FemError> {
        if !(bulk_modulus_pa.is_finite() && bulk_modulus_pa > 0.0) {
            return Err(FemError::InvalidInput {
                what: "cavity: bulk_modulus_pa",
                value: bulk_modulus_pa,
                problem: "not a positive, finite number",
            });
        }
        let nodes = mesh.node_count();
        if let Some(&node) = faces.iter().flatten().find(|&&n| n >= nodes) {
            return Err(FemError::NodeOutOfRange { node, nodes });
        }
        check_closed(&faces)?;
        let rest_volume_m3 = volume(mesh.nodes(), &faces, &vec![0.0; 3 * nodes]);
        if rest_volume_m3 <= 0.0 {
            return Err(FemError::InvalidInput {
                what: "cavity: enclosed volume (m³)",
                value: rest_volume_m3,
                problem: "not positive; the wall's triangles must face into the cavity",
            });
        }
        Ok(Self {
            faces,
            rest_volume_m3,
            bulk_modulus_pa,
        })
    }

    pub fn rest_volume_m3(&self) -> f64 {
        self.rest_volume_m3
    }

    pub fn bulk_modulus_pa(&self) -> f64 {
        self.bulk_modulus_pa
    }

    /// The enclosed volume (m³) at the full displacement `u_m`.
    pub fn volume_m3(&self, mesh: &TetMesh, u_m: &[f64]) -> f64 {
        volume(mesh.nodes(), &self.faces, u_m)
    }

    /// The fluid's pressure (Pa) at the full displacement `u_m`: positive when squeezed.
    pub fn pressure_pa(&self, mesh: &TetMesh, u_m: &[f64]) -> f64 {
        self.pressure_at(self.volume_m3(mesh, u_m))
    }

    fn pressure_at(&self, volume_m3: f64) -> f64 {
        self.bulk_modulus_pa * (self.rest_volume_m3 - volume_m3) / self.rest_volume_m3
    }

    /// `κ/V₀`: the stiffness of the enclosed volume (Pa/m³).
    fn volume_stiffness(&self) -> f64 {
        self.bulk_modulus_pa / self.rest_volume_m3
    }

    /// `∂V/∂u` over every dof at `u_m`.
    pub fn volume_gradient(&self, mesh: &TetMesh, u_m: &[f64]) -> Vec<f64> {
        let mut gradient = vec![0.0; u_m.len()];
        for face in &self.faces {
            let x = positions(mesh.nodes(), face, u_m);
            for (k, &node) in face.iter().enumerate() {
                let g = -x[(k + 1) % 3].cross(&x[(k + 2) % 3]) / 6.0;
                for c in 0..3 {
                    gradient[3 * node + c] += g[c];
                }
            }
        }
        gradient
    }

    /// Adds the fluid's resistance to the internal force at `u_m` (every dof): `−p ∂V/∂u`,
    /// or its linearization at rest, `κ/V₀ g₀ (g₀ · u)`, when `linear`.
    pub fn add_force(&self, mesh: &TetMesh, u_m: &[f64], linear: bool, force: &mut [f64]) {
        let (gradient, pressure) = match linear {
            true => {
                let rest = self.volume_gradient(mesh, &vec![0.0; u_m.len()]);
                let change = crate::dense_sums::dot(&rest, u_m);
                (rest, -self.volume_stiffness() * change)
            }
            false => (self.volume_gradient(mesh, u_m), self.pressure_pa(mesh, u_m)),
        };
        for (f, g) in force.iter_mut().zip(&gradient) {
            *f -= pressure * g;
        }
    }

    /// Adds the fluid's force to `force` (every dof) and its tangent's sparse part
    /// `−p ∂²V/∂u²` to `values` (of `pattern`), and returns its rank-one part over free dofs.
    /// When `linear`, the force is the linearized one and the tangent its rank-one part alone.
    pub fn add_force_and_tangent(
        &self,
        mesh: &TetMesh,
        (pattern, dofs): (&FreePattern, &DofMap),
        u_m: &[f64],
        linear: bool,
        (force, values): (&mut [f64], &mut [f64]),
    ) -> RankOne {
        self.add_force(mesh, u_m, linear, force);
        let at = match linear {
            true => vec![0.0; u_m.len()],
            false => u_m.to_vec(),
        };
        if !linear {
            let pressure = self.pressure_pa(mesh, u_m);
            self.add_pressure_hessian(mesh, (pattern, dofs), &at, -pressure, values);
        }
        RankOne {
            coefficient: self.volume_stiffness(),
            vector: dofs.restrict(&self.volume_gradient(mesh, &at)),
        }
    }

    /// Adds `scale · ∂²V/∂u²` at `u_m`: per triangle, `∂²V/∂x_a∂x_b = [x_c]×/6` for each
    /// cyclic `(a, b, c)`, and its transpose for `(b, a)`.
    fn add_pressure_hessian(
        &self,
        mesh: &TetMesh,
        (pattern, dofs): (&FreePattern, &DofMap),
        u_m: &[f64],
        scale: f64,
        values: &mut [f64],
    ) {
        for face in &self.faces {
            let x = positions(mesh.nodes(), face, u_m);
            for k in 0..3 {
                let (a, b) = (face[k], face[(k + 1) % 3]);
                let block = x[(k + 2) % 3].cross_matrix() * (scale / 6.0);
                pattern.add_node_block(dofs, (a, b), &block, values);
                pattern.add_node_block(dofs, (b, a), &block.transpose(), values);
            }
        }
    }
}

/// The volume the triangles enclose on the side their normals point to, at `u_m`.
fn volume(nodes: &[Point3<f64>], faces: &[[usize; 3]], u_m: &[f64]) -> f64 {
    let sum: f64 = faces
        .iter()
        .map(|face| {
            let x = positions(nodes, face, u_m);
            x[0].dot(&x[1].cross(&x[2]))
        })
        .sum();
    -sum / 6.0
}

fn positions(nodes: &[Point3<f64>], face: &[usize; 3], u_m: &[f64]) -> [Vector3<f64>; 3] {
    face.map(|n| nodes[n].coords + Vector3::new(u_m[3 * n], u_m[3 * n + 1], u_m[3 * n + 2]))
}

/// Every directed edge of the wall appears once and its reverse once: a closed, consistently
/// oriented surface, whose enclosed volume the divergence theorem gives.
fn check_closed(faces: &[[usize; 3]]) -> Result<(), FemError> {
    let mut edges: Vec<(usize, usize)> = faces
        .iter()
        .flat_map(|f| (0..3).map(move |k| (f[k], f[(k + 1) % 3])))
        .collect();
    edges.sort_unstable();
    let repeated = edges.windows(2).any(|w| w[0] == w[1]);
    let unmatched = edges
        .iter()
        .filter(|&&(a, b)| edges.binary_search(&(b, a)).is_err())
        .count();
    if faces.is_empty() || repeated || unmatched > 0 {
        return Err(FemError::InvalidInput {
            what: "cavity: wall edges without their opposite",
            value: unmatched as f64,
            problem: "not zero; the wall must close around the cavity, each triangle facing into it",
        });
    }
    Ok(())
}
