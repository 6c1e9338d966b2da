//! What the haptic tick and the window read of a cut organ while its cut state grows on
//! another thread: a consistent copy of the faces, the enriched functions, their responses
//! at the surface and the condensed system's factor.

use nalgebra::{Matrix3, Vector3};

use super::enrichment::Enriched;
use super::factor::GrowingCholesky;
use super::incision::CutFace;
use crate::mesh::NOT_ON_SURFACE;

/// A cut state as it stood after some segment: enough to soften the tool's patch compliance
/// for the cut, `C = C₀ + Yᵀ Y` with `Y = Ẑᵀ P` ([`super::CutState::felt_force_over`]), and
/// to draw the cut organ under a load on its surface: the nodes' displacement beyond the
/// uncut one, `−Ẑ y` with `y = −Ẑᵀ f`, and the lips' opening, the enriched amplitudes
/// `q = L⁻ᵀ y` (`docs/cutting.md`).
#[derive(Clone, Debug, Default)]
pub struct CutView {
    /// The cut's faces so far.
    pub faces: Vec<CutFace>,
    /// The enriched unknowns so far.
    pub unknowns: usize,
    /// The enriched functions, in the unknowns' order (function `j`: unknowns `3j..3j+3`).
    pub functions: Vec<Enriched>,
    pub(super) surface_index_of: Vec<usize>,
    pub(super) z_hat_surface: Vec<Vec<(u32, f64)>>,
    /// The lower Cholesky factor of the condensed system.
    pub(super) factor: GrowingCholesky,
}

/// The cut's part of an organ's answer to a load on its surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CutAnswer {
    /// `y = −Ẑᵀ f`.
    y: Vec<f64>,
    /// The enriched amplitudes `q = L⁻ᵀ y` (m).
    q: Vec<f64>,
}

impl CutView {
    /// The cut's answer to the nodal forces `load` (`(dof, N)`; dofs of nodes inside add
    /// nothing).
    pub fn answer(&self, load: &[(usize, f64)]) -> CutAnswer {
        let mut y = vec![0.0; self.unknowns];
        add_surface_part(&self.surface_index_of, &self.z_hat_surface, load, &mut y);
        y.iter_mut().for_each(|v| *v = -*v);
        let mut q = y.clone();
        self.factor.backward(&mut q);
        CutAnswer { y, q }
    }

    /// What the cut adds (m) to the uncut displacement of surface node `node` under the load
    /// `answer` was made for, on the node's own side; zero for a node inside.
    pub fn added_displacement(&self, node: usize, answer: &CutAnswer) -> Vector3<f64> {
        Vector3::from_fn(|axis, _| {
            surface_dof(&self.surface_index_of, 3 * node + axis).map_or(0.0, |k| {
                let entries = &self.z_hat_surface[k];
                -entries
                    .iter()
                    .map(|&(p, v)| answer.y[p as usize] * v)
                    .sum::<f64>()
            })
        })
    }

    /// How far (m) function `j`'s node is from itself seen from the other side of its face:
    /// `(H_other − H_node) q_j = −2 H_node q_j`, the lips' opening there.
    pub fn opening(&self, j: usize, answer: &CutAnswer) -> Vector3<f64> {
        let side = f64::from(self.functions[j].node_side);
        Vector3::from_column_slice(&answer.q[3 * j..3 * j + 3]) * (-2.0 * side)
    }

    /// What the cut adds to the uncut compliance (m/N) of the patch `patch` (nodes and their
    /// shares of the tool's load): `Yᵀ Y`, zero with nothing cut. `scratch` is kept from tick
    /// to tick so that nothing is allocated once it has grown.
    pub fn added_compliance(
        &self,
        patch: &[(usize, f64)],
        scratch: &mut CutScratch,
    ) -> Matrix3<f64> {
        if self.unknowns == 0 {
            return Matrix3::zeros();
        }
        self.patch_rows(patch, &mut scratch.rows);
        gram(scratch.rows.as_slice())
    }

    /// Starts summing the cut's part of the organ's loads in `scratch`: none yet.
    pub fn clear_loads(&self, scratch: &mut CutScratch) {
        scratch.loads.clear();
        scratch.loads.resize(self.unknowns, 0.0);
    }

