//! The sparsity pattern of the free-dof stiffness matrix, and where each element entry lands.
//!
//! The pattern is built once per mesh and set of constraints; every later assembly (each
//! Newton iteration, each PGD enrichment) only zeroes and refills the values, so the symbolic
//! factorization can be reused as well.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

use super::element::ElementMatrix;
use super::{DofMap, PRESCRIBED};
use crate::mesh::TetMesh;

/// Marks an element entry that touches a prescribed dof and is not assembled.
const SKIP: u32 = u32::MAX;

/// Symmetric CSC pattern over free dofs (both triangles stored) plus scatter indices.
#[derive(Clone, Debug)]
pub struct FreePattern {
    symbolic: SymbolicSparseColMat<usize>,
    /// For tet `t`, entry `144 t + 12 i + j` is the position of element entry (i, j) in the
    /// value array, or [`SKIP`].
    scatter: Vec<u32>,
}

impl FreePattern {
    /// The pattern of element matrices: nodes that share a tetrahedron.
    pub fn new(mesh: &TetMesh, dofs: &DofMap) -> Self {
        Self::with_neighbours(mesh, dofs, &node_neighbours(mesh))
    }

    /// The pattern of an energy on nodal volumes: nodes that share a neighbour (two rings).
    pub fn two_ring(mesh: &TetMesh, dofs: &DofMap) -> Self {
        let ring = node_neighbours(mesh);
        let neighbours: Vec<Vec<usize>> = ring
            .iter()
            .map(|around| {
                let mut reach: Vec<usize> = around
                    .iter()
                    .flat_map(|&m| ring[m].iter().copied())
                    .collect();
                reach.sort_unstable();
                reach.dedup();
                reach
            })
            .collect();
        Self::with_neighbours(mesh, dofs, &neighbours)
    }

    fn with_neighbours(mesh: &TetMesh, dofs: &DofMap, neighbours: &[Vec<usize>]) -> Self {
        let n = dofs.free_count();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for &dof in &dofs.free_dofs {
            for &m in &neighbours[dof / 3] {
                row_idx.extend(
                    (3 * m..3 * m + 3)
                        .map(|d| dofs.free_index[d])
                        .filter(|&r| r != PRESCRIBED),
                );
            }
            col_ptr.push(row_idx.len());
        }
        assert!(
            row_idx.len() < SKIP as usize,
            "stiffness pattern larger than 4 billion entries"
        );
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let scatter = scatter_indices(mesh, dofs, &symbolic);
        Self { symbolic, scatter }
    }

    /// Number of free dofs.
    pub fn dim(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// A zero value array for this pattern.
    pub fn zero_values(&self) -> Vec<f64> {
        vec![0.0; self.nnz()]
    }

    /// Adds an element matrix of tet `t` into `values`, skipping prescribed dofs.
    pub fn scatter(&self, t: usize, element: &ElementMatrix, values: &mut [f64]) {
        let map = &self.scatter[144 * t..144 * (t + 1)];
        for j in 0..12 {
            for i in 0..12 {
                let pos = map[12 * i + j];
                if pos != SKIP {
                    values[pos as usize] += element[(i, j)];
                }
            }
        }
    }

    /// Adds a 3×3 block coupling node `row` to node `col` into `values` (a force acting on the
    /// nodes of one surface triangle, such as a rigid tool's contact), skipping prescribed
    /// dofs. The two nodes must share a tetrahedron (or a neighbour, in a two-ring pattern).
    pub fn add_node_block(
        &self,
        dofs: &DofMap,
        nodes: (usize, usize),
        block: &nalgebra::Matrix3<f64>,
        values: &mut [f64],
    ) {
        add_at(&self.block_positions(dofs, nodes), block, values);
    }

    /// Where each entry `(i, j)` of the 3×3 block coupling node `row` to node `col` lands in
    /// the values (index `3i + j`), or `SKIP` where a dof is prescribed.
    pub(super) fn block_positions(&self, dofs: &DofMap, (row, col): (usize, usize)) -> [u32; 9] {
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        std::array::from_fn(|k| {
            let (r, c) = (
                dofs.free_index[3 * row + k / 3],
                dofs.free_index[3 * col + k % 3],
            );
            if r == PRESCRIBED || c == PRESCRIBED {
                return SKIP;
            }
            let column = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            let offset = column
                .binary_search(&r)
                .expect("the pattern holds every pair of nodes the block couples");
            (col_ptr[c] + offset) as u32
        })
    }

    /// Wraps values into a faer matrix (copies the pattern, which is cheap next to a solve).
    pub fn matrix(&self, values: Vec<f64>) -> SparseColMat<usize, f64> {
        SparseColMat::new(self.symbolic.clone(), values)
    }

    pub fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// `y = A x` for a matrix with this pattern.
    pub fn mul(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        for (j, &xj) in x.iter().enumerate() {
            for p in col_ptr[j]..col_ptr[j + 1] {
                y[row_idx[p]] += values[p] * xj;
            }
        }
    }
}

/// Adds a 3×3 block at the positions of [`FreePattern::block_positions`].
pub(super) fn add_at(positions: &[u32], block: &nalgebra::Matrix3<f64>, values: &mut [f64]) {
    for (k, &pos) in positions.iter().enumerate() {
        if pos != SKIP {
            values[pos as usize] += block[(k / 3, k % 3)];
        }
    }
}

/// Sorted node adjacency through shared tetrahedra, each node listing itself.
fn node_neighbours(mesh: &TetMesh) -> Vec<Vec<usize>> {
    let mut neighbours = vec![Vec::new(); mesh.node_count()];
    for tet in mesh.tets() {
        for &a in tet {
            neighbours[a].extend_from_slice(tet);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    neighbours
}

fn scatter_indices(
    mesh: &TetMesh,
    dofs: &DofMap,
    symbolic: &SymbolicSparseColMat<usize>,
) -> Vec<u32> {
    let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
    let mut scatter = Vec::with_capacity(144 * mesh.tet_count());
    for tet in mesh.tets() {
        let free: [usize; 12] = std::array::from_fn(|i| dofs.free_index[3 * tet[i / 3] + i % 3]);
        for &row in &free {
            for &col in &free {
                if row == PRESCRIBED || col == PRESCRIBED {
                    scatter.push(SKIP);
                    continue;
                }
                let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                let offset = column
                    .binary_search(&row)
                    .expect("the pattern holds every pair of dofs that share a tetrahedron");
                scatter.push((col_ptr[col] + offset) as u32);
            }
        }
    }
    scatter
}
