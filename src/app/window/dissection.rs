//! Dissection as the trainee sees it: each bed's connective tissue drawn as strands between
//! the two organs, reddening as they are damaged and gone once divided or torn; the hook's
//! burns charred on the organs' surfaces; bile around a perforation of a hollow organ; the
//! L-hook at the tip of its instrument, glowing while its energy is on.

use bevy::prelude::*;

use super::bridge::{HapticLink, Snapshot};
use super::{FrameSet, to_bevy};
use crate::app::haptic::BurnsView;
use crate::dissection::Wall;
use crate::pgd::Vademecum;

/// Areolar tissue, whole...
const STRAND: Color = Color::srgb(0.98, 0.93, 0.78);
/// ...and about to give.
const STRAND_DAMAGED: Color = Color::srgb(0.75, 0.25, 0.2);
/// A burn's char, mixed into the tissue's colour at its triangle's corners.
const CHAR: [f32; 3] = [0.16, 0.09, 0.05];
const CHAR_SHARE: f32 = 0.85;
/// Bile, on the surface around a perforation, within [`BILE_SPREAD_M`].
const BILE: [f32; 3] = [0.42, 0.55, 0.08];
const BILE_SPREAD_M: f32 = 0.008;

/// The strands drawn.
pub(super) struct DissectionPlugin;

impl Plugin for DissectionPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Update, (draw_strands, draw_hooks).in_set(FrameSet::Draw));
    }
}

/// Every live tie of every bed, a line from one organ to the other.
fn draw_strands(snapshot: Res<Snapshot>, mut gizmos: Gizmos) {
    let ties = snapshot.0.beds.iter().flat_map(|bed| &bed.ties);
    for tie in ties.filter(|tie| !tie.failed) {
        let colour = STRAND.mix(&STRAND_DAMAGED, tie.damage as f32);
        gizmos.line(
            to_bevy(&tie.ends.freed_m),
            to_bevy(&tie.ends.base_m),
            colour,
        );
    }
}

/// The hook's length along the shaft past the tip's sphere, and across it (m).
const HOOK_SHANK_M: f32 = 0.005;
const HOOK_BEND_M: f32 = 0.003;
const STEEL: Color = Color::srgb(0.7, 0.72, 0.75);
const ENERGISED: Color = Color::srgb(1.0, 0.75, 0.3);

/// Each hand's L-hook, when it holds one through a port: a shank on along the shaft past the
/// tip's sphere, then the bend across it.
fn draw_hooks(snapshot: Res<Snapshot>, link: Res<HapticLink>, mut gizmos: Gizmos) {
    let radius_m = link.scene.probe.tip_radius_m as f32;
    for hand in &snapshot.0.hands {
        let (Some(on), Some(tip), Some(handle)) = (hand.cautery, hand.tip_m, hand.handle_m) else {
            continue;
        };
        let Some(along) = (tip - handle).try_normalize(1e-9) else {
            continue;
        };
        let (tip, along) = (to_bevy(&tip), to_bevy(&along));
        let across = along.any_orthonormal_vector();
        let start = tip + along * radius_m;
        let bend = start + along * HOOK_SHANK_M;
        let colour = if on { ENERGISED } else { STEEL };
        gizmos.linestrip([start, bend, bend + across * HOOK_BEND_M], colour);
    }
}

/// Chars the vertex colours of organ `organ` (with its `wall`) where the hook burned it, and
/// paints bile around a hollow organ's perforation.
pub(super) fn tint_burns(
    colours: &mut [[f32; 4]],
    organ: usize,
    wall: Wall,
    burns: &BurnsView,
    vademecum: &Vademecum,
) {
    for mark in burns.marks().iter().filter(|m| m.organ == organ) {
        if mark.through && matches!(wall, Wall::Hollow { .. }) {
            spill_bile(colours, &mark.at_rest_m.cast::<f32>(), vademecum);
        }
        for &corner in &vademecum.triangles[mark.at.triangle] {
            if let Some(colour) = colours.get_mut(corner as usize) {
                mix(colour, CHAR, CHAR_SHARE);
            }
        }
    }
}

/// Bile over the surface within [`BILE_SPREAD_M`] of `at_m` (at rest), thinning outwards.
fn spill_bile(colours: &mut [[f32; 4]], at_m: &nalgebra::Vector3<f32>, vademecum: &Vademecum) {
    for (coords, colour) in vademecum.position_coords_m.iter().zip(colours) {
        let distance = (nalgebra::Vector3::from(*coords) - at_m).norm();
        if distance < BILE_SPREAD_M {
            mix(colour, BILE, 1.0 - 0.5 * distance / BILE_SPREAD_M);
        }
    }
}

/// `colour` moved `share` of the way to `to`.
fn mix(colour: &mut [f32; 4], to: [f32; 3], share: f32) {
    for (c, t) in colour.iter_mut().zip(to) {
        *c += (t - *c) * share;
    }
}
