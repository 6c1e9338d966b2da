//! The Kirchhoff–Saint Venant energy of a reduced model as polynomial coefficients (Barbič and
//! James's reduced St. Venant–Kirchhoff): exact, with no training poses, and evaluated at a cost
//! set by the basis size alone.
//!
//! With `u = Φ q`, each element's Green strain is `E(q) = Σᵢ Lᵢ qᵢ + Σⱼₖ Nⱼₖ qⱼ qₖ` (`Lᵢ` the
//! symmetric gradient of mode `i`, `Nⱼₖ = ¼ (Hⱼᵀ Hₖ + Hₖᵀ Hⱼ)` from the modes' displacement
//! gradients), and its energy `½ V E : C : E` with `X : C : Y = λ tr X tr Y + 2μ X : Y`. Summed
//! over elements:
//!
//! `W(q) = ½ Kᵢⱼ qᵢ qⱼ + Aᵢⱼₖ qᵢ qⱼ qₖ + ½ Bᵢⱼₖₗ qᵢ qⱼ qₖ qₗ`,
//!
//! `Kᵢⱼ = Σ V Lᵢ:C:Lⱼ`, `Aᵢⱼₖ = Σ V Lᵢ:C:Nⱼₖ`, `Bᵢⱼₖₗ = Σ V Nᵢⱼ:C:Nₖₗ`, stored over index pairs
//! `j ≤ k` (`P = r(r+1)/2` of them), so `B` takes `P²` numbers: 44,100 for 20 modes.
//!
//! The Simo–Tarnow algorithmic force of a step from `q₀` to `q₁` evaluates the stress at the
//! mean of the two strains, `Ē = E(a) + ¼ N(Δ, Δ)` (`a` the midpoint, `Δ = q₁ − q₀`), with the
//! strain's derivative at the midpoint. Because the energy is quadratic in `E`, its work over
//! the step equals `W(q₁) − W(q₀)` exactly, whatever the step; at `Δ = 0` it is the internal
//! force.

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::{DynamicsError, ModalBasis};
use crate::dense_sums::dot;
use crate::fem::{FemModel, Law};

/// Elements whose coefficient rows are stacked for one matrix product.
const CHUNK_ELEMENTS: usize = 512;

/// Numbers per element row: the six strain components (√2 on shears, so that a dot product
/// is the double contraction) weighted by √(2μV), and the trace weighted by √(λV).
const ROW: usize = 7;

/// A reduced Kirchhoff–Saint Venant (or linear) model.
#[derive(Clone, Debug)]
pub struct ReducedKsv {
    r: usize,
    /// Index pairs `(j, k)`, `j ≤ k`, and the pair of any `(j, k)` (`r × r`).
    pairs: Vec<(usize, usize)>,
    pair_of: Vec<usize>,
    /// `K`, `r × r`, row-major.
    stiffness: Vec<f64>,
    /// `A`, `r × P`, row-major; empty for the linear law.
    cubic: Vec<f64>,
    /// `A` again as `Aₖₘⱼ` laid out `[m][k][j]` (`r³`), so that the force's term
    /// `2 Σₖⱼ Aₖₘⱼ aₖ aⱼ` runs over contiguous memory.
    cubic_by_middle: Vec<f64>,
    /// `B`, `P × P`, row-major; empty for the linear law.
    quartic: Vec<f64>,
}

/// Scratch space of one evaluation: nothing is allocated once it exists.
#[derive(Clone, Debug)]
pub struct Scratch {
    mid: Vec<f64>,
    pairs: Vec<f64>,
    contracted: Vec<f64>,
}

