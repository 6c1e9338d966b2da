//! Proper generalized decomposition: computational vademecums `u(x, s) ≈ Σ X^k(x) Y^k(s)` for a
//! load at any accessible surface point in any direction, plus the local part a truncated sum
//! cannot carry (see `docs/pgd.md`). Plain Rust, no Bevy.

mod anderson;
mod baseline;
mod build;
pub mod container;
mod deformation;
mod enrichment;
mod error;
mod error_curve;
mod file;
mod load_patches;
mod local;
pub mod organ;
mod region;
mod responses;
mod separated;
mod settings;
mod shard;
mod snapshot_modes;
mod statistics;
mod stiffness;
mod surface_modes;
mod tool_patch;
mod vademecum;
mod validate;
pub mod web_form;

pub use baseline::{NewtonBaseline, newton_baseline};
pub use build::{BuildReport, OrganModel, StepReport, WIDE_NEAR_FIELD_SHARE, add_cuts, build};
pub use deformation::{Deformation, PatchLoad, PointLoad, RigidCarry};
pub use enrichment::{ModeReport, PgdSettings, enrich};
pub use error::VademecumError;
pub use error_curve::{EnergyError, ErrorCurve, optimal_errors};
pub use file::{FORMAT_VERSION, decode, encode, load, read_header, save};
pub use load_patches::{LoadOperator, LoadPatches};
pub use local::LocalPart;
pub use region::{
    CutHeader, RegionArrays, RegionReport, RegionResponse, RegionSettings, SparseDofs,
};
pub use responses::{Responses, ScaledLoads, SecantReport, SecantSettings, StepStart};
pub use separated::SeparatedField;
pub use settings::{
    BuildSettings, DEFAULT_LOAD_STEPS_M, NEO_HOOKEAN_STEPS_TOOL_RADII, default_load_steps_m,
};
pub use shard::{
    MergeError, PartFile, PartHeader, Shard, ShardPart, ShardStep, build_shard, load_part, merge,
    save_part,
};
pub use statistics::Statistics;
pub use stiffness::RestStiffness;
pub use surface_modes::SurfaceModes;
pub use vademecum::{
    Header, MAX_STEPS, Patch, RangePress, Step, StepLoads, SurfacePoint, Vademecum,
};
pub use validate::{
    ForceDepthCurve, Sample, ValidationReport, ValidationSettings, force_depth_curve_at, validate,
};

use crate::mesh::TetMesh;

/// Reports the progress of long offline work: a stage with a known amount of work, steps of
/// it, and free-form messages.
pub trait Progress: Sync {
    fn start(&self, stage: &str, total: u64);
    fn advance(&self, amount: u64);
    fn message(&self, text: &str);
}

/// Progress that goes nowhere (tests, library use).
pub struct Silent;

impl Progress for Silent {
    fn start(&self, _: &str, _: u64) {}
    fn advance(&self, _: u64) {}
    fn message(&self, _: &str) {}
}

/// A hash of the builder's own source: every module a build runs (`build.rs` lists them).
/// Vademecums built by code of another hash may differ from what this code builds, so the
/// tests' shared cache of vademecums is keyed by it. A file records its format version, not
/// this: the trainer does not rebuild its vademecums for every change of the code.
pub const BUILDER_SOURCE_HASH: &str = env!("BUILDER_SOURCE_HASH");

/// A hash of the mesh and its named regions (hex): a vademecum is valid only for the mesh it
/// was built on, down to the last bit of a coordinate.
pub fn mesh_hash(mesh: &TetMesh) -> String {
    let mut hasher = blake3::Hasher::new();
    for p in mesh.nodes() {
        for c in p.iter() {
            hasher.update(&c.to_le_bytes());
        }
    }
    for t in mesh.tets() {
        for &n in t {
            hasher.update(&(n as u64).to_le_bytes());
        }
    }
    let regions = mesh.regions();
    for (name, nodes) in &regions.node_sets {
        hasher.update(format!("node set {name} {}", nodes.len()).as_bytes());
        for &n in nodes {
            hasher.update(&(n as u64).to_le_bytes());
        }
    }
    for (name, faces) in &regions.face_sets {
        hasher.update(format!("face set {name} {}", faces.len()).as_bytes());
        for &n in faces.iter().flatten() {
            hasher.update(&(n as u64).to_le_bytes());
        }
    }
    hasher.finalize().to_hex().to_string()
}
