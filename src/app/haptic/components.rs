//! What an organ entity of the haptic world holds: its vademecum and contact surface (shared
//! through `Arc`, never copied), each hand's tool's contact with it, and its deformation
//! state.

use std::sync::Arc;

use bevy::prelude::*;

use crate::contact::{ContactSurface, ToolContact};
use crate::devices::TICK_S;
use crate::dynamics::{DynamicModel, GraspSettings, GraspedOrgan};
use nalgebra::Vector3;

use crate::pgd::{Deformation, Patch, PatchLoad, SurfacePoint, Vademecum};

/// An organ's mechanical model (the vademecum, which carries the regions it was built with in
/// its header) and collision model (its accessible surface).
#[derive(Component, Clone)]
pub struct OrganBody {
    pub name: String,
    pub vademecum: Arc<Vademecum>,
    pub surface: Arc<ContactSurface>,
}

/// An organ's name with the tissue law its vademecum answers, as the reports and the HUD
/// write it ("liver (exponential)").
pub fn organ_with_law(name: &str, vademecum: &Vademecum) -> String {
    format!("{name} ({})", vademecum.header.material.law.name())
}

/// The organ's place in the scene's list: the order of [`super::HapticSnapshot::organs`].
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct OrganIndex(pub usize);

/// A hand's tool's contact with the organ this tick, if it touches, the patch under it and
/// the tool's next load (scratch space kept from tick to tick: the press reads the organ's
/// loads, the last tick's tool load included, while it writes the next one).
#[derive(Clone, Debug, Default)]
pub struct ToolTouch {
    pub contact: Option<ToolContact>,
    pub patch: Patch,
    pub next_load: PatchLoad,
}

impl ToolTouch {
    /// No contact, its buffers with room for the largest patch on `vademecum`.
    pub fn reserved(vademecum: &Vademecum) -> Self {
        Self {
            contact: None,
            patch: Patch::reserved(vademecum),
            next_load: PatchLoad::reserved(vademecum.positions.len()),
        }
    }
}

/// Each hand's touch of the organ, by hand index ([`super::HandIndex`]).
#[derive(Component, Clone, Debug, Default)]
pub struct HandTouches(pub Vec<ToolTouch>);

impl HandTouches {
    /// `hands` hands' touches, none touching, each with room for the largest patch (each
    /// reserved anew: a clone would keep the lengths and lose the room).
    pub fn reserved(vademecum: &Vademecum, hands: usize) -> Self {
        Self((0..hands).map(|_| ToolTouch::reserved(vademecum)).collect())
    }

    /// Whether any hand's tool touches the organ.
    pub fn any(&self) -> bool {
        self.pressing().is_some()
    }

    /// The first hand whose tool touches the organ.
    pub fn pressing(&self) -> Option<usize> {
        self.0.iter().position(|t| t.contact.is_some())
    }
}

/// A patch's `shares` by mesh node rather than by load position, into `nodes` (emptied
/// first; its room kept, so that a buffer made for every position never grows).
pub fn patch_nodes(shares: &[(usize, f64)], vademecum: &Vademecum, nodes: &mut Vec<(usize, f64)>) {
    nodes.clear();
    let shares = shares.iter();
    nodes.extend(shares.map(|&(position, share)| (vademecum.positions[position] as usize, share)));
}

/// The loads on the organ and their modal coefficients. Load slot `h` is hand `h`'s tool's
/// ([`super::HandIndex`]): the hands' loads superpose through the vademecum.
#[derive(Component, Clone, Debug)]
pub struct OrganDeformation(pub Deformation);

/// An organ that moves: its dynamic model (shared with the window, which draws its modes),
/// its state with the grasper's jaws on it, and the kept modes' correction to the static
/// field of the jaws' load this tick (what the snapshot hands the window), and that correction
/// in the vademecum's modes (what organ contact and attachments read).
#[derive(Component)]
pub struct OrganMotion {
    pub model: Arc<DynamicModel>,
    pub organ: GraspedOrgan,
    pub correction: Vec<f64>,
    pub in_vademecum_modes: Vec<f64>,
    /// The jaws' patch on the surface while they hold (load positions), and its mesh nodes;
    /// both with room for every load position.
    pub shares: Vec<(usize, f64)>,
    pub patch_nodes: Vec<(usize, f64)>,
    /// Whether the jaws tore the tissue this tick (what the scenario's tasks score).
    pub tore: bool,
    /// The hand whose jaws hold it (or held it last).
    pub hand: usize,
}

impl OrganMotion {
    /// `positions`: the organ's load positions, the most a patch holds.
    pub fn new(model: Arc<DynamicModel>, settings: GraspSettings, positions: usize) -> Self {
        let organ = model.at_rest(TICK_S, settings);
        let correction = vec![0.0; model.basis.len()];
        let in_vademecum_modes = vec![0.0; model.fit.modes()];
        Self {
            model,
            organ,
            correction,
            in_vademecum_modes,
            shares: Vec::with_capacity(positions),
            patch_nodes: Vec::with_capacity(positions),
            tore: false,
            hand: 0,
        }
    }

    /// What the organ's motion adds to its static field (m) at the blend of volume nodes
    /// `nodes` (`(node, weight)`): the kept modes times the correction, as the window draws
    /// it.
    pub fn moved_at(&self, nodes: &[(usize, f64)]) -> Vector3<f64> {
        let mut moved = Vector3::zeros();
        for (k, &c) in self.correction.iter().enumerate() {
            if c == 0.0 {
                continue;
            }
            let mode = self.model.basis.mode(k);
            for &(node, weight) in nodes {
                let at = 3 * node;
                moved += Vector3::new(mode[at], mode[at + 1], mode[at + 2]) * (c * weight);
            }
        }
        moved
    }

    /// [`Self::moved_at`] a surface point of the organ's `vademecum`.
    pub fn moved_at_point(&self, vademecum: &Vademecum, at: &SurfacePoint) -> Vector3<f64> {
        let corners = vademecum.triangles[at.triangle];
        let nodes: [(usize, f64); 3] = std::array::from_fn(|k| {
            let node = vademecum.positions[corners[k] as usize] as usize;
            (node, at.barycentric[k])
        });
        self.moved_at(&nodes)
    }
}
