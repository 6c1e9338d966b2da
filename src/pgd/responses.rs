//! Exact responses `U = K⁻¹ F`, one column per load parameter: what the brute-force baseline
//! computes, and what the vademecum's local part (compliances, near-field corrections) is cut
//! from.

use rayon::prelude::*;

use super::load_patches::{LoadOperator, LoadPatches};
use super::stiffness::RestStiffness;

/// Columns solved together: one pass over the factor serves them all.
const BLOCK_COLUMNS: usize = 48;

/// Free-dof columns of the responses, column-major (`free_count` rows).
pub struct Responses {
    pub rows: usize,
    pub columns: Vec<f64>,
}

impl Responses {
    pub fn count(&self) -> usize {
        self.columns.len() / self.rows
    }

    pub fn column(&self, p: usize) -> &[f64] {
        &self.columns[p * self.rows..(p + 1) * self.rows]
    }

    /// Solves `K u_p = f_p` for every unit load of `patches`, blocks in parallel; `progress` gets
    /// the number of columns done.
    pub fn linear(
        stiffness: &RestStiffness,
        patches: &LoadPatches,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Self {
        let rows = stiffness.free_count();
        let free_index = &stiffness.model.dofs().free_index;
        let mut columns = vec![0.0; rows * patches.parameter_count()];
        columns
            .par_chunks_mut(rows * BLOCK_COLUMNS)
            .enumerate()
            .for_each(|(block, chunk)| {
                let first = block * BLOCK_COLUMNS;
                for (j, column) in chunk.chunks_exact_mut(rows).enumerate() {
                    let p = first + j;
                    let free = free_index[3 * patches.positions[p / 3] + p % 3];
                    if free != crate::fem::PRESCRIBED {
                        column[free] = 1.0;
                    }
                }
                stiffness.solve_block(chunk);
                progress(chunk.len() / rows);
            });
        Self { rows, columns }
    }

    /// The compliance between all pairs of loads, `G = Fᵀ U` (parameters × parameters,
    /// column-major): the energy Gram matrix of the responses, since `Uᵀ K U = Fᵀ U`.
    pub fn gram(&self, stiffness: &RestStiffness, loads: &(dyn LoadOperator + Sync)) -> Vec<f64> {
        let n = self.count();
        let mut gram = vec![0.0; n * n];
        gram.par_chunks_mut(n).enumerate().for_each(|(p, out)| {
            loads.apply_transpose(&stiffness.extend(self.column(p)), out);
        });
        gram
    }
}
