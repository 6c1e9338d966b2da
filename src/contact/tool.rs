//! The rigid probe and the load it puts on an organ.
//!
//! The tool tip is a sphere. Its contact point `s` is the surface point below the sphere's
//! centre on the deformed surface: the rest surface moved by the organ's other loads (the tool's
//! own load is what is being solved for; under a frictionless tip the point that touches it is
//! the one below its centre). The surface there must move further by the tip's penetration
//! along the normal; the load that does so is the vademecum's 3 × 3 compliance at `s`,
//! inverted (for a KSV vademecum, the secant over its load steps).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::{ContactSurface, SurfaceHit};
use crate::pgd::{BuildSettings, Patch, PatchLoad, SurfacePoint, Vademecum};

/// A rigid probe with a spherical tip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Probe {
    pub tip_radius_m: f64,
}

impl Default for Probe {
    /// The tip the vademecums' tool patch is built for by default.
    fn default() -> Self {
        Self {
            tip_radius_m: BuildSettings::default().tool_tip_radius_m,
        }
    }
}

/// The tool pressing into an organ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolContact {
    /// The contact point on the rest surface.
    pub hit: SurfaceHit,
    /// How far the organ's other loads have moved the surface there (m).
    pub moved_m: Vector3<f64>,
    /// How far the tip reaches below the rest surface, along the normal (m); clamped to the
    /// vademecum's valid range.
    pub depth_m: f64,
    /// The displacement imposed on the surface under the tool (m).
    pub indentation_m: Vector3<f64>,
    /// The force on the organ (N); the device renders its opposite.
    pub force_n: Vector3<f64>,
}

/// What the tool presses: an organ's vademecum, its contact surface, and how far its other
/// loads have moved each surface point (m).
pub struct Target<'a, F: Fn(&SurfacePoint) -> Vector3<f64>> {
    pub vademecum: &'a Vademecum,
    pub surface: &'a ContactSurface,
    pub moved_by_others: F,
}

/// Presses `probe`, its tip centred at `tip_m`, into `target`: sets `load` to the force that
/// makes the surface follow the tip and returns the contact, or releases `load` when the tip
/// does not touch. `patch` is scratch space kept between ticks: nothing is allocated once it
/// and `load` have grown.
pub fn press<F: Fn(&SurfacePoint) -> Vector3<f64>>(
    target: &Target<F>,
    probe: &Probe,
    tip_m: &Vector3<f64>,
    patch: &mut Patch,
    load: &mut PatchLoad,
) -> Option<ToolContact> {
    let vademecum = target.vademecum;
    let Some(contact) = touch(target, probe, tip_m) else {
        load.release();
        return None;
    };
    vademecum.patch_into(&contact.hit.at, patch);
    let force_n = vademecum.patch_force_for_indentation(patch, &contact.indentation_m);
    load.shares.clone_from(&patch.shares);
    load.force_n = force_n;
    Some(ToolContact { force_n, ..contact })
}

/// Where and how deep the tip presses, before the force is known. The point below the tip on
/// the moved surface is found by projecting the tip moved back by the other loads'
/// displacement (one correction: that displacement varies slowly along the surface).
fn touch<F: Fn(&SurfacePoint) -> Vector3<f64>>(
    target: &Target<F>,
    probe: &Probe,
    tip_m: &Vector3<f64>,
) -> Option<ToolContact> {
    let (vademecum, surface) = (target.vademecum, target.surface);
    let mut hit = surface.closest(tip_m)?;
    let mut moved_m = (target.moved_by_others)(&hit.at);
    if moved_m != Vector3::zeros() {
        hit = surface.closest(&(tip_m - moved_m))?;
        moved_m = (target.moved_by_others)(&hit.at);
    }
    let depth_m = probe.tip_radius_m - (tip_m - hit.point_m - moved_m).dot(&hit.normal);
    if depth_m <= 0.0 {
        return None;
    }
    let depth_m = match vademecum.steps.len() {
        1 => depth_m,
        _ => depth_m.min(vademecum.valid_indentation_m()),
    };
    Some(ToolContact {
        hit,
        moved_m,
        depth_m,
        indentation_m: -hit.normal * depth_m,
        force_n: Vector3::zeros(),
    })
}
