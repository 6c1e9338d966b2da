//! The full X-FEM solve of a cut organ: the reference every reduced cut is checked against.
//!
//! The unknowns are every node's displacement (3 per node) followed by every enriched
//! function's (3 each, [`Enrichment::functions`]' order). A linear tetrahedron's gradients are
//! constant, so an element's stiffness between functions `α` and `β` (corner `a`, `b`) is the
//! plain linear-elastic block `k_ab` times `Σ_pieces V_p c_α c_β`, with `c = 1` for a node's
//! own function and `c = H_p − H(x_node)` for an enriched one: exact, with no quadrature.

use faer::MatMut;
use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{Matrix3, Vector3};

use super::CutError;
use super::enrichment::{ElementCut, Enrichment};
use crate::fem::{FemModel, Loads, PRESCRIBED};

/// A cut organ's displacement: every node's, and every enriched function's amplitude (m).
#[derive(Clone, Debug, PartialEq)]
pub struct CutSolution {
    pub nodes_m: Vec<f64>,
    pub enriched_m: Vec<f64>,
}

impl CutSolution {
    /// Node `node`'s displacement as seen from the side `sides` of each face (`+1` or `−1`
    /// per face, in the order the faces were given): on its own side, its nodal value.
    pub fn at_node(&self, enrichment: &Enrichment, node: usize, sides: &[i8]) -> Vector3<f64> {
        let mut u = Vector3::from_column_slice(&self.nodes_m[3 * node..3 * node + 3]);
        for (j, f) in enrichment.functions.iter().enumerate() {
            if f.node == node {
                let c = f64::from(sides[f.face] - f.node_side);
                u += Vector3::from_column_slice(&self.enriched_m[3 * j..3 * j + 3]) * c;
            }
        }
        u
    }
}

/// Solves the cut organ under `loads` (nodal forces, each acting on its node's own side).
/// `model` gives the mesh, the material and the clamped nodes; an enriched function of a
/// clamped node is held too. A cut that frees a piece of tissue is refused.
pub fn solve(
    model: &FemModel,
    enrichment: &Enrichment,
    loads: &Loads,
) -> Result<CutSolution, CutError> {
    Ok(solve_each(model, enrichment, &[loads.as_slice()])?.remove(0))
}

/// The force (N) a tool feels pressing `patch` (nodes and their shares of its load, summing
/// to one) by `indentation_m` into the cut organ: the patch compliance from three solves (a
/// unit force along each axis, spread by the shares), inverted. The reference for
/// [`super::CutState::felt_force`]; `None` where the patch does not resist.
pub fn felt_force(
    model: &FemModel,
    enrichment: &Enrichment,
    patch: &[(usize, f64)],
    indentation_m: Vector3<f64>,
) -> Result<Option<Vector3<f64>>, CutError> {
    let dofs = 3 * model.mesh().node_count();
    let loads: Vec<Vec<f64>> = (0..3)
        .map(|axis| {
            let mut f = vec![0.0; dofs];
            patch
                .iter()
                .for_each(|&(n, share)| f[3 * n + axis] += share);
            f
        })
        .collect();
    let columns: Vec<&[f64]> = loads.iter().map(Vec::as_slice).collect();
    let solutions = solve_each(model, enrichment, &columns)?;
    let mut compliance = Matrix3::zeros();
    for (axis, u) in solutions.iter().enumerate() {
        for &(n, share) in patch {
            for row in 0..3 {
                compliance[(row, axis)] += share * u.nodes_m[3 * n + row];
            }
        }
    }
    Ok(compliance.try_inverse().map(|k| k * indentation_m))
}

/// Solves the cut organ under each of `loads` (nodal forces over every dof), with one
/// factorization.
pub fn solve_each(
    model: &FemModel,
    enrichment: &Enrichment,
    loads: &[&[f64]],
) -> Result<Vec<CutSolution>, CutError> {
    let own = &model.dofs().free_index;
    if enrichment.detaches(model.mesh(), |n| own[3 * n] == PRESCRIBED) {
        return Err(CutError::Detached);
    }
    let dofs = Dofs::new(model, enrichment);
    let matrix = assemble(model, enrichment, &dofs)?;
    let mut rhs = vec![0.0; dofs.free * loads.len()];
    for (column, load) in rhs.chunks_exact_mut(dofs.free.max(1)).zip(loads) {
        for (d, &f) in load.iter().enumerate() {
            if let Some(i) = dofs.index(d) {
                column[i] += f;
            }
        }
    }
    let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower)
        .map_err(|e| CutError::Solve(format!("{e:?}")))?;
    let llt = Llt::try_new_with_symbolic(symbolic, matrix.as_ref(), Side::Lower)
        .map_err(|_| CutError::Detached)?;
    llt.solve_in_place(MatMut::from_column_major_slice_mut(
        &mut rhs,
        dofs.free,
        loads.len(),
    ));
    if rhs.iter().any(|v| !v.is_finite()) {
        return Err(CutError::Detached);
    }
    let nodes = 3 * model.mesh().node_count();
    Ok(rhs
        .chunks_exact(dofs.free.max(1))
        .take(loads.len())
        .map(|column| {
            let value = |d: usize| dofs.index(d).map_or(0.0, |i| column[i]);
            CutSolution {
                nodes_m: (0..nodes).map(value).collect(),
                enriched_m: (nodes..dofs.total).map(value).collect(),
            }
        })
        .collect())
}

