//! The vademecum's local part: what a few dozen global modes cannot carry.
//!
//! A separated sum truncated to n modes is far too stiff under the tool (the response to a
//! point load is not low-rank), so each load position also stores, from its exact response:
//! - its **compliance blocks** `C_mj` (3 × 3: its displacement under a unit load at `j`) with
//!   every position close enough to share a tool patch: the displacement under the tool for
//!   a patch `β` at any point is `Σ_mj β_m β_j C_mj`, exact, so the felt force needs no mode;
//! - its **near-field correction**: the exact response minus the separated sum, at every node
//!   within the local radius, so the dimple under the tool has the exact shape.

use nalgebra::{RealField, Vector3};
use rayon::prelude::*;

use super::load_patches::LoadPatches;
use super::responses::Responses;
use super::stiffness::RestStiffness;
use crate::mesh::TetMesh;

/// Compressed rows per position: `offsets[m]..offsets[m + 1]` index the entries of position `m`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalPart {
    pub neighbour_offsets: Vec<u32>,
    /// Position indices, the position itself included.
    pub neighbours: Vec<u32>,
    /// Nine values per neighbour entry: `[c * 3 + d]` is displacement component `c` (m) of
    /// position m's patch under a unit load (N) in direction `d` at the neighbour.
    pub compliance: Vec<f32>,
    pub correction_offsets: Vec<u32>,
    pub correction_nodes: Vec<u32>,
    /// Nine values per node entry: `[d * 3 + c]` is the residual displacement component `c` of
    /// the node under a unit load in direction `d` at the position.
    pub correction: Vec<f32>,
}

/// Responses by load parameter `3m + d` (a unit force along axis `d` at position `m`), free dof
/// by free dof: what the local part is cut from.
pub trait ParameterResponses {
    fn entry(&self, p: usize, free: usize) -> f64;
}

impl ParameterResponses for &Responses {
    fn entry(&self, p: usize, free: usize) -> f64 {
        self.columns[p * self.rows + free]
    }
}

/// Responses kept once per position, to a unit force along that position's own direction: a
/// unit force along axis `d` is answered by its component along the direction, `w_d`, times
/// that response (a nonlinear step's corrections, which answer the inward push alone).
pub struct AlongDirections<'a> {
    pub responses: &'a Responses,
    pub directions: &'a [Vector3<f64>],
}

impl ParameterResponses for AlongDirections<'_> {
    fn entry(&self, p: usize, free: usize) -> f64 {
        let m = p / 3;
        self.directions[m][p % 3] * self.responses.columns[m * self.responses.rows + free]
    }
}

/// Per position, the positions within `radius_m` of it (itself first): every pair two
/// patches can couple.
pub fn distance_neighbours(coords: &[[f32; 3]], radius_m: f64) -> Vec<Vec<u32>> {
    let r2 = (radius_m * radius_m) as f32;
    (0..coords.len())
        .into_par_iter()
        .map(|m| {
            let a = coords[m];
            let mut list = vec![m as u32];
            list.extend(
                (0..coords.len())
                    .filter(|&j| {
                        j != m && (0..3).map(|c| (coords[j][c] - a[c]).powi(2)).sum::<f32>() <= r2
                    })
                    .map(|j| j as u32),
            );
            list
        })
        .collect()
}

impl LocalPart {
    /// The compliance blocks, from the exact responses.
    pub fn with_compliances(
        stiffness: &RestStiffness,
        patches: &LoadPatches,
        responses: &dyn ParameterResponses,
        neighbours: &[Vec<u32>],
    ) -> Self {
        let mut part = Self::default();
        part.neighbour_offsets.push(0);
        for (m, list) in neighbours.iter().enumerate() {
            for &j in list {
                part.neighbours.push(j);
                part.compliance.extend(compliance_block(
                    stiffness, patches, responses, m, j as usize,
                ));
            }
            part.neighbour_offsets.push(part.neighbours.len() as u32);
        }
        part
    }

