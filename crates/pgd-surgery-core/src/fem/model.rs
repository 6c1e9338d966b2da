//! A finite-element model: mesh, material and Dirichlet conditions, with the precomputed
//! element geometry and sparsity pattern that every assembly reuses.

use nalgebra::{SMatrix, SymmetricEigen, Vector3};

use super::element::{ElementTissue, ElementVector, TetGeometry, gather, j_minus_one};
use super::inclusion::{Inclusion, modulus_scale};
use super::pattern::FreePattern;
use super::volumetric::NodalVolumes;
use super::{Dirichlet, DofMap, FemError, Law, Material, consistent_mass, lumped_mass};
use crate::mesh::TetMesh;

/// Rigid-mode ranks are read off a normalized 6×6 Gram matrix; eigenvalues below this
/// fraction of the largest count as zero.
const RANK_TOLERANCE: f64 = 1e-9;

pub struct FemModel {
    mesh: TetMesh,
    geometry: Vec<TetGeometry>,
    material: Material,
    /// Stiffer or softer regions of the tissue, and the factor on Young's modulus they give
    /// each element (1 for all when there are none).
    inclusions: Vec<Inclusion>,
    modulus_scale: Vec<f64>,
    /// The neo-Hookean volumetric energy on nodal volumes (see `volumetric.rs`); `None` for
    /// the other laws, whose elements carry all their energy.
    volumetric: Option<NodalVolumes>,
    dirichlet: Dirichlet,
    dofs: DofMap,
    pattern: FreePattern,
}

impl FemModel {
    /// Builds a model, refusing an invalid material and constraints that leave any connected
    /// part of the mesh free to move rigidly (the stiffness would be singular).
    pub fn new(mesh: TetMesh, material: Material, dirichlet: Dirichlet) -> Result<Self, FemError> {
        if dirichlet.dof_count() != 3 * mesh.node_count() {
            return Err(FemError::InvalidInput {
                what: "Dirichlet conditions: dof count",
                value: dirichlet.dof_count() as f64,
                problem: "not three times the mesh's node count",
            });
        }
        check_rigid_modes(&mesh, &dirichlet)?;
        Self::unchecked(mesh, material, dirichlet)
    }

    /// A body with no boundary condition, free to move as a whole: for dynamics, where the
    /// mass keeps the problem well posed. Its rest stiffness is singular (the six rigid
    /// modes), so static solves and vademecums refuse it.
    pub fn free_body(mesh: TetMesh, material: Material) -> Result<Self, FemError> {
        let dirichlet = Dirichlet::new(mesh.node_count());
        Self::unchecked(mesh, material, dirichlet)
    }

    fn unchecked(
        mesh: TetMesh,
        material: Material,
        dirichlet: Dirichlet,
    ) -> Result<Self, FemError> {
        material.validate()?;
        let geometry = TetGeometry::of_mesh(&mesh);
        let dofs = DofMap::new(&dirichlet);
        let modulus_scale = vec![1.0; mesh.tet_count()];
        let pattern = match material.law.has_nodal_volumes() {
            true => FreePattern::two_ring(&mesh, &dofs),
            false => FreePattern::new(&mesh, &dofs),
        };
        let volumetric =
            nodal_volumes(&mesh, &geometry, &material, &modulus_scale, &pattern, &dofs);
        Ok(Self {
            modulus_scale,
            volumetric,
            inclusions: Vec::new(),
            mesh,
            geometry,
            material,
            dirichlet,
            dofs,
            pattern,
        })
    }

    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// The model with `inclusions` in its tissue (replacing any it had).
    pub fn with_inclusions(mut self, inclusions: &[Inclusion]) -> Result<Self, FemError> {
        self.modulus_scale = modulus_scale(&self.mesh, inclusions)?;
        self.volumetric = nodal_volumes(
            &self.mesh,
            &self.geometry,
            &self.material,
            &self.modulus_scale,
            &self.pattern,
            &self.dofs,
        );
        self.inclusions = inclusions.to_vec();
        Ok(self)
    }

    pub fn material(&self) -> &Material {
        &self.material
    }

    pub fn inclusions(&self) -> &[Inclusion] {
        &self.inclusions
    }

