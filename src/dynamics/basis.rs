//! The basis the dynamics run in: Ritz vectors of a subspace, mass-orthonormal and ordered by
//! frequency.
//!
//! The subspace is the vademecum's spatial modes: they span the organ's response to the tool
//! anywhere on its accessible surface, which is where the grasp and the press load it. The
//! Rayleigh–Ritz step (`Kᵣ y = ω² Mᵣ y` in that subspace) turns them into vibration modes of
//! the organ restricted to it, whose frequencies are upper bounds of the full model's; the
//! lowest few are kept. What the kept modes miss of a load's response is stiff (its
//! frequencies lie above the kept ones, far above what a hand moves at) and answers it
//! quasi-statically: [`ModalBasis::static_coordinates`] is the kept modes' share of a static
//! response, and the vademecum's exact static response less that share is the remainder
//! (the mode-acceleration method).

use nalgebra::{DMatrix, SymmetricEigen};

use super::DynamicsError;
use crate::fem::FemModel;
use crate::pgd::Vademecum;

/// A vector whose mass norm falls below this fraction of its norm before orthogonalization
/// depends on the others and is dropped.
const DEPENDENT: f64 = 1e-8;

/// Mass-orthonormal vibration modes over all dofs of a model (zero on prescribed dofs).
#[derive(Clone, Debug)]
pub struct ModalBasis {
    /// The modes, column-major, `dof_count` rows each.
    pub vectors: Vec<f64>,
    pub dof_count: usize,
    /// Squared angular frequencies (rad²/s²), ascending.
    pub omega2: Vec<f64>,
}

impl ModalBasis {
    /// The `keep` lowest Ritz vectors of the subspace spanned by `columns` (all dofs,
    /// column-major) for `model`'s rest stiffness and consistent mass.
    pub fn ritz(model: &FemModel, columns: &[f64], keep: usize) -> Result<Self, DynamicsError> {
        let dofs = model.dofs();
        let (full, free) = (3 * model.mesh().node_count(), dofs.free_count());
        let pattern = model.pattern();
        let (stiffness, mass) = (model.rest_stiffness(), model.consistent_mass());
        let mass_times = |x: &[f64]| {
            let mut y = vec![0.0; free];
            pattern.mul(&mass, x, &mut y);
            y
        };
        let subspace: Vec<Vec<f64>> = columns
            .chunks_exact(full)
            .map(|column| dofs.restrict(column))
            .collect();
        let q = mass_orthonormal(subspace, &mass_times);
        if q.is_empty() {
            return Err(DynamicsError::EmptyBasis);
        }
        let kq: Vec<Vec<f64>> = q
            .iter()
            .map(|x| {
                let mut y = vec![0.0; free];
                pattern.mul(&stiffness, x, &mut y);
                y
            })
            .collect();
        let m = q.len();
        let reduced =
            DMatrix::from_fn(m, m, |i, j| 0.5 * (dot(&q[i], &kq[j]) + dot(&q[j], &kq[i])));
        let eigen = SymmetricEigen::new(reduced);
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        order.truncate(keep.max(1));
        let mut vectors = vec![0.0; full * order.len()];
        for (column, &k) in vectors.chunks_exact_mut(full).zip(&order) {
            for (i, qi) in q.iter().enumerate() {
                let y = eigen.eigenvectors[(i, k)];
                for (&d, &v) in dofs.free_dofs.iter().zip(qi) {
                    column[d] += y * v;
                }
            }
        }
        Ok(Self {
            vectors,
            dof_count: full,
            omega2: order.iter().map(|&k| eigen.eigenvalues[k]).collect(),
        })
    }

    /// The `keep` lowest Ritz vectors of the subspace of `vademecum`'s linear spatial modes.
    pub fn of_vademecum(
        model: &FemModel,
        vademecum: &Vademecum,
        keep: usize,
    ) -> Result<Self, DynamicsError> {
        let columns: Vec<f64> = vademecum.steps[0]
            .spatial
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        Self::ritz(model, &columns, keep)
    }

    pub fn len(&self) -> usize {
        self.omega2.len()
    }

    pub fn is_empty(&self) -> bool {
        self.omega2.is_empty()
    }

    pub fn mode(&self, k: usize) -> &[f64] {
        &self.vectors[k * self.dof_count..(k + 1) * self.dof_count]
    }

    /// The generalized force `Φᵀ f` of a force `f` on all dofs.
    pub fn project(&self, force: &[f64]) -> Vec<f64> {
        (0..self.len()).map(|k| dot(self.mode(k), force)).collect()
    }

    /// `u = Φ q` over all dofs.
    pub fn displacement(&self, q: &[f64]) -> Vec<f64> {
        let mut u = vec![0.0; self.dof_count];
        for (k, &qk) in q.iter().enumerate() {
            for (u, &phi) in u.iter_mut().zip(self.mode(k)) {
                *u += qk * phi;
            }
        }
        u
    }

    /// The kept modes' static answer to a generalized force, `qₖ = fₖ / ωₖ²`.
    pub fn static_coordinates(&self, generalized_force: &[f64]) -> Vec<f64> {
        generalized_force
            .iter()
            .zip(&self.omega2)
            .map(|(f, w2)| f / w2)
            .collect()
    }
}

/// Modified Gram–Schmidt in the mass inner product, twice over for round-off, dropping the
/// vectors that depend on those before them.
fn mass_orthonormal(
    vectors: Vec<Vec<f64>>,
    mass_times: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let mut basis: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for mut v in vectors {
        let scale = dot(&v, &mass_times(&v)).sqrt();
        if scale.is_nan() || scale <= 0.0 {
            continue;
        }
        for _ in 0..2 {
            for (b, mb) in &basis {
                let c = dot(&v, mb);
                v.iter_mut().zip(b).for_each(|(v, b)| *v -= c * b);
            }
        }
        let mv = mass_times(&v);
        let norm = dot(&v, &mv).sqrt();
        if norm <= DEPENDENT * scale {
            continue;
        }
        v.iter_mut().for_each(|x| *x /= norm);
        let mv = mv.into_iter().map(|x| x / norm).collect();
        basis.push((v, mv));
    }
    basis.into_iter().map(|(b, _)| b).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
