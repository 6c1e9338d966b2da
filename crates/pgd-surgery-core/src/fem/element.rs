//! The linear tetrahedron: constant shape-function gradients, and the element force and
//! stiffness of every material law.
//!
//! With `g_a = ∇N_a` and `F = I + Σ_a u_a ⊗ g_a`, the Kirchhoff–Saint Venant element gives
//! `f_a = V · P g_a`, with `P = F S`, `S = λ tr(E) I + 2μ E`, `E = ½(FᵀF − I)`, and the
//! consistent tangent block
//! `K_ab = V [ (g_a·S g_b) I + λ (F g_a)(F g_b)ᵀ + μ (g_a·g_b) F Fᵀ + μ (F g_b)(F g_a)ᵀ ]`.
//! At `F = I` this is the linear-elastic block `V [λ g_a g_bᵀ + μ g_b g_aᵀ + μ (g_a·g_b) I]`.
//!
//! The compressible neo-Hookean element has `P = μ (F − F⁻ᵀ) + λ ln J F⁻ᵀ` and the tangent
//! `∂P_iJ/∂F_kL = μ δ_ik δ_JL + (μ − λ ln J) F⁻¹_Jk F⁻¹_Li + λ F⁻¹_Ji F⁻¹_Lk`, whose blocks
//! reduce to the same linear-elastic block at `F = I`. The exponential law replaces `μ` by
//! `μ' = μ e^{b x}` and adds the growth of `μ'`, `2bμ' D_iJ D_kL` with `D = F − F⁻ᵀ` (since
//! `∂x/∂F = 2D`); `x` is second order in the strain, so the rest block is unchanged.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::Law;
use crate::mesh::TetMesh;

pub type ElementMatrix = SMatrix<f64, 12, 12>;
pub type ElementVector = SVector<f64, 12>;

/// The element displacement of tetrahedron `tet` from the full displacement `u`.
pub(super) fn gather(tet: &[usize; 4], u: &[f64]) -> ElementVector {
    ElementVector::from_fn(|i, _| u[3 * tet[i / 3] + i % 3])
}

/// Per-tetrahedron constants of the reference configuration.
#[derive(Clone, Copy, Debug)]
pub struct TetGeometry {
    /// Gradients of the four shape functions, constant over the element (1/m).
    pub grads: [Vector3<f64>; 4],
    pub volume_m3: f64,
}

impl TetGeometry {
    /// Precomputes the gradients of every tetrahedron of a (validated, positively oriented) mesh.
    pub fn of_mesh(mesh: &TetMesh) -> Vec<Self> {
        (0..mesh.tet_count())
            .map(|t| {
                let p = mesh.tet_points(t);
                let edges = Matrix3::from_columns(&[p[1] - p[0], p[2] - p[0], p[3] - p[0]]);
                let volume_m3 = edges.determinant() / 6.0;
                // Rows of edges⁻¹ are the gradients of N_1..N_3; N_0 = 1 − N_1 − N_2 − N_3.
                let inverse = edges
                    .try_inverse()
                    .expect("a validated mesh has no degenerate tetrahedra");
                let g1 = inverse.row(0).transpose();
                let g2 = inverse.row(1).transpose();
                let g3 = inverse.row(2).transpose();
                Self {
                    grads: [-(g1 + g2 + g3), g1, g2, g3],
                    volume_m3,
                }
            })
            .collect()
    }

    /// Displacement gradient `∇u = Σ_a u_a ⊗ g_a`.
    pub fn displacement_gradient(&self, u: &ElementVector) -> Matrix3<f64> {
        let mut h = Matrix3::zeros();
        for a in 0..4 {
            h += u.fixed_rows::<3>(3 * a) * self.grads[a].transpose();
        }
        h
    }

    /// Internal force and tangent stiffness of this element for the element displacement `u`.
    pub fn force_and_tangent(
        &self,
        tissue: &ElementTissue,
        u: &ElementVector,
    ) -> (ElementVector, ElementMatrix) {
        let ElementTissue {
            law, lambda, mu, ..
        } = *tissue;
        match law {
            Law::Linear => {
                let k = self.linear_stiffness(lambda, mu);
                (k * u, k)
            }
            Law::KirchhoffSaintVenant => self.ksv_force_and_tangent(lambda, mu, u),
            Law::NeoHookean | Law::Exponential => self.hyperelastic_force_and_tangent(tissue, u),
        }
    }

    /// Internal force only, for residual evaluations in line searches. Non-finite for a
    /// neo-Hookean element turned inside out (J ≤ 0), where the energy is infinite.
    pub fn force(&self, tissue: &ElementTissue, u: &ElementVector) -> ElementVector {
        match tissue.law {
            Law::Linear => self.linear_stiffness(tissue.lambda, tissue.mu) * u,
            _ => self.nodal_forces(&self.first_piola(tissue, u)),
        }
    }

