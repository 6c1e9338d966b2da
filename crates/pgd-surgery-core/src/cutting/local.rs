//! The enriched functions' responses over a compressed uncut response (a cut vademecum): a
//! sparse solve on a patch of the organ around the new functions, held at the patch's edge,
//! corrected beyond it by the vademecum's global modes.
//!
//! Composing `K⁻¹ b` from compressed unit responses does not work for a deep cut: an enriched
//! function's forces `b` are self-equilibrated, `Bᵀ K⁻¹ B` rests on the cancellation of
//! neighbouring unit responses, and a compliance accurate to a few per cent per load loses
//! it, so that `S = A − Bᵀ K⁻¹ B` turns indefinite. Here the cut organ is solved instead by a
//! Ritz (Galerkin) approximation on one subspace that grows with the cut: the global modes
//! `X`, and per enriched function `k` the function relaxed by its patch response,
//! `ψ̃_k = ψ_k − r_k` with `r_k = K_P⁻¹ b_k` (zero outside the patch `P`). With the exact
//! response (`r_k = K⁻¹ b_k`) that subspace holds the exact cut field under any load, and the
//! condensation below is the exact one. The condensed matrix is the Schur complement, onto the
//! `ψ̃`, of the cut stiffness's Gram matrix over the subspace: symmetric positive definite by
//! construction however deep and long the cut, and, the modes coming first, bordered as
//! functions are added. With the residual `ρ_k = K r_k − b_k` (the reactions at the patch's
//! edge) and `G = Xᵀ K X`:
//!
//! ```text
//! z̃_k = r_k + X c_k,  c_k = −G⁺ Xᵀ ρ_k          (what the state uses for K⁻¹ b_k)
//! S̃_jk = A_jk − b_jᵀ r_k + r_jᵀ ρ_k + (Xᵀ ρ_j) · c_k
//! ```
//!
//! A segment costs a sparse factorization of its patch, not of the organ.

use faer::MatMut;
use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use nalgebra::{DMatrix, DVector, Point3, SymmetricEigen};

use super::CutError;
use super::response::{Response, UncutResponse};
use crate::fem::{FemModel, PRESCRIBED};
use crate::pgd::SparseDofs;

/// Eigenvalues of `G` below this fraction of the largest are dropped: modes that repeat one
/// another add nothing to the subspace.
const GRAM_CUTOFF: f64 = 1e-12;

/// An enriched function's response from its patch, with what its condensed entries need.
#[derive(Clone, Debug, Default)]
pub struct LocalResponse {
    /// `z̃ = r + X c`: the patch response as the near part, the modal correction as modes.
    pub response: Response,
    /// `ρ = K r − b` over full dofs: the reactions at the patch's edge.
    pub residual: SparseDofs,
    /// `Xᵀ ρ`.
    pub residual_modes: Vec<f64>,
}

/// The stiffness entries between a patch and the free dofs just outside it.
struct Edge {
    /// The outside dofs (full numbering).
    rows: Vec<usize>,
    /// `(patch dof, place in rows, K entry)`.
    entries: Vec<(usize, usize, f64)>,
}

/// The rest stiffness and the modes' Gram matrix, to solve patches around new functions.
pub struct PatchSolver {
    /// Free-dof rest stiffness, both triangles.
    stiffness: SparseColMat<usize, f64>,
    free_index: Vec<usize>,
    free_dofs: Vec<usize>,
    nodes: Vec<Point3<f64>>,
    radius_m: f64,
    /// `G⁺`, the pseudo-inverse of `Xᵀ K X`.
    gram_inverse: DMatrix<f64>,
}

impl PatchSolver {
    /// The solver for `model` whose uncut response `modes` has global modes; a patch holds the
    /// free nodes within `radius_m` of the loaded ones.
    pub fn new(model: &FemModel, modes: &impl UncutResponse, radius_m: f64) -> Self {
        let stiffness = model.pattern().matrix(model.rest_stiffness());
        let free_dofs = model.dofs().free_dofs.clone();
        let gram_inverse = gram_inverse(model, &stiffness, modes);
        Self {
            stiffness,
            free_index: model.dofs().free_index.clone(),
            free_dofs,
            nodes: model.mesh().nodes().to_vec(),
            radius_m,
            gram_inverse,
        }
    }