impl ReducedKsv {
    /// The coefficients of `model`'s energy in `basis`: one pass over the elements, as matrix
    /// products of their stacked rows.
    pub fn new(model: &FemModel, basis: &ModalBasis) -> Result<Self, DynamicsError> {
        let law = model.material().law;
        let nonlinear = match law {
            Law::Linear => false,
            Law::KirchhoffSaintVenant => true,
            Law::NeoHookean | Law::Exponential => return Err(DynamicsError::unsupported(law)),
        };
        let r = basis.len();
        let (pairs, pair_of) = index_pairs(r);
        let p_count = if nonlinear { pairs.len() } else { 0 };
        let mut k = DMatrix::zeros(r, r);
        let mut a = DMatrix::zeros(r, p_count);
        let mut b = DMatrix::zeros(p_count, p_count);
        let tets = model.mesh().tets();
        for first in (0..tets.len()).step_by(CHUNK_ELEMENTS) {
            let last = (first + CHUNK_ELEMENTS).min(tets.len());
            let (lin, quad) = element_rows(model, basis, first..last, &pairs[..p_count]);
            k.gemm_tr(1.0, &lin, &lin, 1.0);
            if nonlinear {
                a.gemm_tr(1.0, &lin, &quad, 1.0);
                b.gemm_tr(1.0, &quad, &quad, 1.0);
            }
        }
        let row_major = |m: DMatrix<f64>| m.transpose().as_slice().to_vec();
        let cubic = row_major(a);
        let cubic_by_middle = match nonlinear {
            true => (0..r * r * r)
                .map(|i| {
                    let (m, k, j) = (i / (r * r), (i / r) % r, i % r);
                    cubic[k * p_count + pair_of[m * r + j]]
                })
                .collect(),
            false => Vec::new(),
        };
        Ok(Self {
            r,
            pairs,
            pair_of,
            stiffness: row_major(k),
            cubic,
            cubic_by_middle,
            quartic: row_major(b),
        })
    }

