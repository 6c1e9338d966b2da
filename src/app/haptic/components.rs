//! What an organ entity of the haptic world holds: its vademecum and contact surface (shared
//! through `Arc`, never copied), the tool's contact with it, and its deformation state.

use std::sync::Arc;

use bevy::prelude::*;

use crate::contact::{ContactSurface, ToolContact};
use crate::pgd::{Deformation, Patch, PatchLoad, Vademecum};

/// An organ's mechanical model (the vademecum, which carries the regions it was built with in
/// its header) and collision model (its accessible surface).
#[derive(Component, Clone)]
pub struct OrganBody {
    pub name: String,
    pub vademecum: Arc<Vademecum>,
    pub surface: Arc<ContactSurface>,
}

/// The organ's place in the scene's list: the order of [`super::HapticSnapshot::organs`].
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct OrganIndex(pub usize);

/// The tool's contact with the organ this tick, if it touches, the patch under it and the
/// tool's next load (scratch space kept from tick to tick: the press reads the organ's loads,
/// the last tick's tool load included, while it writes the next one).
#[derive(Component, Clone, Debug, Default)]
pub struct ToolTouch {
    pub contact: Option<ToolContact>,
    pub patch: Patch,
    pub next_load: PatchLoad,
}

/// The loads on the organ and their modal coefficients. Load slot [`Self::TOOL`] is the tool's.
#[derive(Component, Clone, Debug)]
pub struct OrganDeformation(pub Deformation);

impl OrganDeformation {
    pub const TOOL: usize = 0;
}
