//! The basis the dynamics run in: the organ's lowest vibration modes, mass-orthonormal and
//! ordered by frequency.
//!
//! They are found by subspace iteration (`K⁻¹ M` applied to a block, then Rayleigh–Ritz)
//! started from the vademecum's spatial modes, which already span much of the organ's
//! response to the tool, and the rigid motions, which the lowest modes of an organ hanging
//! from its attachments resemble. Their frequencies converge to the full model's from above
//! (`tests/dynamics`: the lowest within 0.1 % of a dense modal analysis). What the kept modes
//! miss of a load's response is stiff (its frequencies lie above the kept ones, far above
//! what a hand moves at) and answers the load quasi-statically:
//! [`ModalBasis::static_coordinates`] is the kept modes' share of a static response, and the
//! vademecum's exact static response less that share is the remainder (the mode-acceleration
//! method).

use nalgebra::{DMatrix, SymmetricEigen, Vector3};

use super::DynamicsError;
use crate::fem::FemModel;
use crate::pgd::{RestStiffness, Vademecum};

/// Vectors iterated beyond those kept: the lowest kept modes converge at the rate of their
/// frequency over the first guard vector's.
const GUARD_VECTORS: usize = 8;

/// Subspace iterations from the vademecum's modes: enough for the kept frequencies to settle
/// to a fraction of a per cent (`tests/dynamics`).
const SUBSPACE_ITERATIONS: usize = 6;

/// The seed of the scattered start vectors: the same basis on every run.
const SCATTER_SEED: u64 = 0x9E37_79B9_7F4A_7C15;

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
        let full = 3 * model.mesh().node_count();
        let subspace = columns
            .chunks_exact(full)
            .map(|c| dofs.restrict(c))
            .collect();
        let (modes, omega2) = Matrices::of(model).ritz(subspace, keep)?;
        Ok(Self::from_free(model, &modes, omega2))
    }

    /// The `keep` lowest vibration modes of `model`, found by subspace iteration from
    /// `vademecum`'s linear spatial modes, the rigid motions (which the lowest modes of an
    /// organ hanging from its attachments resemble) and, where these are too few, scattered
    /// vectors: each iteration multiplies the subspace by `K⁻¹ M` and takes its Ritz vectors
    /// again.
    pub fn of_vademecum(
        model: &FemModel,
        vademecum: &Vademecum,
        keep: usize,
    ) -> Result<Self, DynamicsError> {
        let dofs = model.dofs();
        let full = 3 * model.mesh().node_count();
        let mut subspace: Vec<Vec<f64>> = vademecum.steps[0]
            .spatial
            .chunks_exact(full)
            .map(|c| dofs.restrict(&c.iter().map(|&v| f64::from(v)).collect::<Vec<_>>()))
            .collect();
        subspace.extend(rigid_motions(model).iter().map(|c| dofs.restrict(c)));
        let block = (keep + GUARD_VECTORS).min(dofs.free_count());
        let missing = block.saturating_sub(subspace.len());
        subspace.extend(scattered(missing, dofs.free_count()));
        let matrices = Matrices::of(model);
        let stiffness = RestStiffness::new(model)?;
        let (mut modes, mut omega2) = matrices.ritz(subspace, block)?;
        for _ in 0..SUBSPACE_ITERATIONS {
            let mut block_columns: Vec<f64> =
                modes.iter().flat_map(|x| matrices.mass_times(x)).collect();
            stiffness.solve_block(&mut block_columns);
            let rows = dofs.free_count();
            let next = block_columns
                .chunks_exact(rows)
                .map(<[f64]>::to_vec)
                .collect();
            (modes, omega2) = matrices.ritz(next, block)?;
        }
        modes.truncate(keep.max(1));
        omega2.truncate(keep.max(1));
        Ok(Self::from_free(model, &modes, omega2))
    }

    /// The basis of `modes` over free dofs, zero on the prescribed ones.
    fn from_free(model: &FemModel, modes: &[Vec<f64>], omega2: Vec<f64>) -> Self {
        let full = 3 * model.mesh().node_count();
        let mut vectors = vec![0.0; full * modes.len()];
        for (column, mode) in vectors.chunks_exact_mut(full).zip(modes) {
            for (&d, &v) in model.dofs().free_dofs.iter().zip(mode) {
                column[d] = v;
            }
        }
        Self {
            vectors,
            dof_count: full,
            omega2,
        }
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

/// The rest stiffness and consistent mass of a model over its free dofs.
struct Matrices<'a> {
    model: &'a FemModel,
    stiffness: Vec<f64>,
    mass: Vec<f64>,
}