    /// The linear law's reduced model in a Ritz basis: its stiffness is the diagonal of
    /// squared frequencies, with no pass over the elements.
    pub fn linear(basis: &ModalBasis) -> Self {
        let r = basis.len();
        let mut stiffness = vec![0.0; r * r];
        for (k, w2) in basis.omega2.iter().enumerate() {
            stiffness[k * r + k] = *w2;
        }
        let (pairs, pair_of) = index_pairs(r);
        Self {
            r,
            pairs,
            pair_of,
            stiffness,
            cubic: Vec::new(),
            cubic_by_middle: Vec::new(),
            quartic: Vec::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.r
    }

    pub fn is_empty(&self) -> bool {
        self.r == 0
    }

    pub fn is_nonlinear(&self) -> bool {
        !self.cubic.is_empty()
    }

    /// The reduced rest stiffness `K` (row-major).
    pub fn stiffness(&self) -> &[f64] {
        &self.stiffness
    }

    pub fn scratch(&self) -> Scratch {
        Scratch {
            mid: vec![0.0; self.r],
            pairs: vec![0.0; self.pairs.len()],
            contracted: vec![0.0; self.pairs.len()],
        }
    }

    /// The strain energy `W(q)` (J).
    pub fn energy(&self, q: &[f64]) -> f64 {
        let quadratic = 0.5 * dot(q, &self.k_times(q));
        if !self.is_nonlinear() {
            return quadratic;
        }
        let t: Vec<f64> = self
            .pairs
            .iter()
            .map(|&(j, k)| weight(j, k) * q[j] * q[k])
            .collect();
        let p = t.len();
        let cubic: f64 = (0..self.r)
            .map(|i| q[i] * dot(&self.cubic[i * p..(i + 1) * p], &t))
            .sum();
        let quartic: f64 = (0..p)
            .map(|a| t[a] * dot(&self.quartic[a * p..(a + 1) * p], &t))
            .sum();
        quadratic + cubic + 0.5 * quartic
    }

    /// The internal force `∂W/∂q` at `q` into `out`.
    pub fn force(&self, q: &[f64], out: &mut [f64], scratch: &mut Scratch) {
        self.algorithmic_force((q, q), out, scratch);
    }

    /// The Simo–Tarnow force of a step from `q₀` to `q₁` into `out`: its dot product with
    /// `q₁ − q₀` is `W(q₁) − W(q₀)`.
    pub fn algorithmic_force(&self, (q0, q1): (&[f64], &[f64]), out: &mut [f64], s: &mut Scratch) {
        let r = self.r;
        self.midpoint_terms((q0, q1), s);
        let a = &s.mid;
        for (o, row) in out.iter_mut().zip(self.stiffness.chunks_exact(r)) {
            *o = dot(row, a);
        }
        if !self.is_nonlinear() {
            return;
        }
        let p = self.pairs.len();
        for (m, o) in out.iter_mut().enumerate() {
            let pairs_of_m = &self.pair_of[m * r..(m + 1) * r];
            let mut f = dot(&self.cubic[m * p..(m + 1) * p], &s.pairs);
            let by_middle = &self.cubic_by_middle[m * r * r..(m + 1) * r * r];
            for (row, &ak) in by_middle.chunks_exact(r).zip(a) {
                f += 2.0 * ak * dot(row, a);
            }
            let contracted: f64 = pairs_of_m
                .iter()
                .zip(a)
                .map(|(&q, &aj)| s.contracted[q] * aj)
                .sum();
            *o += f + 2.0 * contracted;
        }
    }

    /// The midpoint `a`, the pairs `s_p` of `a aᵀ + ¼ Δ Δᵀ` and `B s` into `s` (only the
    /// midpoint for the linear law).
    fn midpoint_terms(&self, (q0, q1): (&[f64], &[f64]), s: &mut Scratch) {
        for (m, (x, y)) in s.mid.iter_mut().zip(q0.iter().zip(q1)) {
            *m = 0.5 * (x + y);
        }
        if !self.is_nonlinear() {
            return;
        }
        let a = &s.mid;
        for (sp, &(j, k)) in s.pairs.iter_mut().zip(&self.pairs) {
            let (dj, dk) = (q1[j] - q0[j], q1[k] - q0[k]);
            *sp = weight(j, k) * (a[j] * a[k] + 0.25 * dj * dk);
        }
        let p = self.pairs.len();
        for (g, row) in s.contracted.iter_mut().zip(self.quartic.chunks_exact(p)) {
            *g = dot(row, &s.pairs);
        }
    }

    /// `∂f_ST/∂q₁` of the step from `q₀` to `q₁` into `out` (`r × r`, row-major): for
    /// Newton's method where the rest Jacobian is not enough (large rotations).
    pub fn algorithmic_jacobian(
        &self,
        (q0, q1): (&[f64], &[f64]),
        out: &mut [f64],
        s: &mut Scratch,
    ) {
        let r = self.r;
        self.midpoint_terms((q0, q1), s);
        for (o, k) in out.iter_mut().zip(&self.stiffness) {
            *o = 0.5 * k;
        }
        if !self.is_nonlinear() {
            return;
        }
        let (a, p) = (&s.mid, self.pairs.len());
        let cubic = |i: usize, j: usize, k: usize| self.cubic[i * p + self.pair_of[j * r + k]];
        let quartic = |i: usize, j: usize, k: usize, l: usize| {
            self.quartic[self.pair_of[i * r + j] * p + self.pair_of[k * r + l]]
        };
        for m in 0..r {
            for n in 0..r {
                let mut d = s.contracted[self.pair_of[m * r + n]];
                for k in 0..r {
                    d += cubic(m, n, k) * q1[k] + cubic(n, m, k) * a[k] + cubic(k, m, n) * a[k];
                    let mut inner = 0.0;
                    for (l, &q1l) in q1.iter().enumerate() {
                        inner += quartic(m, k, n, l) * q1l;
                    }
                    d += 2.0 * a[k] * inner;
                }
                out[m * r + n] += d;
            }
        }
    }

    /// The tangent stiffness `∂f/∂q` at `q` into `out` (`r × r`, row-major).
    pub fn tangent(&self, q: &[f64], out: &mut [f64], s: &mut Scratch) {
        self.algorithmic_jacobian((q, q), out, s);
        out.iter_mut().for_each(|k| *k *= 2.0);
    }

    fn k_times(&self, q: &[f64]) -> Vec<f64> {
        self.stiffness
            .chunks_exact(self.r)
            .map(|row| dot(row, q))
            .collect()
    }
}

/// The index pairs `(j, k)`, `j ≤ k`, of `r` modes, and the pair of every `(j, k)`.
fn index_pairs(r: usize) -> (Vec<(usize, usize)>, Vec<usize>) {
    let pairs: Vec<(usize, usize)> = (0..r).flat_map(|j| (j..r).map(move |k| (j, k))).collect();
    let mut pair_of = vec![0; r * r];
    for (p, &(j, k)) in pairs.iter().enumerate() {
        pair_of[j * r + k] = p;
        pair_of[k * r + j] = p;
    }
    (pairs, pair_of)
}

/// How often the pair `(j, k)` stands for itself in a sum over all `j, k`.
fn weight(j: usize, k: usize) -> f64 {
    if j == k { 1.0 } else { 2.0 }
}

/// The stacked rows of elements `first..last`: `ROW` rows per element, one column per mode
/// (linear strains) and one per pair of `pairs` (quadratic strains).
fn element_rows(
    model: &FemModel,
    basis: &ModalBasis,
    elements: std::ops::Range<usize>,
    pairs: &[(usize, usize)],
) -> (DMatrix<f64>, DMatrix<f64>) {
    let r = basis.len();
    let first = elements.start;
    let rows = ROW * elements.len();
    let mut lin = DMatrix::zeros(rows, r);
    let mut quad = DMatrix::zeros(rows, pairs.len());
    let mut gradients = vec![Matrix3::zeros(); r];
    for t in elements {
        let tet = &model.mesh().tets()[t];
        let geometry = &model.geometry()[t];
        for (i, h) in gradients.iter_mut().enumerate() {
            let mode = basis.mode(i);
            *h = (0..4)
                .map(|a| {
                    Vector3::from_fn(|c, _| mode[3 * tet[a] + c]) * geometry.grads[a].transpose()
                })
                .sum();
        }
        let (lambda, mu) = model.lame(t);
        let shear = (2.0 * mu * geometry.volume_m3).sqrt();
        let volume = (lambda * geometry.volume_m3).sqrt();
        let row = ROW * (t - first);
        for (i, h) in gradients.iter().enumerate() {
            write_row(
                &mut lin,
                row,
                i,
                &(0.5 * (h + h.transpose())),
                shear,
                volume,
            );
        }
        for (p, &(j, k)) in pairs.iter().enumerate() {
            let hjk = gradients[j].transpose() * gradients[k];
            write_row(
                &mut quad,
                row,
                p,
                &(0.25 * (hjk + hjk.transpose())),
                shear,
                volume,
            );
        }
    }
    (lin, quad)
}

/// Writes the symmetric tensor `x` as an element row block: `√(2μV)` times its components
/// (√2 on the shears) and `√(λV)` times its trace.
fn write_row(
    m: &mut DMatrix<f64>,
    row: usize,
    column: usize,
    x: &Matrix3<f64>,
    shear: f64,
    volume: f64,
) {
    let s2 = std::f64::consts::SQRT_2;
    let components = [
        x[(0, 0)],
        x[(1, 1)],
        x[(2, 2)],
        s2 * x[(0, 1)],
        s2 * x[(0, 2)],
        s2 * x[(1, 2)],
    ];
    for (c, v) in components.into_iter().enumerate() {
        m[(row + c, column)] = shear * v;
    }
    m[(row + 6, column)] = volume * x.trace();
}
