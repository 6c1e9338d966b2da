//! External loads as consistent nodal forces: point forces, a regularized point load spread
//! over a surface patch, uniform tractions and pressure on faces.

use nalgebra::{Point3, Vector3};

use super::FemError;
use crate::mesh::{Surface, TetMesh, area_vector};

/// Nodal forces in newtons, three per node (x, y, z).
#[derive(Clone, Debug, PartialEq)]
pub struct Loads {
    forces_n: Vec<f64>,
}

impl Loads {
    pub fn new(node_count: usize) -> Self {
        Self {
            forces_n: vec![0.0; 3 * node_count],
        }
    }

    /// Wraps a full nodal force vector, refusing non-finite entries.
    pub fn from_vec(forces_n: Vec<f64>) -> Result<Self, FemError> {
        if let Some((i, &value)) = forces_n.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(FemError::NonFiniteLoad {
                node: i / 3,
                component: i % 3,
                value,
            });
        }
        Ok(Self { forces_n })
    }

    pub fn as_slice(&self) -> &[f64] {
        &self.forces_n
    }

    pub fn node_count(&self) -> usize {
        self.forces_n.len() / 3
    }

    /// Sum of all nodal forces (N).
    pub fn total_force_n(&self) -> Vector3<f64> {
        self.forces_n
            .chunks_exact(3)
            .fold(Vector3::zeros(), |acc, f| {
                acc + Vector3::new(f[0], f[1], f[2])
            })
    }

    /// Adds a force (N) at one node.
    pub fn add_nodal_force(&mut self, node: usize, force_n: [f64; 3]) -> Result<(), FemError> {
        let nodes = self.node_count();
        if node >= nodes {
            return Err(FemError::NodeOutOfRange { node, nodes });
        }
        for (component, value) in force_n.into_iter().enumerate() {
            if !value.is_finite() {
                return Err(FemError::NonFiniteLoad {
                    node,
                    component,
                    value,
                });
            }
        }
        for (c, value) in force_n.into_iter().enumerate() {
            self.forces_n[3 * node + c] += value;
        }
        Ok(())
    }

    /// Adds a uniform traction (Pa, force per reference area) over faces, lumped a third of each
    /// face's force to each of its nodes (exact for linear triangles under a constant traction).
    pub fn add_traction(
        &mut self,
        mesh: &TetMesh,
        faces: &[[usize; 3]],
        traction_pa: [f64; 3],
    ) -> Result<(), FemError> {
        let traction = Vector3::from(traction_pa);
        self.add_face_forces(mesh, faces, |area| traction * area.norm())
    }

    /// Adds a pressure (Pa) on faces: the traction is `−p n` with `n` the face's outward normal,
    /// so a positive pressure pushes into the solid (the gallbladder's bile on its inner wall).
    pub fn add_pressure(
        &mut self,
        mesh: &TetMesh,
        faces: &[[usize; 3]],
        pressure_pa: f64,
    ) -> Result<(), FemError> {
        if !pressure_pa.is_finite() {
            return Err(FemError::InvalidInput {
                what: "pressure_pa",
                value: pressure_pa,
                problem: "not finite",
            });
        }
        self.add_face_forces(mesh, faces, |area| -area * pressure_pa)
    }

    fn add_face_forces(
        &mut self,
        mesh: &TetMesh,
        faces: &[[usize; 3]],
        force_of: impl Fn(Vector3<f64>) -> Vector3<f64>,
    ) -> Result<(), FemError> {
        for face in faces {
            let third = force_of(area_vector(mesh.nodes(), face)) / 3.0;
            for &n in face {
                self.add_nodal_force(n, third.into())?;
            }
        }
        Ok(())
    }

    /// Adds a point force (N) at `point` of the surface whose outward normal there is `facing`,
    /// regularized over the surface patch within `radius_m` (see [`PatchKernel`]).
    pub fn add_point_load(
        &mut self,
        mesh: &TetMesh,
        surface: &Surface,
        point: Point3<f64>,
        facing: Vector3<f64>,
        force_n: [f64; 3],
        radius_m: f64,
    ) -> Result<(), FemError> {
        let kernel = PatchKernel::new(mesh, surface, radius_m)?;
        for (node, share) in kernel.shares(point, &facing)? {
            self.add_nodal_force(node, force_n.map(|f| f * share))?;
        }
        Ok(())
    }
}

