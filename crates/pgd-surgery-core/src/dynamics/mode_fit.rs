//! The kept vibration modes written in the vademecum's own spatial modes.
//!
//! Everything that reads an organ's shape from its vademecum coefficients — organ-against-organ
//! contact (the pointshell, the master's distance field) and attachments (the carry) — sees
//! the static field only. Adding the motion there in the vademecum's modes lets all of it see
//! the organ swing, with no change to how it reads: the kept modes are fitted, once, by least
//! squares over the accessible surface (the load positions, which is all that contact and
//! attachments read), and each tick the motion costs `kept × modes` products.
//!
//! The kept modes are found by subspace iteration started from the vademecum's modes, so they
//! lie close to their span; what the fit misses is reported per mode as a relative residual
//! (`tests/dynamics`: the coarse organs' lowest modes to a few per cent).

use nalgebra::DMatrix;

use super::ModalBasis;
use crate::pgd::Vademecum;

/// Singular values below this fraction of the largest are dropped: the vademecum's modes are
/// not orthogonal, and nearly dependent ones would amplify round-off.
const RANK_TOLERANCE: f64 = 1e-10;

/// Per kept mode, its coefficients over the vademecum's first load step's spatial modes.
#[derive(Clone, Debug)]
pub struct ModeFit {
    /// Row-major, `kept × modes`.
    coefficients: Vec<f64>,
    modes: usize,
    /// Per kept mode, the fit's residual over the accessible surface relative to the mode there.
    pub residual: Vec<f64>,
}

impl ModeFit {
    /// Fits every mode of `basis` by `vademecum`'s first step's spatial modes at its load
    /// positions' nodes.
    pub fn new(basis: &ModalBasis, vademecum: &Vademecum) -> Self {
        let modes = vademecum.modes(0);
        let rows = 3 * vademecum.positions.len();
        let design = DMatrix::from_fn(rows, modes, |r, k| {
            let node = vademecum.positions[r / 3] as usize;
            vademecum.mode_at_node(0, k, node)[r % 3]
        });
        let targets = DMatrix::from_fn(rows, basis.len(), |r, j| {
            let node = vademecum.positions[r / 3] as usize;
            basis.mode(j)[3 * node + r % 3]
        });
        let svd = design.clone().svd(true, true);
        let cutoff = RANK_TOLERANCE * svd.singular_values.max();
        let solution = svd
            .solve(&targets, cutoff)
            .unwrap_or_else(|_| DMatrix::zeros(modes, basis.len()));
        let fitted = &design * &solution;
        let residual = (0..basis.len())
            .map(|j| {
                let norm = targets.column(j).norm();
                let miss = (targets.column(j) - fitted.column(j)).norm();
                if norm > 0.0 { miss / norm } else { 0.0 }
            })
            .collect();
        Self {
            // Column-major `modes × kept`: each kept mode's coefficients contiguous.
            coefficients: solution.as_slice().to_vec(),
            modes,
            residual,
        }
    }

    /// The vademecum's first step's modal coefficients of the kept modes moved by `q` (m),
    /// written into `out` (its length the step's mode count).
    pub fn coefficients_into(&self, q: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (row, &qj) in self.coefficients.chunks_exact(self.modes).zip(q) {
            for (o, &c) in out.iter_mut().zip(row) {
                *o += qj * c;
            }
        }
    }

    /// How many vademecum coefficients [`Self::coefficients_into`] writes.
    pub fn modes(&self) -> usize {
        self.modes
    }
}
