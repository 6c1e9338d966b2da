//! A deterministic generator of anatomically plausible organ meshes, in metres.
//!
//! Frame (RAS, right-handed): +x towards the patient's right, +y anterior (up, towards the
//! surgeon for a supine patient; Bevy's up), +z superior (towards the head).
//!
//! Solid organs (liver, pancreas, duodenum) are implicit shapes meshed by isosurface stuffing;
//! thin-walled ones (gallbladder, cornea) are extruded shells. Organs are built in a fixed order
//! and each later organ yields to the earlier ones — its shape minus theirs grown by a small gap —
//! so neighbours touch along a shared interface without overlapping, and that interface is
//! where attachments are tagged. The same organ comes out bit for bit on every platform (its
//! trigonometry and roots are `libm`'s, not the C library's): the web page regenerates it and
//! must match the mesh hash of the vademecum built for it natively.

mod abdomen;
mod shapes;

use serde::{Deserialize, Serialize};

use super::{MeshError, TetMesh};
pub use abdomen::{
    Abdomen, CORNEA_CURVATURE_M, CORNEA_RIM_M, CORNEA_THICKNESS_M, GALLBLADDER_WALL_M, GAP_M,
};

/// Region names stored with generated meshes.
pub mod region {
    /// Nodes held fixed (Dirichlet).
    pub const CLAMPED: &str = "clamped";
    /// Faces where a tool may press.
    pub const ACCESSIBLE: &str = "accessible";
    /// Faces loaded by an inner pressure (the gallbladder's bile).
    pub const PRESSURIZED: &str = "pressurized";
    /// Prefix of the node sets at an attachment: `attached_duodenum` on the pancreas, etc.
    pub const ATTACHED_PREFIX: &str = "attached_";
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Organ {
    Liver,
    Gallbladder,
    Pancreas,
    Duodenum,
    Cornea,
}

impl Organ {
    pub const ALL: [Organ; 5] = [
        Organ::Liver,
        Organ::Gallbladder,
        Organ::Pancreas,
        Organ::Duodenum,
        Organ::Cornea,
    ];

    /// The organs of the abdominal scene, which share one frame (the cornea stands alone).
    pub const ABDOMEN: [Organ; 4] = [
        Organ::Liver,
        Organ::Gallbladder,
        Organ::Pancreas,
        Organ::Duodenum,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Organ::Liver => "liver",
            Organ::Gallbladder => "gallbladder",
            Organ::Pancreas => "pancreas",
            Organ::Duodenum => "duodenum",
            Organ::Cornea => "cornea",
        }
    }

    pub fn from_name(name: &str) -> Option<Organ> {
        Organ::ALL.into_iter().find(|o| o.name() == name)
    }

    /// The direction (a unit vector of the organ's frame) the surgeon looks at it from:
    /// anterior (+y) for the abdominal organs, which share the patient's frame; along the
    /// cornea's axis (+z) for the cornea, which stands in a frame of its own.
    pub fn facing(self) -> [f64; 3] {
        match self {
            Organ::Cornea => [0.0, 0.0, 1.0],
            _ => [0.0, 1.0, 0.0],
        }
    }

    /// Target node count at resolution 1: the papers' sizes where they give them.
    pub fn default_nodes(self) -> usize {
        match self {
            Organ::Liver => 4_300,
            Organ::Gallbladder => 4_200,
            Organ::Pancreas => 2_500,
            Organ::Duodenum => 2_500,
            Organ::Cornea => 8_500,
        }
    }
}

/// Knobs of the generator.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrganSettings {
    /// Multiplies every organ's node count (1 = the papers' sizes).
    pub resolution: f64,
    /// Varies proportions by a few percent, deterministically: a different patient.
    pub seed: u64,
    /// Elements through the cornea's thickness: a cut's depth is resolved to one of them.
    #[serde(default = "default_cornea_layers")]
    pub cornea_layers: usize,
}

/// The cornea's elements through its thickness by default: enough for pressing.
pub const CORNEA_LAYERS: usize = 2;

fn default_cornea_layers() -> usize {
    CORNEA_LAYERS
}

impl Default for OrganSettings {
    fn default() -> Self {
        Self {
            resolution: 1.0,
            seed: 1,
            cornea_layers: CORNEA_LAYERS,
        }
    }
}

/// Generates one organ with its regions. The abdominal organs' shapes depend on each other,
/// so the whole layout is set up and the organ asked for is meshed.
pub fn generate(organ: Organ, settings: &OrganSettings) -> Result<TetMesh, MeshError> {
    Abdomen::new(settings).mesh(organ, settings)
}