impl<'a> Matrices<'a> {
    fn of(model: &'a FemModel) -> Self {
        Self {
            model,
            stiffness: model.rest_stiffness(),
            mass: model.consistent_mass(),
        }
    }

    fn times(&self, values: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        self.model.pattern().mul(values, x, &mut y);
        y
    }

    fn mass_times(&self, x: &[f64]) -> Vec<f64> {
        self.times(&self.mass, x)
    }

    /// The `keep` lowest Ritz pairs of the span of `subspace` (free dofs): mass-orthonormal
    /// vectors and their squared frequencies, ascending.
    fn ritz(
        &self,
        subspace: Vec<Vec<f64>>,
        keep: usize,
    ) -> Result<(Vec<Vec<f64>>, Vec<f64>), DynamicsError> {
        let q = mass_orthonormal(subspace, &|x| self.mass_times(x));
        if q.is_empty() {
            return Err(DynamicsError::EmptyBasis);
        }
        let kq: Vec<Vec<f64>> = q.iter().map(|x| self.times(&self.stiffness, x)).collect();
        let m = q.len();
        let reduced =
            DMatrix::from_fn(m, m, |i, j| 0.5 * (dot(&q[i], &kq[j]) + dot(&q[j], &kq[i])));
        let eigen = SymmetricEigen::new(reduced);
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        order.truncate(keep.max(1));
        let modes = order
            .iter()
            .map(|&k| {
                let mut mode = vec![0.0; q[0].len()];
                for (i, qi) in q.iter().enumerate() {
                    let y = eigen.eigenvectors[(i, k)];
                    mode.iter_mut().zip(qi).for_each(|(m, v)| *m += y * v);
                }
                mode
            })
            .collect();
        Ok((modes, order.iter().map(|&k| eigen.eigenvalues[k]).collect()))
    }
}

/// `count` reproducible pseudo-random vectors of length `n` in [-1, 1]: the usual start of a
/// subspace iteration, where the vademecum and the rigid motions give too few vectors.
fn scattered(count: usize, n: usize) -> Vec<Vec<f64>> {
    let mut rng = fastrand::Rng::with_seed(SCATTER_SEED);
    (0..count)
        .map(|_| (0..n).map(|_| 2.0 * rng.f64() - 1.0).collect())
        .collect()
}

/// The six rigid motions of the mesh about its centroid, over all dofs.
fn rigid_motions(model: &FemModel) -> Vec<Vec<f64>> {
    let nodes = model.mesh().nodes();
    let centroid = nodes.iter().map(|p| p.coords).sum::<Vector3<f64>>() / nodes.len() as f64;
    let motion = |at: &dyn Fn(Vector3<f64>) -> Vector3<f64>| -> Vec<f64> {
        nodes
            .iter()
            .flat_map(|p| {
                let v = at(p.coords - centroid);
                [v.x, v.y, v.z]
            })
            .collect()
    };
    (0..3)
        .map(|axis| motion(&|_| Vector3::ith(axis, 1.0)))
        .chain((0..3).map(|axis| motion(&|r| Vector3::<f64>::ith(axis, 1.0).cross(&r))))
        .collect()
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
