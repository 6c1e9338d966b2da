//! The neo-Hookean volumetric energy on nodal volumes (average nodal pressure, Bonet and
//! Burton 1998): the cure this project uses for volumetric locking of linear tetrahedra at
//! ν = 0.48.
//!
//! A linear tetrahedron has one volume ratio `J`, so a nearly incompressible mesh must keep
//! almost every element's volume, about one constraint per element against under one free dof
//! per element: the mesh locks. Here the energy `λ/2 (ln J)²` is evaluated per node instead,
//! on `J̄_n = v_n / V_n`, with `v_n = Σ_e v_e / 4` the current volume of the elements around
//! node `n` shared among their corners (one constraint per node, as many as dofs / 3). The
//! shear part `μ/2 (I₁ − 3) − μ ln J` stays per element.
//!
//! With `p_n = λ_n ln J̄_n / J̄_n` and `d_a = ∂v_e/∂x_a = V_e cof(F) g_a`, the force on corner
//! `a` of element `e` is `p̄_e d_a`, `p̄_e` the mean of its corners' `p_n`. The tangent is
//! `Σ_n (dp_n/dv_n) b_n b_nᵀ` (`b_n = ∂v_n/∂x`, coupling every pair of nodes around `n`, so
//! the stiffness pattern reaches two rings) plus, per element,
//! `p̄_e V_e J (c_a c_bᵀ − c_b c_aᵀ)` with `c = F⁻ᵀ g`. A homogeneous deformation has the same
//! `J` everywhere, so the patch test and the exact homogeneous solutions are unchanged.

use nalgebra::{Matrix3, Vector3};

use super::DofMap;
use super::element::{ElementMatrix, ElementVector, TetGeometry, gather};
use super::pattern::FreePattern;
use crate::mesh::TetMesh;

/// Per-node constants of the averaged volumetric energy.
pub(super) struct NodalVolumes {
    /// Reference nodal volume `V_n = Σ_e V_e / 4` (m³).
    reference_m3: Vec<f64>,
    /// Volume-weighted mean of the first Lamé constant over the elements around each node (Pa).
    lambda_pa: Vec<f64>,
    /// The elements around each node.
    node_tets: Vec<Vec<usize>>,
}

/// One element's volumetric quantities at the current displacement.
struct ElementVolume {
    /// `J − 1`, formed from the invariants of the displacement gradient.
    j_minus_one: f64,
    /// `d_a = V_e cof(F) g_a`, the derivative of the element's volume by its corners.
    d: [Vector3<f64>; 4],
    /// `c_a = F⁻ᵀ g_a`.
    c: [Vector3<f64>; 4],
}

impl NodalVolumes {
    /// `lambda_pa[e]` is element `e`'s first Lamé constant.
    pub(super) fn new(mesh: &TetMesh, geometry: &[TetGeometry], lambda_pa: &[f64]) -> Self {
        let n = mesh.node_count();
        let (mut reference_m3, mut weighted) = (vec![0.0; n], vec![0.0; n]);
        let mut node_tets = vec![Vec::new(); n];
        for (t, (tet, geo)) in mesh.tets().iter().zip(geometry).enumerate() {
            for &node in tet {
                reference_m3[node] += geo.volume_m3 / 4.0;
                weighted[node] += lambda_pa[t] * geo.volume_m3 / 4.0;
                node_tets[node].push(t);
            }
        }
        let lambda_pa = weighted
            .iter()
            .zip(&reference_m3)
            .map(|(w, v)| if *v > 0.0 { w / v } else { 0.0 })
            .collect();
        Self {
            reference_m3,
            lambda_pa,
            node_tets,
        }
    }

    /// Nodal pressures `p_n` and stiffnesses `dp_n/dv_n`, and each element's volume terms.
    fn state(
        &self,
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        u_m: &[f64],
    ) -> (Vec<f64>, Vec<f64>, Vec<ElementVolume>) {
        let elements: Vec<ElementVolume> = mesh
            .tets()
            .iter()
            .zip(geometry)
            .map(|(tet, geo)| element_volume(geo, &gather(tet, u_m)))
            .collect();
        let mut change_m3 = vec![0.0; self.reference_m3.len()];
        for ((tet, geo), element) in mesh.tets().iter().zip(geometry).zip(&elements) {
            for &node in tet {
                change_m3[node] += geo.volume_m3 * element.j_minus_one / 4.0;
            }
        }
        let (mut pressure, mut stiffness) =
            (vec![0.0; change_m3.len()], vec![0.0; change_m3.len()]);
        for n in 0..change_m3.len() {
            let volume = self.reference_m3[n];
            if volume <= 0.0 {
                continue;
            }
            let j_minus_one = change_m3[n] / volume;
            let (j, log_j) = (1.0 + j_minus_one, j_minus_one.ln_1p());
            let lambda = self.lambda_pa[n];
            pressure[n] = lambda * log_j / j;
            stiffness[n] = lambda * (1.0 - log_j) / (j * j * volume);
        }
        (pressure, stiffness, elements)
    }

    /// Adds the volumetric force (N) on every dof.
    pub(super) fn add_force(
        &self,
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        u_m: &[f64],
        force: &mut [f64],
    ) {
        let (pressure, _, elements) = self.state(mesh, geometry, u_m);
        for (tet, element) in mesh.tets().iter().zip(&elements) {
            add_corner_forces(tet, &element.d, corner_mean(tet, &pressure), force);
        }
    }

