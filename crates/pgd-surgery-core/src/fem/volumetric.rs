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
use super::element::{
    ElementMatrix, ElementTissue, ElementVector, TetGeometry, gather, j_minus_one, shear_growth,
    volume_change,
};
use super::pattern::{FreePattern, add_at};
use crate::mesh::TetMesh;

/// Per-node constants of the averaged volumetric energy.
pub(super) struct NodalVolumes {
    /// Reference nodal volume `V_n = Σ_e V_e / 4` (m³).
    reference_m3: Vec<f64>,
    /// Volume-weighted mean of the first Lamé constant over the elements around each node (Pa).
    lambda_pa: Vec<f64>,
    /// The elements around each node.
    node_tets: Vec<Vec<usize>>,
    /// The nodes around each node, and where their blocks land in the stiffness values.
    rings: Vec<Ring>,
}

/// The nodes of the elements around one node, ascending: the support of its volume gradient.
struct Ring {
    nodes: Vec<usize>,
    /// For each element around the node, the place of each of its corners in `nodes`.
    corner_slots: Vec<[usize; 4]>,
    /// For each pair `(i, j)` of ring nodes, the positions of their 3×3 block, at `9 (i r + j)`.
    positions: Vec<u32>,
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
    /// `lambda_pa[e]` is element `e`'s first Lamé constant; `pattern` is the model's two-ring
    /// pattern.
    pub(super) fn new(
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        lambda_pa: &[f64],
        pattern: &FreePattern,
        dofs: &DofMap,
    ) -> Self {
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
        let rings = node_tets
            .iter()
            .map(|tets| Ring::new(mesh, tets, pattern, dofs))
            .collect();
        Self {
            reference_m3,
            lambda_pa,
            node_tets,
            rings,
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
        let j_minus_one = self.nodal_mean(mesh, geometry, |t| elements[t].j_minus_one);
        let (mut pressure, mut stiffness) =
            (vec![0.0; j_minus_one.len()], vec![0.0; j_minus_one.len()]);
        for (n, &change) in j_minus_one.iter().enumerate() {
            let volume = self.reference_m3[n];
            if volume <= 0.0 {
                continue;
            }
            let (j, log_j) = (1.0 + change, change.ln_1p());
            let lambda = self.lambda_pa[n];
            pressure[n] = nodal_pressure(lambda, change);
            stiffness[n] = lambda * (1.0 - log_j) / (j * j * volume);
        }
        (pressure, stiffness, elements)
    }

    /// The volume-weighted mean over the elements around each node of a per-element quantity
    /// (`Σ_e V_e x_e / 4V_n`; zero at a node in no element).
    fn nodal_mean(
        &self,
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        of_element: impl Fn(usize) -> f64,
    ) -> Vec<f64> {
        let mut sum = vec![0.0; self.reference_m3.len()];
        for (t, (tet, geo)) in mesh.tets().iter().zip(geometry).enumerate() {
            let share = geo.volume_m3 * of_element(t) / 4.0;
            for &node in tet {
                sum[node] += share;
            }
        }
        for (value, &volume) in sum.iter_mut().zip(&self.reference_m3) {
            *value = if volume > 0.0 { *value / volume } else { 0.0 };
        }
        sum
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
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        pattern: &FreePattern,
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
        let mut gradient = Vec::new();
        for (n, (tets, ring)) in self.node_tets.iter().zip(&self.rings).enumerate() {
            // b_n = ∂v_n/∂x over the ring: a quarter of each element's volume gradient.
            gradient.clear();
            gradient.resize(ring.nodes.len(), Vector3::zeros());
            for (&t, slots) in tets.iter().zip(&ring.corner_slots) {
                for (a, &slot) in slots.iter().enumerate() {
                    gradient[slot] += elements[t].d[a] / 4.0;
                }
            }
            let r = ring.nodes.len();
            for (i, gi) in gradient.iter().enumerate() {
                for (j, gj) in gradient.iter().enumerate() {
                    let block: Matrix3<f64> = gi * gj.transpose() * stiffness[n];
                    add_at(&ring.positions[9 * (i * r + j)..][..9], &block, values);
                }
            }
        }
    }

    /// Adds the neo-Hookean family's force minus its rest linearization, `f(u) − K₀ u`, on
    /// every dof: the shear part of element `e` (its law and modulus from `tissue(e)`) and the
    /// volumetric part on nodal volumes, in one pass over the elements once the nodal pressures
    /// are known. Per element the corner forces are `V S g_a` with
    /// `S = μ (F⁻ᵀ − I) Hᵀ + (μ' − μ)(F − F⁻ᵀ) + p̄ J F⁻ᵀ − q̄ I`: the shear stress
    /// `μ' (F − F⁻ᵀ)` less its linearization `μ (H + Hᵀ)` (`μ' = μ` for the neo-Hookean law,
    /// `μ e^{b x}` for the exponential one), and the volumetric `p̄ d_a` less its linearization
    /// `q̄ V g_a`, `q_n = λ_n θ_n` the linear pressure of the nodal volumetric strain
    /// `θ_n = Σ_e V_e tr(H_e) / 4V_n`. The secant fixed point evaluates this once per
    /// response and iteration: it is the vademecum build's inner loop.
    pub(super) fn add_nonlinear_force(
        &self,
        mesh: &TetMesh,
        geometry: &[TetGeometry],
        tissue: impl Fn(usize) -> ElementTissue,
        u_m: &[f64],
        out: &mut [f64],
    ) {
        let strains: Vec<(f64, f64)> = mesh
            .tets()
            .iter()
            .zip(geometry)
            .map(|(tet, geo)| {
                let h = geo.displacement_gradient(&gather(tet, u_m));
                (j_minus_one(&h), h.trace())
            })
            .collect();
        let pressure: Vec<f64> = self
            .nodal_mean(mesh, geometry, |t| strains[t].0)
            .iter()
            .zip(&self.lambda_pa)
            .map(|(&change, &lambda)| nodal_pressure(lambda, change))
            .collect();
        let linear: Vec<f64> = self
            .nodal_mean(mesh, geometry, |t| strains[t].1)
            .iter()
            .zip(&self.lambda_pa)
            .map(|(theta, lambda)| lambda * theta)
            .collect();
        for (t, (tet, geo)) in mesh.tets().iter().zip(geometry).enumerate() {
            let h = geo.displacement_gradient(&gather(tet, u_m));
            let (j_minus_one, inverse_t) = volume_change(&h);
            let (p, q) = (corner_mean(tet, &pressure), corner_mean(tet, &linear));
            let ElementTissue { mu, stiffening, .. } = tissue(t);
            let growth = shear_growth(stiffening, &h, j_minus_one.ln_1p());
            let mut stress = (inverse_t - Matrix3::identity()) * h.transpose() * mu
                + inverse_t * (p * (1.0 + j_minus_one))
                - Matrix3::identity() * q;
            if growth != 0.0 {
                stress += (h + inverse_t * h.transpose()) * (mu * growth);
            }
            for (a, &node) in tet.iter().enumerate() {
                let f = stress * geo.grads[a] * geo.volume_m3;
                for c in 0..3 {
                    out[3 * node + c] += f[c];
                }
            }
        }
    }
}

impl Ring {
    fn new(mesh: &TetMesh, tets: &[usize], pattern: &FreePattern, dofs: &DofMap) -> Self {
        let mut nodes: Vec<usize> = tets.iter().flat_map(|&t| mesh.tets()[t]).collect();
        nodes.sort_unstable();
        nodes.dedup();
        let slot = |node: usize| nodes.binary_search(&node).expect("listed above");
        let corner_slots = tets.iter().map(|&t| mesh.tets()[t].map(slot)).collect();
        let positions = nodes
            .iter()
            .flat_map(|&a| nodes.iter().map(move |&b| (a, b)))
            .flat_map(|pair| pattern.block_positions(dofs, pair))
            .collect();
        Self {
            nodes,
            corner_slots,
            positions,
        }
    }
}

/// The nodal pressure `p = λ ln J̄ / J̄` at the volume change `J̄ − 1`.
fn nodal_pressure(lambda_pa: f64, j_minus_one: f64) -> f64 {
    lambda_pa * j_minus_one.ln_1p() / (1.0 + j_minus_one)
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

/// One element's volume terms at its displacement `u`.
fn element_volume(geo: &TetGeometry, u: &ElementVector) -> ElementVolume {
    let h = geo.displacement_gradient(u);
    let (j_minus_one, inverse_t) = volume_change(&h);
    let cofactor = inverse_t * (1.0 + j_minus_one);
    ElementVolume {
        j_minus_one,
        d: geo.grads.map(|g| cofactor * g * geo.volume_m3),
        c: geo.grads.map(|g| inverse_t * g),
    }
}
