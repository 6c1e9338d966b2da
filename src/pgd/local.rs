//! The vademecum's local part: what a few dozen global modes cannot carry.
//!
//! A separated sum truncated to n modes is far too stiff under the tool (the response to a
//! point load is not low-rank), so each load position also stores, from its exact response:
//! - its **compliance blocks** `C_mj = B_mᵀ u_j` (3 × 3) with itself and with every position
//!   sharing an accessible triangle: the patch-averaged displacement under the tool, exact for
//!   any load interpolated over a triangle, so the felt force needs no mode at all;
//! - its **near-field correction**: the exact response minus the separated sum, at every node
//!   within the local radius, so the dimple under the tool has the exact shape.

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

/// Per position, the positions it shares an accessible triangle with (itself first).
pub fn triangle_neighbours(positions: usize, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut neighbours: Vec<Vec<u32>> = (0..positions as u32).map(|m| vec![m]).collect();
    for t in triangles {
        for &a in t {
            for &b in t {
                if !neighbours[a as usize].contains(&b) {
                    neighbours[a as usize].push(b);
                }
            }
        }
    }
    neighbours
}

impl LocalPart {
    /// The compliance blocks, from the exact responses (one column per parameter).
    pub fn with_compliances(
        stiffness: &RestStiffness,
        patches: &LoadPatches,
        responses: &Responses,
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

    /// Stores the residual of the separated sum (`residual`, one column per parameter) at each
    /// position's near-field nodes.
    pub fn set_corrections(
        &mut self,
        stiffness: &RestStiffness,
        residual: &Responses,
        near: &[Vec<u32>],
    ) {
        let free_index = &stiffness.model.dofs().free_index;
        self.correction_offsets = vec![0];
        self.correction_nodes.clear();
        self.correction.clear();
        for (m, nodes) in near.iter().enumerate() {
            for &node in nodes {
                for d in 0..3 {
                    let r = residual.column(3 * m + d);
                    for c in 0..3 {
                        let value = match free_index[3 * node as usize + c] {
                            crate::fem::PRESCRIBED => 0.0,
                            free => r[free],
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

/// `C_mj[c][d] = Σ_patch(m) share · u_(j,d)[node, c]`.
fn compliance_block(
    stiffness: &RestStiffness,
    patches: &LoadPatches,
    responses: &Responses,
    m: usize,
    j: usize,
) -> [f32; 9] {
    let free_index = &stiffness.model.dofs().free_index;
    let mut block = [0.0f32; 9];
    for d in 0..3 {
        let u = responses.column(3 * j + d);
        for c in 0..3 {
            let value: f64 = patches.patches[m]
                .iter()
                .filter_map(|&(node, share)| {
                    let free = free_index[3 * node + c];
                    (free != crate::fem::PRESCRIBED).then(|| share * u[free])
                })
                .sum();
            block[c * 3 + d] = value as f32;
        }
    }
    block
}
