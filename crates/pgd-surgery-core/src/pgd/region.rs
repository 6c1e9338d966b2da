//! The uncut organ's response to a unit force at any node of a region, compressed: what a cut
//! vademecum stores so that a cut costs products, not solves.
//!
//! A cut's enriched functions load the organ through the nodes of the elements it crosses,
//! inside the organ as well as on its surface (`docs/cutting.md`). The response to a unit force
//! at node `b`, `G(·, b) = K⁻¹ e_b`, is kept as the tool's is: a separated sum
//! `Σ_k X^k Y^k(b)` found by PGD over the region's nodes, plus the exact remainder at the nodes
//! within a radius of `b` (its near field, where a point load's response is singular and a
//! truncated sum cannot follow it).

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::Progress;
use super::enrichment::{PgdSettings, enrich};
use super::load_patches::LoadPatches;
use super::local::near_nodes;
use super::separated::SeparatedField;
use super::statistics::Statistics;
use super::stiffness::RestStiffness;
use crate::fem::{FemError, PRESCRIBED};
use crate::mesh::TetMesh;
use crate::mesh::organs::{CORNEA_THICKNESS_M, Organ};

/// Where cuts may go and how finely their loads' responses are kept.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionSettings {
    /// Cuts reach this deep below the accessible faces (m).
    pub depth_m: f64,
    /// Each load's exact response is kept at the nodes this close to it (m).
    pub near_radius_m: f64,
    /// PGD modes of the far field.
    pub modes: usize,
    /// How far from a segment's enriched functions the cut state's patch solve reaches (m);
    /// `None` (files written before it was stored) leaves the cut state's default.
    #[serde(default)]
    pub patch_radius_m: Option<f64>,
}

impl RegionSettings {
    /// Cuts as deep as the organ's surgery takes them. The cornea: every node (1.5 times its
    /// thickness under the anterior face, so that the posterior face, which the intraocular
    /// pressure loads, is in; radial keratotomy cuts to 95 % of the thickness), a near field
    /// of 1 mm (two elements of the keratotomy mesh), patches of 3 mm (the cornea is a thin
    /// shell, whose bending carries an incision's effect several thicknesses away). The
    /// abdominal organs: 20 mm under the accessible faces, an 8 mm near field, patches of
    /// 20 mm (about three elements).
    pub fn for_organ(organ: Option<Organ>) -> Self {
        match organ {
            Some(Organ::Cornea) => Self {
                depth_m: 1.5 * CORNEA_THICKNESS_M,
                near_radius_m: 1e-3,
                modes: 40,
                patch_radius_m: Some(3e-3),
            },
            _ => Self {
                depth_m: 0.02,
                near_radius_m: 8e-3,
                modes: 40,
                patch_radius_m: Some(0.02),
            },
        }
    }
}

/// The header's account of a cut vademecum: where cuts may go, how finely their responses
/// are kept, and how the build went.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CutHeader {
    /// The face set cuts enter by.
    pub faces: String,
    pub settings: RegionSettings,
    pub report: RegionReport,
}

/// A sparse load or response over full dofs: `(dof, value)`.
pub type SparseDofs = Vec<(usize, f64)>;

/// A cut section's arrays, as its file holds them: the positions it serves, the nodes held
/// fixed, its modes, and each position's near field (its nodes `near_offsets[m]..
/// near_offsets[m + 1]` of `near_nodes`, a 3 × 3 block each in `near`).
pub struct RegionArrays {
    pub positions: Vec<u32>,
    pub held: Vec<u32>,
    pub spatial: Vec<f32>,
    pub parametric: Vec<f32>,
    pub near_offsets: Vec<u32>,
    pub near_nodes: Vec<u32>,
    pub near: Vec<f32>,
}

/// The compressed responses. Spatial modes are mode-major over all dofs; parametric modes
/// mode-major over three parameters per position; the near field per position in CSR rows of
/// 3 × 3 blocks (`block[3c + d]`: component `c` of the node under a unit force along `d`).
#[derive(Clone, Debug, PartialEq)]
pub struct RegionResponse {
    /// Volume node of each load position: the region's free nodes.
    pub positions: Vec<u32>,
    /// The nodes with every dof held: a load there moves nothing.
    pub held: Vec<u32>,
    pub spatial: Vec<f32>,
    pub parametric: Vec<f32>,
    pub near_offsets: Vec<u32>,
    pub near_nodes: Vec<u32>,
    pub near: Vec<f32>,
    /// The radius of the cut state's patch solves (m), from the settings it was built with.
    pub patch_radius_m: Option<f64>,
    /// Per volume node, its position, [`HELD`] where every dof is prescribed, or [`OUTSIDE`].
    slot: Vec<u32>,
}

