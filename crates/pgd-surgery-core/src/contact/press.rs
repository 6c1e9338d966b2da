//! The rigid probe and the load it puts on an organ.
//!
//! The tool tip is a sphere. Its contact point `s` is the surface point below the sphere's
//! centre on the deformed surface (the rest surface moved by all the organ's loads). The tip
//! holds the surface under it, averaged over its contact patch: along the normal, as deep as
//! the tip reaches into the surface as the organ's other loads have moved it; sideways, where
//! it was at rest, whatever the other loads do. The load that does so is the vademecum's 3 × 3
//! patch compliance at `s`, inverted (for a KSV vademecum, the secant over its load steps),
//! times the displacement the tool must add. With no other load on the organ that is the
//! tip's penetration along the normal. Holding the surface sideways too, against the other
//! loads, makes the tool a spring on the patch: its answer to them derives from an energy, so
//! the tool and organ contact can be solved as one problem ([`super::hold`]). A tool that
//! let the others move the surface sideways, yet held it sideways against its own load, drove
//! the gallbladder into the liver with the contact, tick after tick.

use nalgebra::{Matrix3, Vector3};
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
    /// How far the organ's other loads have moved the surface there (m), averaged over the
    /// tool's patch.
    pub moved_m: Vector3<f64>,
    /// How far the tip reaches below the rest surface, along the normal (m).
    pub depth_m: f64,
    /// How much of that depth lies beyond what the vademecum's load steps cover (m); zero
    /// within the range. The organ answers at the range edge's secant stiffness there, what
    /// the trainee feels at the stiffness of its last load-step interval
    /// ([`Vademecum::patch_press_in_range`]), and the run's report says so.
    pub beyond_range_m: f64,
    /// The displacement the tool's load adds to the surface under it (m): into the surface by
    /// the depth, and back sideways by what the other loads moved it.
    pub indentation_m: Vector3<f64>,
    /// How the force changes with the indentation (N/m): the inverse of the patch compliance.
    pub stiffness_n_per_m: Matrix3<f64>,
    /// The force on the organ (N): its load.
    pub force_n: Vector3<f64>,
    /// What the tissue's stiffening beyond its range adds to the force felt (N; zero within
    /// the range): the device renders the opposite of [`Self::felt_n`].
    pub stiffening_n: Vector3<f64>,
    /// How that stiffening changes with the indentation (N/m; zero within the range): the
    /// felt force's stiffness less the organ's.
    pub stiffening_n_per_m: Matrix3<f64>,
}

impl ToolContact {
    /// The force whose opposite the device renders (N).
    pub fn felt_n(&self) -> Vector3<f64> {
        self.force_n + self.stiffening_n
    }
}

/// What the tool presses: an organ's vademecum, its contact surface, how far a patch has
/// moved under the organ's other loads (averaged by its shares), and how far each surface
/// point has moved under all its loads (the tool's of the last tick included) (m).
pub struct Target<'a, F, G>
where
    F: Fn(&Patch) -> Vector3<f64>,
    G: Fn(&SurfacePoint) -> Vector3<f64>,
{
    pub vademecum: &'a Vademecum,
    pub surface: &'a ContactSurface,
    pub moved_by_others: F,
    pub moved_by_all: G,
}

/// Presses `probe`, its tip centred at `tip_m`, into `target`: sets `load` to the force that
/// makes the surface follow the tip and returns the contact, or releases `load` when the tip
/// does not touch. `previous` is the last tick's contact point, which the new one tracks
/// ([`ContactSurface::tracked`]). `patch` is scratch space kept between ticks: nothing is
/// allocated once it and `load` have grown.
pub fn press<F, G>(
    target: &Target<F, G>,
    probe: &Probe,
    tip_m: &Vector3<f64>,
    previous: Option<&SurfacePoint>,
    patch: &mut Patch,
    load: &mut PatchLoad,
) -> Option<ToolContact>
where
    F: Fn(&Patch) -> Vector3<f64>,
    G: Fn(&SurfacePoint) -> Vector3<f64>,
{
    let vademecum = target.vademecum;
    let Some(contact) = touch(target, probe, tip_m, previous, patch) else {
        load.release();
        return None;
    };
    let press = vademecum.patch_press_in_range(patch, &contact.indentation_m);
    load.shares.clone_from(&patch.shares);
    load.force_n = press.force_n;
    Some(ToolContact {
        force_n: press.force_n,
        stiffening_n: press.felt_n - press.force_n,
        stiffening_n_per_m: press.felt_stiffness_n_per_m - press.stiffness_n_per_m,
        stiffness_n_per_m: press.stiffness_n_per_m,
        beyond_range_m: contact.depth_m * press.beyond,
        ..contact
    })
}