    /// Stores the residual of the separated sum at each position's near-field nodes.
    pub fn set_corrections(
        &mut self,
        stiffness: &RestStiffness,
        residual: &dyn ParameterResponses,
        near: &[Vec<u32>],
    ) {
        let free_index = &stiffness.model.dofs().free_index;
        self.correction_offsets = vec![0];
        self.correction_nodes.clear();
        self.correction.clear();
        for (m, nodes) in near.iter().enumerate() {
            for &node in nodes {
                for d in 0..3 {
                    for c in 0..3 {
                        let value = match free_index[3 * node as usize + c] {
                            crate::fem::PRESCRIBED => 0.0,
                            free => residual.entry(3 * m + d, free),
                        };
                        self.correction.push(value as f32);
                    }
                }
            }
            self.correction_nodes.extend(nodes);
            self.correction_offsets
                .push(self.correction_nodes.len() as u32);
        }
    }

    pub fn neighbours_of(&self, m: usize) -> std::ops::Range<usize> {
        self.neighbour_offsets[m] as usize..self.neighbour_offsets[m + 1] as usize
    }

    /// Correction entry `e` under a load `force` on its position: that node's residual
    /// displacement (m), in the force's precision (f64 for the whole field, f32 where the
    /// contact sums many entries each tick).
    pub fn residual<T: RealField + Copy>(&self, e: usize, force: &Vector3<T>) -> Vector3<T> {
        let values = &self.correction[9 * e..9 * e + 9];
        let value = |i: usize| nalgebra::convert::<f64, T>(values[i] as f64);
        Vector3::from_fn(|c, _| {
            value(c) * force[0] + value(3 + c) * force[1] + value(6 + c) * force[2]
        })
    }

    /// Adds correction entry `e` under a load `force` on its position to `sum` (m): lanes 0–2
    /// take the residual displacement, lane 3 is scratch. Each column is read four values at
    /// a time so that the sum compiles to vector multiplies and adds: the contact sums tens of
    /// thousands of entries a tick. Equal to [`Self::residual`] up to f32 rounding. Inlined
    /// across modules: called out of line, once per entry, it took the gallbladder press's
    /// tick from 34 to 50 µs.
    #[inline]
    pub fn add_residual(&self, e: usize, force: &[f32; 3], sum: &mut [f32; 4]) {
        let column = |d: usize| -> Option<&[f32; 4]> {
            self.correction
                .get(9 * e + 3 * d..9 * e + 3 * d + 4)?
                .try_into()
                .ok()
        };
        match (column(0), column(1), column(2)) {
            (Some(x), Some(y), Some(z)) => {
                for c in 0..4 {
                    sum[c] += x[c] * force[0] + y[c] * force[1] + z[c] * force[2];
                }
            }
            // The last entry, whose third column ends the array.
            _ => {
                let u = self.residual(e, &Vector3::from(*force));
                for c in 0..3 {
                    sum[c] += u[c];
                }
            }
        }
    }

    pub fn corrections_of(&self, m: usize) -> std::ops::Range<usize> {
        self.correction_offsets[m] as usize..self.correction_offsets[m + 1] as usize
    }
}

/// Per position, the nodes within `radius_m` of it: where its exact response is kept.
pub fn near_nodes(mesh: &TetMesh, positions: &[usize], radius_m: f64) -> Vec<Vec<u32>> {
    positions
        .par_iter()
        .map(|&p| {
            let centre = mesh.nodes()[p];
            (0..mesh.node_count())
                .filter(|&n| (mesh.nodes()[n] - centre).norm() <= radius_m)
                .map(|n| n as u32)
                .collect()
        })
        .collect()
}

/// `C_mj[c][d] = u_(j,d)[node m, c]`: displacement of position m under a unit load at j.
fn compliance_block(
    stiffness: &RestStiffness,
    patches: &LoadPatches,
    responses: &dyn ParameterResponses,
    m: usize,
    j: usize,
) -> [f32; 9] {
    let free_index = &stiffness.model.dofs().free_index;
    let node = patches.positions[m];
    let mut block = [0.0f32; 9];
    for d in 0..3 {
        for c in 0..3 {
            block[c * 3 + d] = match free_index[3 * node + c] {
                crate::fem::PRESCRIBED => 0.0,
                free => responses.entry(3 * j + d, free) as f32,
            };
        }
    }
    block
}