    /// Patches reach `radius_m` from the loaded nodes from now on.
    pub fn set_radius(&mut self, radius_m: f64) {
        self.radius_m = radius_m;
    }

    /// The responses to `loads` (an enriched function's forces each, on free dofs), all from
    /// one patch around them. An error names a loaded node outside the region `modes` covers.
    pub fn respond(
        &self,
        loads: &[SparseDofs],
        modes: &impl UncutResponse,
    ) -> Result<Vec<LocalResponse>, CutError> {
        if let Some(&(dof, _)) = loads.iter().flatten().find(|(d, _)| !modes.covers(d / 3)) {
            return Err(CutError::OutsideRegion { node: dof / 3 });
        }
        if loads.is_empty() {
            return Ok(Vec::new());
        }
        let patch = self.patch_dofs(loads);
        let mut local = vec![usize::MAX; self.free_dofs.len()];
        for (i, &f) in patch.iter().enumerate() {
            local[f] = i;
        }
        let n = patch.len();
        let mut block = vec![0.0; n * loads.len()];
        for (c, load) in loads.iter().enumerate() {
            for &(dof, v) in load {
                block[c * n + local[self.free_index[dof]]] += v;
            }
        }
        self.solve_patch(&patch, &local, &mut block)?;
        let edge = self.edge(&patch, &local);
        Ok(block
            .chunks_exact(n)
            .map(|column| self.local_response(&patch, &edge, column, modes))
            .collect())
    }

    /// The stiffness entries that couple the patch's dofs to the free dofs just outside it:
    /// all that a patch response's residual reads.
    fn edge(&self, patch: &[usize], local: &[usize]) -> Edge {
        let (row_idx, col_ptr) = (
            self.stiffness.symbolic().row_idx(),
            self.stiffness.symbolic().col_ptr(),
        );
        let values = self.stiffness.val();
        let mut rows: Vec<usize> = Vec::new();
        let mut slot = std::collections::HashMap::new();
        let mut entries = Vec::new();
        for (i, &f) in patch.iter().enumerate() {
            for p in col_ptr[f]..col_ptr[f + 1] {
                if local[row_idx[p]] == usize::MAX {
                    let k = *slot.entry(row_idx[p]).or_insert_with(|| {
                        rows.push(self.free_dofs[row_idx[p]]);
                        rows.len() - 1
                    });
                    entries.push((i, k, values[p]));
                }
            }
        }
        Edge { rows, entries }
    }

    /// The free dofs of the nodes within the radius of a loaded node, found by walking the
    /// stiffness's neighbours outward from the loaded nodes (each keeps the loaded node it
    /// was reached from), sorted.
    fn patch_dofs(&self, loads: &[SparseDofs]) -> Vec<usize> {
        let node_count = self.nodes.len();
        let mut seed_of = vec![usize::MAX; node_count];
        let mut queue: Vec<usize> = Vec::new();
        for &(dof, _) in loads.iter().flatten() {
            let node = dof / 3;
            if seed_of[node] == usize::MAX {
                seed_of[node] = node;
                queue.push(node);
            }
        }
        let (row_idx, col_ptr) = (
            self.stiffness.symbolic().row_idx(),
            self.stiffness.symbolic().col_ptr(),
        );
        let mut next = 0;
        while next < queue.len() {
            let node = queue[next];
            next += 1;
            let Some(f) = (0..3)
                .map(|c| self.free_index[3 * node + c])
                .find(|&f| f != PRESCRIBED)
            else {
                continue;
            };
            let seed = self.nodes[seed_of[node]];
            for &row in &row_idx[col_ptr[f]..col_ptr[f + 1]] {
                let neighbour = self.free_dofs[row] / 3;
                if seed_of[neighbour] == usize::MAX
                    && (self.nodes[neighbour] - seed).norm() <= self.radius_m
                {
                    seed_of[neighbour] = seed_of[node];
                    queue.push(neighbour);
                }
            }
        }
        let mut dofs: Vec<usize> = queue
            .iter()
            .flat_map(|&node| (0..3).map(move |c| 3 * node + c))
            .map(|d| self.free_index[d])
            .filter(|&f| f != PRESCRIBED)
            .collect();
        dofs.sort_unstable();
        dofs
    }

