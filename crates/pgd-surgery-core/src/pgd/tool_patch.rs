//! The tool's contact patch over the load positions: the shares of a patch centred anywhere,
//! computed one way for the trainer and for the build, and the patch centred on each position,
//! which is what a nonlinear load step loads.
//!
//! A nodal load pressed deep strains the elements around its node far more than the tool's
//! patch does at the same depth, and nonlinear responses do not superpose: so a nonlinear step
//! answers the tool's own patch, centred on each position, at the tool's own depth.

use nalgebra::Vector3;

use super::load_patches::UnitLoads;
use crate::fem::{on_pressed_side, patch_weight};

/// Where the load positions are, how much surface each carries and which way it faces.
#[derive(Clone, Copy)]
pub struct PatchGeometry<'a> {
    pub coords_m: &'a [[f32; 3]],
    pub areas_m2: &'a [f32],
    pub normals: &'a [[f32; 3]],
    pub radius_m: f64,
}

impl<'a> PatchGeometry<'a> {
    /// The unnormalized shares of the patch centred at `centre` among `candidates`: the
    /// positions within the tool's radius on the side `facing` (a thin wall's far side is not
    /// pressed).
    pub fn weights(
        self,
        centre: Vector3<f64>,
        facing: Vector3<f64>,
        candidates: impl Iterator<Item = usize> + 'a,
    ) -> impl Iterator<Item = (usize, f64)> + 'a {
        candidates.filter_map(move |m| {
            let normal = Vector3::from(self.normals[m].map(f64::from));
            if !on_pressed_side(&normal, &facing) {
                return None;
            }
            let p = Vector3::from(self.coords_m[m].map(f64::from));
            let w = patch_weight(self.areas_m2[m] as f64, (p - centre).norm(), self.radius_m);
            (w > 0.0).then_some((m, w))
        })
    }

    /// The shares (summing to one) of the patch centred on position `m`, facing its normal,
    /// among its `neighbours`.
    pub fn centred_on(&self, m: usize, neighbours: &[u32]) -> Vec<(usize, f64)> {
        let centre = Vector3::from(self.coords_m[m].map(f64::from));
        let facing = Vector3::from(self.normals[m].map(f64::from));
        let candidates = neighbours.iter().map(|&j| j as usize);
        let mut shares: Vec<(usize, f64)> = self.weights(centre, facing, candidates).collect();
        let total: f64 = shares.iter().map(|s| s.1).sum();
        if total > 0.0 {
            shares.iter_mut().for_each(|s| s.1 /= total);
            shares
        } else {
            vec![(m, 1.0)]
        }
    }
}

/// The loads of a nonlinear step: load `m` is a unit force spread over the tool's patch centred
/// on position `m`, pushing into the organ along its inward normal. A nonlinear law answers a
/// push and a pull differently, and the tool, frictionless, presses along the surface's
/// normal: the step answers that press, and a force's other components are answered linearly.
pub struct ToolPatchLoads {
    /// The volume node of each position.
    pub positions: Vec<usize>,
    /// Per position, its patch's shares over positions.
    pub shares: Vec<Vec<(usize, f64)>>,
    /// Per position, its inward unit normal.
    pub inward: Vec<Vector3<f64>>,
}

impl ToolPatchLoads {
    /// The patch centred on every position of `geometry`, among each one's `neighbours`.
    pub fn new(positions: Vec<usize>, geometry: &PatchGeometry, neighbours: &[Vec<u32>]) -> Self {
        let shares = (0..positions.len())
            .map(|m| geometry.centred_on(m, &neighbours[m]))
            .collect();
        let inward = geometry.normals.iter().map(inward_normal).collect();
        Self {
            positions,
            shares,
            inward,
        }
    }
}

impl UnitLoads for ToolPatchLoads {
    fn nodal_shares(&self, m: usize) -> impl Iterator<Item = (usize, f64)> {
        self.shares[m]
            .iter()
            .map(|&(j, share)| (self.positions[j], share))
    }

    fn direction(&self, m: usize) -> Vector3<f64> {
        self.inward[m]
    }
}

/// The inward unit normal of a position whose outward normal is `outward`: the direction a
/// nonlinear step pushes it along.
pub(super) fn inward_normal(outward: &[f32; 3]) -> Vector3<f64> {
    -Vector3::from(outward.map(f64::from)).normalize()
}