/// The numbering of the free unknowns: a node's own dofs are free where the model's are; an
/// enriched function's where its node is not held.
struct Dofs {
    free_index: Vec<usize>,
    free: usize,
    total: usize,
}

impl Dofs {
    fn new(model: &FemModel, enrichment: &Enrichment) -> Self {
        let own = &model.dofs().free_index;
        let mut free_index = own.clone();
        for f in &enrichment.functions {
            let held = (0..3).any(|c| own[3 * f.node + c] == PRESCRIBED);
            free_index.extend([0; 3].map(|_| if held { PRESCRIBED } else { 0 }));
        }
        let mut free = 0;
        for i in free_index.iter_mut() {
            if *i != PRESCRIBED {
                *i = free;
                free += 1;
            }
        }
        Self {
            total: free_index.len(),
            free_index,
            free,
        }
    }

    fn index(&self, dof: usize) -> Option<usize> {
        self.free_index
            .get(dof)
            .copied()
            .filter(|&i| i != PRESCRIBED)
    }
}

/// The enriched stiffness over the free unknowns (both triangles).
fn assemble(
    model: &FemModel,
    enrichment: &Enrichment,
    dofs: &Dofs,
) -> Result<SparseColMat<usize, f64>, CutError> {
    let nodes = model.mesh().node_count();
    let mut triplets = Vec::new();
    for (t, tet) in model.mesh().tets().iter().enumerate() {
        let geometry = &model.geometry()[t];
        let (lambda, mu) = model.lame(t);
        let cut = &enrichment.elements[t];
        let functions = element_functions(tet, cut, nodes);
        let weights = piece_weights(cut, &functions, enrichment, geometry.volume_m3);
        for (x, &(row, a)) in functions.iter().enumerate() {
            for (y, &(col, b)) in functions.iter().enumerate() {
                let w = weights[x * functions.len() + y];
                if w == 0.0 {
                    continue;
                }
                let block = geometry.elastic_block(a, b, lambda, mu) * w;
                for i in 0..3 {
                    for j in 0..3 {
                        if let (Some(r), Some(c)) = (dofs.index(row + i), dofs.index(col + j)) {
                            triplets.push(Triplet::new(r, c, block[(i, j)]));
                        }
                    }
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(dofs.free, dofs.free, &triplets)
        .map_err(|e| CutError::Solve(format!("{e:?}")))
}

/// The element's functions: first dof of each and its corner; the four corners' own, then
/// the enriched ones.
pub(super) fn element_functions(
    tet: &[usize; 4],
    cut: &ElementCut,
    nodes: usize,
) -> Vec<(usize, usize)> {
    (0..4)
        .map(|a| (3 * tet[a], a))
        .chain(cut.functions.iter().map(|&(j, a)| (3 * nodes + 3 * j, a)))
        .collect()
}

/// `Σ_pieces V_p c_α c_β` for every pair of the element's functions (row-major).
pub(super) fn piece_weights(
    cut: &ElementCut,
    functions: &[(usize, usize)],
    enrichment: &Enrichment,
    volume_m3: f64,
) -> Vec<f64> {
    let n = functions.len();
    if cut.functions.is_empty() {
        return vec![volume_m3; n * n];
    }
    let mut weights = vec![0.0; n * n];
    let mut c = vec![1.0; n];
    for piece in &cut.pieces {
        for (x, &(j, _)) in cut.functions.iter().enumerate() {
            let f = enrichment.functions[j];
            let slot = cut.faces.iter().position(|&k| k == f.face).expect("named");
            c[4 + x] = f64::from(piece.sides[slot] - f.node_side);
        }
        for x in 0..n {
            for y in 0..n {
                weights[x * n + y] += piece.volume_m3 * c[x] * c[y];
            }
        }
    }
    weights
}