    /// Overwrites `block` (column-major, one column per load over the patch's dofs) with the
    /// patch's responses, its edge held.
    fn solve_patch(
        &self,
        patch: &[usize],
        local: &[usize],
        block: &mut [f64],
    ) -> Result<(), CutError> {
        let (row_idx, col_ptr) = (
            self.stiffness.symbolic().row_idx(),
            self.stiffness.symbolic().col_ptr(),
        );
        let values = self.stiffness.val();
        let (mut ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
        for &f in patch {
            for p in col_ptr[f]..col_ptr[f + 1] {
                let r = local[row_idx[p]];
                if r != usize::MAX {
                    rows.push(r);
                    vals.push(values[p]);
                }
            }
            ptr.push(rows.len());
        }
        let n = patch.len();
        let failed = |e: &dyn std::fmt::Debug| CutError::Solve(format!("a patch solve: {e:?}"));
        let symbolic = SymbolicSparseColMat::new_checked(n, n, ptr, None, rows);
        let matrix = SparseColMat::new(symbolic, vals);
        let analysis =
            SymbolicLlt::try_new(matrix.symbolic(), Side::Lower).map_err(|e| failed(&e))?;
        let llt = Llt::try_new_with_symbolic(analysis, matrix.as_ref(), Side::Lower)
            .map_err(|e| failed(&e))?;
        let columns = block.len() / n.max(1);
        llt.solve_in_place(MatMut::from_column_major_slice_mut(block, n, columns));
        Ok(())
    }

    /// One load's response from its patch solution `column`: the residual at the patch's edge
    /// and the modes' correction for it.
    fn local_response(
        &self,
        patch: &[usize],
        edge: &Edge,
        column: &[f64],
        modes: &impl UncutResponse,
    ) -> LocalResponse {
        // K r outside the patch (inside, it equals the load to round-off).
        let mut reaction = vec![0.0; edge.rows.len()];
        for &(i, k, value) in &edge.entries {
            reaction[k] += value * column[i];
        }
        let residual: SparseDofs = edge.rows.iter().copied().zip(reaction).collect();
        let residual_modes = modes.spatial_products(&residual);
        let modal = -(&self.gram_inverse * DVector::from_column_slice(&residual_modes));
        LocalResponse {
            response: Response {
                modal: modal.as_slice().to_vec(),
                near: patch
                    .iter()
                    .zip(column)
                    .map(|(&f, &r)| (self.free_dofs[f], r))
                    .collect(),
            },
            residual,
            residual_modes,
        }
    }
}

/// `G⁺` for `G = Xᵀ K X` over the free dofs, eigenvalues below [`GRAM_CUTOFF`] of the largest
/// dropped.
fn gram_inverse(
    model: &FemModel,
    stiffness: &SparseColMat<usize, f64>,
    modes: &impl UncutResponse,
) -> DMatrix<f64> {
    let m = modes.modes();
    let free = &model.dofs().free_dofs;
    let mut full = vec![0.0; 3 * model.mesh().node_count()];
    let (mut x, mut kx) = (Vec::with_capacity(m), Vec::with_capacity(m));
    for k in 0..m {
        full.fill(0.0);
        let mut unit = vec![0.0; m];
        unit[k] = 1.0;
        modes.add_spatial(&unit, &mut full);
        let xk: Vec<f64> = free.iter().map(|&d| full[d]).collect();
        let mut yk = vec![0.0; free.len()];
        model.pattern().mul(stiffness.val(), &xk, &mut yk);
        x.push(xk);
        kx.push(yk);
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
    let gram = DMatrix::from_fn(m, m, |i, j| 0.5 * (dot(&x[i], &kx[j]) + dot(&x[j], &kx[i])));
    let eigen = SymmetricEigen::new(gram);
    let largest = eigen.eigenvalues.iter().copied().fold(0.0, f64::max);
    let inverted = eigen.eigenvalues.map(|l| {
        if l > GRAM_CUTOFF * largest {
            1.0 / l
        } else {
            0.0
        }
    });
    &eigen.eigenvectors * DMatrix::from_diagonal(&inverted) * eigen.eigenvectors.transpose()
}
