//! What the haptic tick reads of a cut organ while its cut state grows on another thread: a
//! consistent copy of the faces and of the enriched functions' responses at the surface.

use nalgebra::Matrix3;

use super::incision::CutFace;
use crate::mesh::NOT_ON_SURFACE;

/// A cut state as it stood after some segment: enough to soften the tool's patch compliance
/// for the cut, `C = C₀ + Yᵀ Y` with `Y = Ẑᵀ P` ([`super::CutState::felt_force_over`]).
#[derive(Clone, Debug, Default)]
pub struct CutView {
    /// The cut's faces so far.
    pub faces: Vec<CutFace>,
    /// The enriched unknowns so far.
    pub unknowns: usize,
    pub(super) surface_index_of: Vec<usize>,
    pub(super) z_hat_surface: Vec<Vec<(u32, f64)>>,
}

impl CutView {
    /// What the cut adds to the uncut compliance (m/N) of the patch `patch` (nodes and their
    /// shares of the tool's load): `Yᵀ Y`, zero with nothing cut. `y` is scratch space, kept
    /// from tick to tick so that nothing is allocated once it has grown.
    pub fn added_compliance(&self, patch: &[(usize, f64)], y: &mut [Vec<f64>; 3]) -> Matrix3<f64> {
        if self.unknowns == 0 {
            return Matrix3::zeros();
        }
        for (axis, y) in y.iter_mut().enumerate() {
            y.clear();
            y.resize(self.unknowns, 0.0);
            for &(node, share) in patch {
                let load = [(3 * node + axis, share)];
                add_surface_part(&self.surface_index_of, &self.z_hat_surface, &load, y);
            }
        }
        gram(y.as_slice())
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