/// The regularized Dirac load of a tool tip: a point force spread over the surface nodes within
/// `radius_m` (the contact patch), each getting a share proportional to its lumped area times
/// the smooth kernel `(1 − (d/r)²)²`. The shares sum to one, so the total force is exact, and
/// the load moves smoothly as its point slides along the surface.
///
/// Only nodes on the pressed side take a share ([`on_pressed_side`]): through a wall thinner
/// than the patch (the gallbladder's 2.5 mm, the cornea's 0.5 mm) the tool does not push the
/// far face.
#[derive(Clone, Debug)]
pub struct PatchKernel {
    nodes: Vec<usize>,
    positions: Vec<Point3<f64>>,
    areas_m2: Vec<f64>,
    normals: Vec<Vector3<f64>>,
    radius_m: f64,
}

impl PatchKernel {
    pub fn new(mesh: &TetMesh, surface: &Surface, radius_m: f64) -> Result<Self, FemError> {
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return Err(FemError::InvalidInput {
                what: "point load radius_m",
                value: radius_m,
                problem: "not a positive, finite length",
            });
        }
        Ok(Self {
            nodes: surface.nodes.clone(),
            positions: surface.nodes.iter().map(|&n| mesh.nodes()[n]).collect(),
            areas_m2: surface.vertex_areas(mesh),
            normals: surface.vertex_normals(mesh),
            radius_m,
        })
    }

    /// Lumped area (m²) of the `i`-th surface node.
    pub fn area_m2(&self, surface_index: usize) -> f64 {
        self.areas_m2[surface_index]
    }

    /// The surface nodes (volume numbering) loaded by a unit force at `point`, where the
    /// surface's outward normal is `facing`, with their shares, which sum to one.
    pub fn shares(
        &self,
        point: Point3<f64>,
        facing: &Vector3<f64>,
    ) -> Result<Vec<(usize, f64)>, FemError> {
        let weights: Vec<(usize, f64)> = (0..self.nodes.len())
            .filter(|&i| on_pressed_side(&self.normals[i], facing))
            .filter_map(|i| {
                let distance_m = (self.positions[i] - point).norm();
                let w = patch_weight(self.areas_m2[i], distance_m, self.radius_m);
                (w > 0.0).then_some((self.nodes[i], w))
            })
            .collect();
        let total: f64 = weights.iter().map(|&(_, w)| w).sum();
        if total <= 0.0 {
            return Err(FemError::InvalidInput {
                what: "point load radius_m",
                value: self.radius_m,
                problem: "smaller than the distance from the load point to any surface node; use a radius at least the local edge length",
            });
        }
        Ok(weights.into_iter().map(|(n, w)| (n, w / total)).collect())
    }
}

/// Whether a surface node whose vertex normal is `normal` lies on the side a tool pressing
/// where the surface's outward normal is `facing` can load: the two face the same way.
pub fn on_pressed_side<T: nalgebra::RealField + Copy>(
    normal: &Vector3<T>,
    facing: &Vector3<T>,
) -> bool {
    normal.dot(facing) > T::zero()
}

/// The unnormalized share of a node of lumped area `area_m2` at `distance_m` from the load:
/// `area · (1 − (d/r)²)²` inside the patch, zero outside.
pub fn patch_weight(area_m2: f64, distance_m: f64, radius_m: f64) -> f64 {
    let t = distance_m / radius_m;
    if t < 1.0 {
        area_m2 * (1.0 - t * t).powi(2)
    } else {
        0.0
    }
}