/// A tracked contact point moves to another part of the surface only when that part is
/// closer to the tip by this many tip radii.
const SWITCH_TIP_RADII: f64 = 0.25;

/// Where and how deep the tip presses, before the force is known, and the patch under it.
/// - The point below the tip is found on the surface as all loads have moved it (one
///   correction: the displacement varies slowly along the surface), tracked from the last
///   tick's point, so that it slides along a groove's side instead of jumping to the other.
///   The other loads alone would not do: an organ pressed against another carries the two
///   loads' large, opposite displacements (the coarse gallbladder's floppy modes, tens of
///   centimetres each way), and the point found with one of them jumped across the surface
///   from tick to tick.
/// - What the other loads moved is averaged over the patch with the patch's shares, as the
///   patch compliance averages the tool's own displacement. Taken at one point instead, the
///   tool's answer to a contact force did not match what the contact solve expected, and on
///   the floppy gallbladder held by the tool the contact's compliance is the small difference
///   of the two ([`super::hold`]).
fn touch<F, G>(
    target: &Target<F, G>,
    probe: &Probe,
    tip_m: &Vector3<f64>,
    previous: Option<&SurfacePoint>,
    patch: &mut Patch,
) -> Option<ToolContact>
where
    F: Fn(&Patch) -> Vector3<f64>,
    G: Fn(&SurfacePoint) -> Vector3<f64>,
{
    let (vademecum, surface) = (target.vademecum, target.surface);
    let switch_m = SWITCH_TIP_RADII * probe.tip_radius_m;
    let mut hit = surface.tracked(tip_m, previous, switch_m)?;
    let moved_by_all = (target.moved_by_all)(&hit.at);
    if moved_by_all != Vector3::zeros() {
        hit = surface.tracked(
            &(tip_m - moved_by_all),
            previous.or(Some(&hit.at)),
            switch_m,
        )?;
    }
    vademecum.patch_into(&hit.at, patch);
    let moved_m = (target.moved_by_others)(patch);
    let depth_m = probe.tip_radius_m - (tip_m - hit.point_m - moved_m).dot(&hit.normal);
    if depth_m <= 0.0 {
        return None;
    }
    let sideways_m = moved_m - hit.normal * moved_m.dot(&hit.normal);
    Some(ToolContact {
        hit,
        moved_m,
        depth_m,
        beyond_range_m: 0.0,
        indentation_m: -hit.normal * depth_m - sideways_m,
        stiffness_n_per_m: Matrix3::zeros(),
        force_n: Vector3::zeros(),
        stiffening_n: Vector3::zeros(),
        stiffening_n_per_m: Matrix3::zeros(),
    })
}

/// The tool, where it is, answers the contact forces of the tick moving the surface under it
/// by `moved_m` ([`super::ToolHold`]): it takes the move back, so its depth grows by the move
/// along the normal, and its load by the hold's stiffness times the move (exact for a linear
/// vademecum; for a KSV one the next tick's press takes the secant and its range again).
/// Beyond the range what the trainee feels follows at its own, stiffer chord, so the
/// tissue's stiffening answers the move in the same tick. A depth that reaches zero lets go.
pub fn follow(contact: &mut Option<ToolContact>, load: &mut PatchLoad, moved_m: &Vector3<f64>) {
    let Some(touch) = contact else {
        return;
    };
    if *moved_m == Vector3::zeros() {
        return;
    }
    touch.depth_m += moved_m.dot(&touch.hit.normal);
    if touch.depth_m <= 0.0 {
        *contact = None;
        load.release();
        return;
    }
    let change_n = touch.stiffness_n_per_m * -moved_m;
    touch.moved_m += moved_m;
    touch.indentation_m -= moved_m;
    touch.force_n += change_n;
    touch.stiffening_n += touch.stiffening_n_per_m * -moved_m;
    load.force_n += change_n;
}
