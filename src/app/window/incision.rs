//! Cutting as the trainee sees it: the lines an incision task asks for, the cuts the scalpel
//! has made (in the colour of cut tissue's shadow), and the scalpel's edge at the tool tip. Drawn as lines over the organs: the
//! surface itself is not split along a cut (`docs/cutting.md`, Limits).

use bevy::prelude::*;
use nalgebra::Vector3;

use super::bridge::Snapshot;
use super::lesson::Lesson;
use super::{FrameSet, to_bevy};
use crate::scenario::{Task, metres};

/// The marked line is drawn this far out of the surface (m), so the organ does not hide it,
/// and a cut twice as far, over it.
const LIFT_M: f64 = 0.001;
/// The blade's edge is drawn this long either side of the tip (m).
const EDGE_HALF_M: f32 = 0.008;

pub(super) fn setup(app: &mut App) {
    app.add_systems(
        Update,
        (draw_marked_lines, draw_cuts, draw_edge).in_set(FrameSet::Draw),
    );
}

/// Each incision task's line, in green.
fn draw_marked_lines(lesson: Option<Res<Lesson>>, mut gizmos: Gizmos) {
    let Some(lesson) = lesson else {
        return;
    };
    for task in &lesson.scenario.tasks {
        if let Task::Incision { from_mm, to_mm, .. } = task {
            let (from, to) = (metres(*from_mm), metres(*to_mm));
            gizmos.line(
                lifted(&from, 1.0),
                lifted(&to, 1.0),
                Color::srgb(0.2, 0.9, 0.3),
            );
        }
    }
}

/// Every stroke of the scalpel, from where the tissue parted to where the cut reached, in
/// the colour of cut tissue.
fn draw_cuts(snapshot: Res<Snapshot>, mut gizmos: Gizmos) {
    for organ in &snapshot.0.organs {
        for stroke in &organ.strokes {
            let (from, to) = (stroke.start_m.into(), stroke.end_m.into());
            let colour = Color::srgb(0.12, 0.0, 0.02);
            gizmos.line(lifted(&from, 2.0), lifted(&to, 2.0), colour);
        }
    }
}

/// The scalpel's edge through the tool tip, so the trainee sees which way it cuts.
fn draw_edge(snapshot: Res<Snapshot>, mut gizmos: Gizmos) {
    let (Some(tip), Some(edge)) = (snapshot.0.tip_m, snapshot.0.blade_edge) else {
        return;
    };
    let (tip, edge) = (to_bevy(&tip), to_bevy(&edge) * EDGE_HALF_M);
    gizmos.line(tip - edge, tip + edge, Color::srgb(0.9, 0.9, 0.95));
}

/// A point of a line on the surface, drawn `lifts` times [`LIFT_M`] out of it (towards the
/// surgeon).
fn lifted(point_m: &Vector3<f64>, lifts: f64) -> Vec3 {
    to_bevy(&(point_m + Vector3::y() * LIFT_M * lifts))
}