/// What a region build did and how close the compressed responses come to the exact ones.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegionReport {
    pub positions: usize,
    pub modes: usize,
    /// Near-field blocks stored, per position on average.
    pub near_nodes_per_position: f64,
    pub pgd_seconds: f64,
    pub near_field_seconds: f64,
    /// Relative L2 error of the whole field, compressed against exact, over a sample of the
    /// unit loads (every direction of every `ERROR_SAMPLE_STRIDE`-th position).
    pub sampled_error: Statistics,
    pub total_seconds: f64,
}

/// One position in this many has its compressed response compared with the exact one.
const ERROR_SAMPLE_STRIDE: usize = 61;

/// The slot of a node outside the region.
const OUTSIDE: u32 = u32::MAX;
/// The slot of a held node: a load there moves nothing.
const HELD: u32 = u32::MAX - 1;

/// Positions solved together (three columns each).
const BLOCK_POSITIONS: usize = 16;

impl RegionResponse {
    /// The free nodes within `depth_m` of any node of `faces`, their lumped volumes (m³)
    /// as weights.
    pub fn region_nodes(
        stiffness: &RestStiffness,
        faces: &[[usize; 3]],
        depth_m: f64,
    ) -> LoadPatches {
        let mesh = stiffness.model.mesh();
        let mut on_faces: Vec<usize> = faces.iter().flatten().copied().collect();
        on_faces.sort_unstable();
        on_faces.dedup();
        let free = &stiffness.model.dofs().free_index;
        let positions: Vec<usize> = (0..mesh.node_count())
            .into_par_iter()
            .filter(|&n| (0..3).any(|c| free[3 * n + c] != PRESCRIBED))
            .filter(|&n| {
                let p = mesh.nodes()[n];
                on_faces
                    .iter()
                    .any(|&f| (mesh.nodes()[f] - p).norm() <= depth_m)
            })
            .collect();
        let volumes = lumped_volumes(mesh, stiffness);
        let weights = positions.iter().map(|&n| volumes[n]).collect();
        LoadPatches { positions, weights }
    }

    /// Builds the compressed responses to unit loads at `region`'s nodes.
    pub fn build(
        stiffness: &RestStiffness,
        region: &LoadPatches,
        settings: &RegionSettings,
        progress: &dyn Progress,
    ) -> Result<(Self, RegionReport), FemError> {
        let started = Instant::now();
        progress.start("cut modes", settings.modes as u64);
        let pgd = PgdSettings {
            max_modes: settings.modes,
            ..PgdSettings::default()
        };
        let (field, _) = enrich(
            stiffness,
            region,
            &region.parameter_weights(),
            &pgd,
            &mut |_, _| {
                progress.advance(1);
                true
            },
        )?;
        let pgd_seconds = started.elapsed().as_secs_f64();
        let clock = Instant::now();
        let mesh = stiffness.model.mesh();
        let near = near_nodes(mesh, &region.positions, settings.near_radius_m);
        progress.start("cut near field", region.positions.len() as u64);
        let blocks: Vec<(Vec<f32>, Vec<f64>)> = region
            .positions
            .par_chunks(BLOCK_POSITIONS)
            .enumerate()
            .map(|(b, chunk)| {
                let first = b * BLOCK_POSITIONS;
                let out = near_blocks(stiffness, &field, chunk, first, &near);
                progress.advance(chunk.len() as u64);
                out
            })
            .collect();
        let mut near_offsets = vec![0u32];
        for list in &near {
            near_offsets.push(near_offsets.last().expect("starts at 0") + list.len() as u32);
        }
        let mut errors = Vec::new();
        let mut near_values = Vec::new();
        for (values, sampled) in blocks {
            near_values.extend(values);
            errors.extend(sampled);
        }
        let arrays = RegionArrays {
            positions: region.positions.iter().map(|&n| n as u32).collect(),
            held: held_nodes(&stiffness.model.dofs().free_index),
            spatial: field.spatial.iter().flatten().map(|&v| v as f32).collect(),
            parametric: (field.parametric.iter().flatten())
                .map(|&v| v as f32)
                .collect(),
            near_offsets,
            near_nodes: near.concat(),
            near: near_values,
        };
        let response =
            Self::new(arrays, mesh.node_count()).with_patch_radius(settings.patch_radius_m);
        let report = RegionReport {
            positions: region.positions.len(),
            modes: field.modes(),
            near_nodes_per_position: response.near_nodes.len() as f64
                / region.positions.len().max(1) as f64,
            pgd_seconds,
            near_field_seconds: clock.elapsed().as_secs_f64(),
            sampled_error: Statistics::of(errors.into_iter()),
            total_seconds: started.elapsed().as_secs_f64(),
        };
        Ok((response, report))
    }