    /// Adds the cut's part of `force_n` (N) spread over the patch `patch` to the loads summed
    /// in `scratch`: `w += Ẑᵀ P f` (nothing with nothing cut).
    pub fn add_load(
        &self,
        patch: &[(usize, f64)],
        force_n: &Vector3<f64>,
        scratch: &mut CutScratch,
    ) {
        if self.unknowns == 0 {
            return;
        }
        for &(node, share) in patch {
            for axis in 0..3 {
                let load = [(3 * node + axis, share * force_n[axis])];
                add_surface_part(
                    &self.surface_index_of,
                    &self.z_hat_surface,
                    &load,
                    &mut scratch.loads,
                );
            }
        }
    }

    /// What the cut adds at the patch `patch`: to its compliance (`Yᵀ Y`), and to its
    /// displacement under the loads summed in `scratch` (`Yᵀ w`, its own load's part among
    /// them if it was added). Both zero with nothing cut.
    pub fn patch_response(&self, patch: &[(usize, f64)], scratch: &mut CutScratch) -> PatchCut {
        if self.unknowns == 0 {
            return PatchCut::default();
        }
        self.patch_rows(patch, &mut scratch.rows);
        let rows = &scratch.rows;
        let moved = |axis: usize| {
            rows[axis]
                .iter()
                .zip(&scratch.loads)
                .map(|(y, w)| y * w)
                .sum()
        };
        PatchCut {
            added_m_per_n: gram(rows.as_slice()),
            moved_m: Vector3::from_fn(|axis, _| moved(axis)),
        }
    }

    /// `Y = Ẑᵀ P` for the patch `patch`, a row per axis, into `rows`.
    fn patch_rows(&self, patch: &[(usize, f64)], rows: &mut [Vec<f64>; 3]) {
        for (axis, y) in rows.iter_mut().enumerate() {
            y.clear();
            y.resize(self.unknowns, 0.0);
            for &(node, share) in patch {
                let load = [(3 * node + axis, share)];
                add_surface_part(&self.surface_index_of, &self.z_hat_surface, &load, y);
            }
        }
    }
}

/// What a cut adds at a tool's patch ([`CutView::patch_response`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PatchCut {
    /// To the patch's compliance (m/N).
    pub added_m_per_n: Matrix3<f64>,
    /// To the patch's displacement under the organ's loads (m).
    pub moved_m: Vector3<f64>,
}

/// Scratch space for a view's answers at a patch: `Y`'s three rows, and the cut's part of the
/// organ's loads, `w`. Made with room for every unknown of a view, the haptic tick never grows
/// it.
#[derive(Clone, Debug, Default)]
pub struct CutScratch {
    rows: [Vec<f64>; 3],
    loads: Vec<f64>,
}

impl CutScratch {
    /// Room for `unknowns` enriched unknowns.
    pub fn with_room(unknowns: usize) -> Self {
        Self {
            rows: std::array::from_fn(|_| Vec::with_capacity(unknowns)),
            loads: Vec::with_capacity(unknowns),
        }
    }
}

/// `y += Ẑᵀ p` over the surface dofs of the sparse load `p` (`Ẑ` kept per surface dof as
/// `(unknown, value)`; a dof of a node inside adds nothing).
pub(super) fn add_surface_part(
    surface_index_of: &[usize],
    z_hat_surface: &[Vec<(u32, f64)>],
    load: &[(usize, f64)],
    y: &mut [f64],
) {
    for &(d, share) in load {
        let Some(k) = surface_dof(surface_index_of, d) else {
            continue;
        };
        for &(p, v) in &z_hat_surface[k] {
            y[p as usize] += share * v;
        }
    }
}

/// `Yᵀ Y` for the three rows `y` (one per axis).
pub(super) fn gram(y: &[Vec<f64>]) -> Matrix3<f64> {
    Matrix3::from_fn(|row, axis| y[row].iter().zip(&y[axis]).map(|(a, b)| a * b).sum())
}

/// The place of dof `d` among the surface nodes' dofs, if its node is on the surface.
pub(super) fn surface_dof(surface_index_of: &[usize], d: usize) -> Option<usize> {
    match surface_index_of[d / 3] {
        NOT_ON_SURFACE => None,
        k => Some(3 * k + d % 3),
    }
}