    /// The internal force minus the linear one, `f(u) − K_e u`: the nonlinear terms that the
    /// load-step scheme of paper 000 moves to the right-hand side. Zero for the linear law.
    pub fn nonlinear_force(&self, tissue: &ElementTissue, u: &ElementVector) -> ElementVector {
        if tissue.law == Law::Linear {
            return ElementVector::zeros();
        }
        let h = self.displacement_gradient(u);
        let strain = (h + h.transpose()) * 0.5;
        let linear =
            Matrix3::identity() * (tissue.lambda * strain.trace()) + strain * (2.0 * tissue.mu);
        self.nodal_forces(&(self.first_piola(tissue, u) - linear))
    }

    /// First Piola–Kirchhoff stress `P` of a nonlinear law at the element's displacement.
    fn first_piola(&self, tissue: &ElementTissue, u: &ElementVector) -> Matrix3<f64> {
        match tissue.law {
            Law::Linear => unreachable!("the linear law has no separate stress path"),
            Law::KirchhoffSaintVenant => {
                let (f, s) = self.ksv_stress(tissue.lambda, tissue.mu, u);
                f * s
            }
            Law::NeoHookean | Law::Exponential => {
                hyperelastic_stress(tissue, &self.displacement_gradient(u)).p
            }
        }
    }

    /// Linear-elastic element stiffness.
    pub fn linear_stiffness(&self, lambda: f64, mu: f64) -> ElementMatrix {
        let mut k = ElementMatrix::zeros();
        for a in 0..4 {
            for b in 0..4 {
                let block = self.elastic_block(a, b, lambda, mu);
                k.fixed_view_mut::<3, 3>(3 * a, 3 * b)
                    .copy_from(&(block * self.volume_m3));
            }
        }
        k
    }

    /// The linear-elastic stiffness between corners `a` and `b` per unit volume:
    /// `λ g_a g_bᵀ + μ g_b g_aᵀ + μ (g_a·g_b) I`. Enriched elements weigh it by how their
    /// functions' factors vary over the element's pieces.
    pub fn elastic_block(&self, a: usize, b: usize, lambda: f64, mu: f64) -> Matrix3<f64> {
        let (ga, gb) = (self.grads[a], self.grads[b]);
        (ga * gb.transpose()) * lambda
            + (gb * ga.transpose()) * mu
            + Matrix3::identity() * (mu * ga.dot(&gb))
    }

    /// Deformation gradient F and second Piola–Kirchhoff stress S of the KSV law.
    fn ksv_stress(&self, lambda: f64, mu: f64, u: &ElementVector) -> (Matrix3<f64>, Matrix3<f64>) {
        let h = self.displacement_gradient(u);
        // E = ½(H + Hᵀ + HᵀH) rather than ½(FᵀF − I): the latter cancels catastrophically for
        // small strains, which would put a floor of ~1e-8 on the relative residual.
        let e = (h + h.transpose() + h.transpose() * h) * 0.5;
        let f = Matrix3::identity() + h;
        let s = Matrix3::identity() * (lambda * e.trace()) + e * (2.0 * mu);
        (f, s)
    }

    /// The neo-Hookean family's force and its tangent block
    /// `K_ab = V [μ' (g_a·g_b) I + (μ' − λ ln J) c_b c_aᵀ + λ c_a c_bᵀ + 2bμ' (D g_a)(D g_b)ᵀ]`,
    /// `c = F⁻ᵀ g`, `D = F − F⁻ᵀ`, `μ' = μ e^{b x}` (the last term is the growth of `μ'`).
    fn hyperelastic_force_and_tangent(
        &self,
        tissue: &ElementTissue,
        u: &ElementVector,
    ) -> (ElementVector, ElementMatrix) {
        let stress = hyperelastic_stress(tissue, &self.displacement_gradient(u));
        let force = self.nodal_forces(&stress.p);
        let (lambda, shear) = (tissue.lambda, stress.shear_pa);
        let c: [Vector3<f64>; 4] = self.grads.map(|g| stress.inverse_t * g);
        let growth = 2.0 * tissue.stiffening * shear;
        let dg: [Vector3<f64>; 4] = self.grads.map(|g| stress.f_minus_inverse_t * g);
        let mut k = ElementMatrix::zeros();
        for a in 0..4 {
            for b in 0..4 {
                let mut block = Matrix3::identity() * (shear * self.grads[a].dot(&self.grads[b]))
                    + (c[b] * c[a].transpose()) * (shear - lambda * stress.log_j)
                    + (c[a] * c[b].transpose()) * lambda;
                if growth != 0.0 {
                    block += (dg[a] * dg[b].transpose()) * growth;
                }
                k.fixed_view_mut::<3, 3>(3 * a, 3 * b)
                    .copy_from(&(block * self.volume_m3));
            }
        }
        (force, k)
    }

    /// `f_a = V · P g_a` for a first Piola–Kirchhoff stress `P`.
    fn nodal_forces(&self, p: &Matrix3<f64>) -> ElementVector {
        let mut force = ElementVector::zeros();
        for a in 0..4 {
            force
                .fixed_rows_mut::<3>(3 * a)
                .copy_from(&(p * self.grads[a] * self.volume_m3));
        }
        force
    }