    /// Assembles a response from its arrays (as read from a file, checked there).
    pub fn new(arrays: RegionArrays, node_count: usize) -> Self {
        let RegionArrays {
            positions,
            held,
            spatial,
            parametric,
            near_offsets,
            near_nodes,
            near,
        } = arrays;
        let mut slot = vec![OUTSIDE; node_count];
        for &n in &held {
            slot[n as usize] = HELD;
        }
        for (m, &n) in positions.iter().enumerate() {
            slot[n as usize] = m as u32;
        }
        Self {
            positions,
            held,
            spatial,
            parametric,
            near_offsets,
            near_nodes,
            near,
            patch_radius_m: None,
            slot,
        }
    }

    /// The response with the radius its cut state's patch solves reach (m).
    pub fn with_patch_radius(self, patch_radius_m: Option<f64>) -> Self {
        Self {
            patch_radius_m,
            ..self
        }
    }

    pub fn node_count(&self) -> usize {
        self.slot.len()
    }

    pub fn modes(&self) -> usize {
        self.parametric.len() / (3 * self.positions.len()).max(1)
    }

    /// The position of volume node `node`, if the region holds it.
    pub fn position_of(&self, node: usize) -> Option<usize> {
        self.slot
            .get(node)
            .copied()
            .filter(|&m| m != OUTSIDE && m != HELD)
            .map(|m| m as usize)
    }

    /// Whether the region holds `node`, or holds it still (a load there moves nothing).
    pub fn covers(&self, node: usize) -> bool {
        self.slot.get(node).is_some_and(|&m| m != OUTSIDE)
    }

    /// `Yᵀ f`: the modal coefficients of the response to the sparse load `load` (loads on
    /// held nodes move nothing). `Err(node)` names a loaded node outside the region.
    pub fn modal_coefficients(&self, load: &[(usize, f64)]) -> Result<Vec<f64>, usize> {
        let parameters = 3 * self.positions.len();
        let mut out = vec![0.0; self.modes()];
        for &(dof, value) in load {
            if self.slot.get(dof / 3) == Some(&HELD) {
                continue;
            }
            let m = self.position_of(dof / 3).ok_or(dof / 3)?;
            let p = 3 * m + dof % 3;
            for (k, c) in out.iter_mut().enumerate() {
                *c += self.parametric[k * parameters + p] as f64 * value;
            }
        }
        Ok(out)
    }

    /// `Xᵀ v` for a sparse `v` over full dofs.
    pub fn spatial_products(&self, v: &[(usize, f64)]) -> Vec<f64> {
        let dofs = 3 * self.node_count();
        (0..self.modes())
            .map(|k| {
                let x = &self.spatial[k * dofs..(k + 1) * dofs];
                v.iter().map(|&(d, value)| x[d] as f64 * value).sum()
            })
            .collect()
    }

    /// `u += Σ_k c_k X^k` over all dofs.
    pub fn add_spatial(&self, coefficients: &[f64], u: &mut [f64]) {
        let dofs = 3 * self.node_count();
        for (k, &c) in coefficients.iter().enumerate() {
            let x = &self.spatial[k * dofs..(k + 1) * dofs];
            for (ui, &xi) in u.iter_mut().zip(x) {
                *ui += c * xi as f64;
            }
        }
    }

    /// The near-field part of the response to `load` (whose nodes the region holds),
    /// accumulated into `u` (full dofs).
    pub fn add_near(&self, load: &[(usize, f64)], u: &mut [f64]) {
        for &(dof, value) in load {
            let Some(m) = self.position_of(dof / 3) else {
                continue;
            };
            let d = dof % 3;
            let range = self.near_offsets[m] as usize..self.near_offsets[m + 1] as usize;
            for e in range {
                let node = self.near_nodes[e] as usize;
                let block = &self.near[9 * e..9 * e + 9];
                for c in 0..3 {
                    u[3 * node + c] += block[3 * c + d] as f64 * value;
                }
            }
        }
    }