    /// Adds the volumetric force on every dof and its tangent over free dofs.
    pub(super) fn add_force_and_tangent(
        &self,
        (mesh, geometry): (&TetMesh, &[TetGeometry]),
        (pattern, dofs): (&FreePattern, &DofMap),
        u_m: &[f64],
        force: &mut [f64],
        values: &mut [f64],
    ) {
        let (pressure, stiffness, elements) = self.state(mesh, geometry, u_m);
        for (t, (tet, element)) in mesh.tets().iter().zip(&elements).enumerate() {
            let mean = corner_mean(tet, &pressure);
            add_corner_forces(tet, &element.d, mean, force);
            let mut k = ElementMatrix::zeros();
            for a in 0..4 {
                for b in 0..4 {
                    // V J c_a = d_a, so V J (c_a c_bᵀ − c_b c_aᵀ) = d_a c_bᵀ − d_b c_aᵀ.
                    let block = (element.d[a] * element.c[b].transpose()
                        - element.d[b] * element.c[a].transpose())
                        * mean;
                    k.fixed_view_mut::<3, 3>(3 * a, 3 * b).copy_from(&block);
                }
            }
            pattern.scatter(t, &k, values);
        }
        for (n, tets) in self.node_tets.iter().enumerate() {
            let gradient = self.volume_gradient(mesh, &elements, tets);
            for &(a, da) in &gradient {
                for &(b, db) in &gradient {
                    let block: Matrix3<f64> = da * db.transpose() * stiffness[n];
                    pattern.add_node_block(dofs, (a, b), &block, values);
                }
            }
        }
    }

    /// `b_n = ∂v_n/∂x` as (node, 3-vector) over the nodes around `n`.
    fn volume_gradient(
        &self,
        mesh: &TetMesh,
        elements: &[ElementVolume],
        tets: &[usize],
    ) -> Vec<(usize, Vector3<f64>)> {
        let mut gradient: Vec<(usize, Vector3<f64>)> = Vec::with_capacity(16);
        for &t in tets {
            for (a, &node) in mesh.tets()[t].iter().enumerate() {
                let share = elements[t].d[a] / 4.0;
                match gradient.iter_mut().find(|(m, _)| *m == node) {
                    Some((_, sum)) => *sum += share,
                    None => gradient.push((node, share)),
                }
            }
        }
        gradient
    }

    /// Adds the volumetric force minus its rest linearization, `f_vol(u) − K₀ u`, on every dof:
    /// per element `p̄_e d_a − q̄_e V_e g_a`, with `q_n = λ_n θ_n` the linear nodal pressure of
    /// the nodal volumetric strain `θ_n = Σ_e V_e tr(H_e) / 4V_n`.
    pub(super) fn add_nonlinear_force(
        &self,
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        u_m: &[f64],
        out: &mut [f64],
    ) {
        let (pressure, _, elements) = self.state(mesh, geometry, u_m);
        let mut linear = vec![0.0; pressure.len()];
        for (tet, geo) in mesh.tets().iter().zip(geometry) {
            let trace = geo.displacement_gradient(&gather(tet, u_m)).trace();
            for &node in tet {
                linear[node] += geo.volume_m3 * trace / 4.0;
            }
        }
        for (n, value) in linear.iter_mut().enumerate() {
            let volume = self.reference_m3[n];
            *value = if volume > 0.0 {
                self.lambda_pa[n] * *value / volume
            } else {
                0.0
            };
        }
        for ((tet, geo), element) in mesh.tets().iter().zip(geometry).zip(&elements) {
            let (p, q) = (corner_mean(tet, &pressure), corner_mean(tet, &linear));
            for (a, &node) in tet.iter().enumerate() {
                let f = element.d[a] * p - geo.grads[a] * (q * geo.volume_m3);
                for c in 0..3 {
                    out[3 * node + c] += f[c];
                }
            }
        }
    }
}

/// The mean of a nodal quantity over an element's corners.
fn corner_mean(tet: &[usize; 4], values: &[f64]) -> f64 {
    tet.iter().map(|&n| values[n]).sum::<f64>() / 4.0
}

/// Adds `pressure · d_a` to each corner `a` of an element.
fn add_corner_forces(tet: &[usize; 4], d: &[Vector3<f64>; 4], pressure: f64, force: &mut [f64]) {
    for (a, &node) in tet.iter().enumerate() {
        for c in 0..3 {
            force[3 * node + c] += pressure * d[a][c];
        }
    }
}

/// `J − 1`, `d_a` and `c_a` of one element; NaN when it is turned inside out (J ≤ 0).
fn element_volume(geo: &TetGeometry, u: &ElementVector) -> ElementVolume {
    let h = geo.displacement_gradient(u);
    let trace = h.trace();
    let j_minus_one = trace + 0.5 * (trace * trace - (h * h).trace()) + h.determinant();
    let f = Matrix3::identity() + h;
    let inverse_t = match f.try_inverse() {
        Some(inverse) if j_minus_one > -1.0 => inverse.transpose(),
        _ => Matrix3::from_element(f64::NAN),
    };
    let cofactor = inverse_t * (1.0 + j_minus_one);
    ElementVolume {
        j_minus_one,
        d: geo.grads.map(|g| cofactor * g * geo.volume_m3),
        c: geo.grads.map(|g| inverse_t * g),
    }
}