    /// The element's Lamé constants (λ, μ) in pascals: the material's, scaled by any inclusion
    /// the element lies in (both scale with Young's modulus at a fixed Poisson's ratio).
    pub fn lame(&self, element: usize) -> (f64, f64) {
        let (lambda, mu) = self.material.lame();
        let scale = self.modulus_scale[element];
        (scale * lambda, scale * mu)
    }

    /// The law and constants the element itself carries: all the Lamé constants, except the
    /// first when the volumetric energy lives on nodal volumes.
    fn element_tissue(&self, element: usize) -> ElementTissue {
        let (lambda, mu) = self.lame(element);
        ElementTissue {
            law: self.material.law,
            lambda: if self.volumetric.is_some() {
                0.0
            } else {
                lambda
            },
            mu,
            stiffening: self.material.stiffening,
        }
    }

    pub fn dirichlet(&self) -> &Dirichlet {
        &self.dirichlet
    }

    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    pub fn pattern(&self) -> &FreePattern {
        &self.pattern
    }

    pub fn geometry(&self) -> &[TetGeometry] {
        &self.geometry
    }

    /// Internal force (N) on every dof for the full displacement `u_m`.
    pub fn internal_force(&self, u_m: &[f64]) -> Vec<f64> {
        let mut force = vec![0.0; u_m.len()];
        for (t, (tet, geo)) in self.mesh.tets().iter().zip(&self.geometry).enumerate() {
            let fe = geo.force(&self.element_tissue(t), &gather(tet, u_m));
            scatter_vector(tet, &fe, &mut force);
        }
        if let Some(volumetric) = &self.volumetric {
            volumetric.add_force(&self.mesh, &self.geometry, u_m, &mut force);
        }
        force
    }

    /// Whether the full displacement `u_m` turns an element inside out (J ≤ 0): not a state
    /// tissue can be in, though the Kirchhoff–Saint Venant law, whose energy stays finite
    /// there, has equilibria in it.
    pub fn turns_an_element_inside_out(&self, u_m: &[f64]) -> bool {
        let mut tets = self.mesh.tets().iter().zip(&self.geometry);
        tets.any(|(tet, geo)| j_minus_one(&geo.displacement_gradient(&gather(tet, u_m))) <= -1.0)
    }

    /// The nonlinear part of the internal force (N) on every dof, `f_int(u) − K₀ u` with `K₀`
    /// the rest stiffness: zero for the linear law. Adds into `out` (length: all dofs).
    pub fn add_nonlinear_force(&self, u_m: &[f64], out: &mut [f64]) {
        if self.material.law == Law::Linear {
            return;
        }
        if let Some(volumetric) = &self.volumetric {
            let tissue = |t| self.element_tissue(t);
            volumetric.add_nonlinear_force(&self.mesh, &self.geometry, tissue, u_m, out);
            return;
        }
        for (t, (tet, geo)) in self.mesh.tets().iter().zip(&self.geometry).enumerate() {
            let fe = geo.nonlinear_force(&self.element_tissue(t), &gather(tet, u_m));
            scatter_vector(tet, &fe, out);
        }
    }

    /// Internal force on every dof, and the tangent stiffness over free dofs as values of
    /// [`Self::pattern`], both at the full displacement `u_m`.
    pub fn force_and_tangent(&self, u_m: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut force = vec![0.0; u_m.len()];
        let mut values = self.pattern.zero_values();
        for (t, (tet, geo)) in self.mesh.tets().iter().zip(&self.geometry).enumerate() {
            let (fe, ke) = geo.force_and_tangent(&self.element_tissue(t), &gather(tet, u_m));
            scatter_vector(tet, &fe, &mut force);
            self.pattern.scatter(t, &ke, &mut values);
        }
        if let Some(volumetric) = &self.volumetric {
            volumetric.add_force_and_tangent(
                &self.mesh,
                &self.geometry,
                &self.pattern,
                u_m,
                &mut force,
                &mut values,
            );
        }
        (force, values)
    }

    /// The stiffness at rest (free dofs): the linear-elastic stiffness for both laws.
    pub fn rest_stiffness(&self) -> Vec<f64> {
        self.force_and_tangent(&vec![0.0; 3 * self.mesh.node_count()])
            .1
    }