    fn ksv_force_and_tangent(
        &self,
        lambda: f64,
        mu: f64,
        u: &ElementVector,
    ) -> (ElementVector, ElementMatrix) {
        let (f, s) = self.ksv_stress(lambda, mu, u);
        let force = self.nodal_forces(&(f * s));
        let fft = f * f.transpose();
        let fg: [Vector3<f64>; 4] = self.grads.map(|g| f * g);
        let sg: [Vector3<f64>; 4] = self.grads.map(|g| s * g);
        let mut k = ElementMatrix::zeros();
        for a in 0..4 {
            for b in 0..4 {
                let ga_gb = self.grads[a].dot(&self.grads[b]);
                let block = Matrix3::identity() * self.grads[a].dot(&sg[b])
                    + (fg[a] * fg[b].transpose()) * lambda
                    + fft * (mu * ga_gb)
                    + (fg[b] * fg[a].transpose()) * mu;
                k.fixed_view_mut::<3, 3>(3 * a, 3 * b)
                    .copy_from(&(block * self.volume_m3));
            }
        }
        (force, k)
    }
}

/// What an element's law needs: the law, the element's Lamé constants (Pa; λ is zero where
/// the volumetric energy lives on nodal volumes) and the exponential law's stiffening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementTissue {
    pub law: Law,
    pub lambda: f64,
    pub mu: f64,
    pub stiffening: f64,
}

/// The stress of the neo-Hookean family at one displacement gradient.
struct HyperelasticStress {
    /// First Piola–Kirchhoff stress.
    p: Matrix3<f64>,
    inverse_t: Matrix3<f64>,
    /// `F − F⁻ᵀ`, the direction of the shear stress.
    f_minus_inverse_t: Matrix3<f64>,
    log_j: f64,
    /// The current shear modulus `μ e^{b x}` (μ for the neo-Hookean law).
    shear_pa: f64,
}

/// `P = μ' (F − F⁻ᵀ) + λ ln J F⁻ᵀ` with `μ' = μ e^{b x}`, for the displacement gradient `h`.
/// An element turned inside out (J ≤ 0) has infinite energy: its stress is NaN, which a line
/// search backs off from.
///
/// `F − F⁻ᵀ` and `ln J` are formed from `h` directly (`F⁻¹ − I = −h F⁻¹`, and `J − 1` from the
/// invariants of `h`): differences of numbers near 1 would cancel catastrophically for small
/// strains and put a floor under Newton's relative residual.
fn hyperelastic_stress(tissue: &ElementTissue, h: &Matrix3<f64>) -> HyperelasticStress {
    let (j_minus_one, inverse_t) = volume_change(h);
    let log_j = j_minus_one.ln_1p();
    // F − F⁻ᵀ = h + (h F⁻¹)ᵀ = h + F⁻ᵀ hᵀ.
    let f_minus_inverse_t = h + inverse_t * h.transpose();
    let shear_pa = tissue.mu * (1.0 + shear_growth(tissue.stiffening, h, log_j));
    HyperelasticStress {
        p: f_minus_inverse_t * shear_pa + inverse_t * (tissue.lambda * log_j),
        inverse_t,
        f_minus_inverse_t,
        log_j,
        shear_pa,
    }
}

/// How much the exponential law has grown the shear modulus, `e^{b x} − 1` with
/// `x = I₁ − 3 − 2 ln J` (0 for `b = 0`, the neo-Hookean law). `I₁ − 3 = 2 tr h + |h|²` and
/// `exp_m1` keep it accurate at small strain, where the growth is second order.
pub(super) fn shear_growth(stiffening: f64, h: &Matrix3<f64>, log_j: f64) -> f64 {
    if stiffening == 0.0 {
        return 0.0;
    }
    let x = 2.0 * h.trace() + h.norm_squared() - 2.0 * log_j;
    (stiffening * x).exp_m1()
}

/// `J − 1 = I₁ + I₂ + I₃` from the invariants of the displacement gradient `h`.
pub(super) fn j_minus_one(h: &Matrix3<f64>) -> f64 {
    let trace = h.trace();
    trace + 0.5 * (trace * trace - (h * h).trace()) + h.determinant()
}

/// `J − 1` and `F⁻ᵀ` for the displacement gradient `h`, `F⁻ᵀ` NaN for an element turned inside
/// out (J ≤ 0). `J − 1 = I₁ + I₂ + I₃` from the invariants of `h`, not `det F − 1`, which
/// cancels catastrophically for small strains.
pub(super) fn volume_change(h: &Matrix3<f64>) -> (f64, Matrix3<f64>) {
    let j_minus_one = j_minus_one(h);
    let inverse_t = match (Matrix3::identity() + h).try_inverse() {
        Some(inverse) if j_minus_one > -1.0 => inverse.transpose(),
        _ => Matrix3::from_element(f64::NAN),
    };
    (j_minus_one, inverse_t)
}