    /// The near-field part of the response to `load`, as a sparse list of full dofs.
    pub fn near_response(&self, load: &[(usize, f64)], scratch: &mut Vec<f64>) -> SparseDofs {
        scratch.resize(3 * self.node_count(), 0.0);
        self.add_near(load, scratch);
        let mut out = Vec::new();
        for &(dof, _) in load {
            let Some(m) = self.position_of(dof / 3) else {
                continue;
            };
            for e in self.near_offsets[m] as usize..self.near_offsets[m + 1] as usize {
                let node = self.near_nodes[e] as usize;
                for (c, value) in scratch[3 * node..3 * node + 3].iter_mut().enumerate() {
                    if *value != 0.0 {
                        out.push((3 * node + c, std::mem::take(value)));
                    }
                }
            }
        }
        out
    }
}

/// The nodes whose every dof is prescribed.
fn held_nodes(free_index: &[usize]) -> Vec<u32> {
    (0..free_index.len() / 3)
        .filter(|&n| {
            free_index[3 * n..3 * n + 3]
                .iter()
                .all(|&f| f == PRESCRIBED)
        })
        .map(|n| n as u32)
        .collect()
}

/// Each node's share of the volume of its elements (m³).
fn lumped_volumes(mesh: &TetMesh, stiffness: &RestStiffness) -> Vec<f64> {
    let mut volumes = vec![0.0; mesh.node_count()];
    for (tet, geometry) in mesh.tets().iter().zip(stiffness.model.geometry()) {
        for &n in tet {
            volumes[n] += geometry.volume_m3 / 4.0;
        }
    }
    volumes
}

/// The exact responses to the unit loads at `chunk` (positions `first..`), reduced to their
/// near-field remainders after the separated sum; and, for the sampled positions, the
/// relative L2 error of the whole compressed field.
fn near_blocks(
    stiffness: &RestStiffness,
    field: &SeparatedField,
    chunk: &[usize],
    first: usize,
    near: &[Vec<u32>],
) -> (Vec<f32>, Vec<f64>) {
    let rows = stiffness.free_count();
    let free_index = &stiffness.model.dofs().free_index;
    let mut block = vec![0.0; rows * 3 * chunk.len()];
    for (j, &node) in chunk.iter().enumerate() {
        for d in 0..3 {
            let f = free_index[3 * node + d];
            if f != PRESCRIBED {
                block[(3 * j + d) * rows + f] = 1.0;
            }
        }
    }
    stiffness.solve_block(&mut block);
    let exact = |column: usize, dof: usize| match free_index[dof] {
        PRESCRIBED => 0.0,
        f => block[column * rows + f],
    };
    let mut values = Vec::new();
    let mut errors = Vec::new();
    for j in 0..chunk.len() {
        let m = first + j;
        let modal = |dof: usize, d: usize| -> f64 {
            field
                .spatial
                .iter()
                .zip(&field.parametric)
                .map(|(x, y)| x[dof] * y[3 * m + d])
                .sum()
        };
        for &node in &near[m] {
            let node = node as usize;
            for c in 0..3 {
                for d in 0..3 {
                    let dof = 3 * node + c;
                    values.push((exact(3 * j + d, dof) - modal(dof, d)) as f32);
                }
            }
        }
        if m.is_multiple_of(ERROR_SAMPLE_STRIDE) {
            let kept: std::collections::HashSet<u32> = near[m].iter().copied().collect();
            for d in 0..3 {
                let (mut diff, mut norm) = (0.0, 0.0);
                for dof in 0..3 * stiffness.model.mesh().node_count() {
                    let u = exact(3 * j + d, dof);
                    // The near field is exact up to f32 rounding; elsewhere the sum answers.
                    let approx = if kept.contains(&((dof / 3) as u32)) {
                        u
                    } else {
                        modal(dof, d)
                    };
                    diff += (u - approx).powi(2);
                    norm += u * u;
                }
                errors.push((diff / norm.max(f64::MIN_POSITIVE)).sqrt());
            }
        }
    }
    (values, errors)
}