    /// Lumped mass per node (kg).
    pub fn lumped_mass(&self) -> Vec<f64> {
        lumped_mass(
            self.mesh.tets(),
            &self.geometry,
            self.mesh.node_count(),
            self.material.density_kg_m3,
        )
    }

    /// Consistent mass over free dofs, as values of [`Self::pattern`].
    pub fn consistent_mass(&self) -> Vec<f64> {
        consistent_mass(&self.pattern, &self.geometry, self.material.density_kg_m3)
    }
}

/// The law's nodal volumes, with each element's first Lamé constant scaled by its inclusion;
/// `None` for a law whose elements carry all their energy.
fn nodal_volumes(
    mesh: &TetMesh,
    geometry: &[TetGeometry],
    material: &Material,
    modulus_scale: &[f64],
    pattern: &FreePattern,
    dofs: &DofMap,
) -> Option<NodalVolumes> {
    material.law.has_nodal_volumes().then(|| {
        let (lambda, _) = material.lame();
        let lambdas: Vec<f64> = modulus_scale.iter().map(|s| s * lambda).collect();
        NodalVolumes::new(mesh, geometry, &lambdas, pattern, dofs)
    })
}

fn scatter_vector(tet: &[usize; 4], fe: &ElementVector, out: &mut [f64]) {
    for (i, value) in fe.iter().enumerate() {
        out[3 * tet[i / 3] + i % 3] += value;
    }
}

/// For every connected part of the mesh, the six rigid modes restricted to its prescribed dofs
/// must have the same rank as on all its dofs (6 for any solid part, 3 for a lone node).
fn check_rigid_modes(mesh: &TetMesh, dirichlet: &Dirichlet) -> Result<(), FemError> {
    for component in connected_parts(mesh) {
        let centroid = component
            .iter()
            .fold(Vector3::zeros(), |acc, &n| acc + mesh.nodes()[n].coords)
            / component.len() as f64;
        let scale = component
            .iter()
            .map(|&n| (mesh.nodes()[n].coords - centroid).norm())
            .fold(f64::MIN_POSITIVE, f64::max);
        let mut all = SMatrix::<f64, 6, 6>::zeros();
        let mut held = SMatrix::<f64, 6, 6>::zeros();
        for &n in &component {
            let r = (mesh.nodes()[n].coords - centroid) / scale;
            for c in 0..3 {
                // Value at dof (n, c) of the translations e_k and the rotations e_k × r.
                let mut mode = SMatrix::<f64, 6, 1>::zeros();
                mode[c] = 1.0;
                for k in 0..3 {
                    mode[3 + k] = Vector3::ith(k, 1.0).cross(&r)[c];
                }
                let outer = mode * mode.transpose();
                all += outer;
                if dirichlet.value(3 * n + c).is_some() {
                    held += outer;
                }
            }
        }
        let (needed, rank) = (rank(all), rank(held));
        if rank < needed {
            return Err(FemError::Unconstrained {
                example_node: component[0],
                component_nodes: component.len(),
                rank,
            });
        }
    }
    Ok(())
}

fn rank(gram: SMatrix<f64, 6, 6>) -> usize {
    let eigen = SymmetricEigen::new(gram).eigenvalues;
    let largest = eigen.iter().cloned().fold(0.0, f64::max);
    eigen
        .iter()
        .filter(|&&e| e > RANK_TOLERANCE * largest.max(1.0))
        .count()
}

/// Node sets of the connected parts (through shared tetrahedra); a node in no tetrahedron is a
/// part of its own.
fn connected_parts(mesh: &TetMesh) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..mesh.node_count()).collect();
    fn root(parent: &mut [usize], mut n: usize) -> usize {
        while parent[n] != n {
            parent[n] = parent[parent[n]];
            n = parent[n];
        }
        n
    }
    for tet in mesh.tets() {
        let first = root(&mut parent, tet[0]);
        for &n in &tet[1..] {
            let r = root(&mut parent, n);
            parent[r] = first;
        }
    }
    let mut parts: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for n in 0..mesh.node_count() {
        let r = root(&mut parent, n);
        parts.entry(r).or_default().push(n);
    }
    parts.into_values().collect()
}
