//! Cutting as the trainee sees it: the lines an incision task asks for, a keratotomy's
//! optical zone (as the surgeon's marker inks it), the cuts the scalpel has made (in the
//! colour of cut tissue's shadow), and the scalpel's edge at the tool tip, drawn as lines
//! over the organs (the surface split along a cut is [`super::cut_surface`]'s).

use bevy::prelude::*;
use nalgebra::Vector3;

use super::bridge::{HapticLink, Snapshot};
use super::lesson::Lesson;
use super::{FrameSet, to_bevy};
use crate::cutting::keratotomy::anterior_point;
use crate::scenario::metres;
use crate::scenario::tasks::{Incision, RadialKeratotomy};

/// The blade's edge is drawn this many tool radii either side of the tip.
const EDGE_HALF_RADII: f32 = 1.33;
/// The colour of a line marked on the tissue.
const MARKER: Color = Color::srgb(0.2, 0.9, 0.3);

/// The incisions drawn.
pub(super) struct IncisionPlugin;

impl Plugin for IncisionPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            Update,
            (draw_marked_lines, draw_optical_zones, draw_cuts, draw_edge).in_set(FrameSet::Draw),
        );
    }
}

/// Each incision task's line, in green.
fn draw_marked_lines(lesson: Option<Res<Lesson>>, link: Res<HapticLink>, mut gizmos: Gizmos) {
    let Some(lesson) = lesson else {
        return;
    };
    let lift = Lift::of(&link);
    for task in &lesson.scenario.tasks {
        if let Some(incision) = task.get::<Incision>() {
            let (from, to) = (metres(incision.from_mm), metres(incision.to_mm));
            gizmos.line(lift.up(&from, 1.0), lift.up(&to, 1.0), MARKER);
        }
    }
}

/// Each keratotomy's optical zone, a green ring on the cornea: the incisions start outside it.
fn draw_optical_zones(lesson: Option<Res<Lesson>>, link: Res<HapticLink>, mut gizmos: Gizmos) {
    let Some(lesson) = lesson else {
        return;
    };
    let lift = Lift::of(&link);
    for task in &lesson.scenario.tasks {
        if let Some(keratotomy) = task.get::<RadialKeratotomy>() {
            let radius_m = keratotomy.optical_zone_mm.metres() / 2.0;
            let ring = (0..=72).map(|k| {
                let at = anterior_point(std::f64::consts::TAU * f64::from(k) / 72.0, radius_m);
                lift.up(&at.coords, 1.0)
            });
            gizmos.linestrip(ring, MARKER);
        }
    }
}

/// Every stroke of the scalpel, from where the tissue parted to where the cut reached, in
/// the colour of cut tissue, over the organ's rest surface (a straight line between the ends
/// would run under a curved one: the cornea's).
fn draw_cuts(snapshot: Res<Snapshot>, link: Res<HapticLink>, mut gizmos: Gizmos) {
    let lift = Lift::of(&link);
    let colour = Color::srgb(0.12, 0.0, 0.02);
    for (organ, (_, vademecum)) in snapshot.0.organs.iter().zip(&link.scene.organs) {
        let surface = &vademecum.position_coords_m;
        for stroke in &organ.strokes {
            let (from, to) = (stroke.start_m.into(), stroke.end_m.into());
            gizmos.linestrip(lift.over(surface, &from, &to), colour);
        }
    }
}

/// The scalpel's edge through the tool tip, so the trainee sees which way it cuts.
fn draw_edge(snapshot: Res<Snapshot>, link: Res<HapticLink>, mut gizmos: Gizmos) {
    let (Some(tip), Some(edge)) = (
        snapshot.0.first_hand().tip_m,
        snapshot.0.first_hand().blade_edge,
    ) else {
        return;
    };
    let half_m = EDGE_HALF_RADII * link.scene.probe.tip_radius_m as f32;
    let (tip, edge) = (to_bevy(&tip), to_bevy(&edge) * half_m);
    gizmos.line(tip - edge, tip + edge, Color::srgb(0.9, 0.9, 0.95));
}

/// How lines on the surface are lifted out of it, towards the surgeon, so that the organ
/// does not hide them.
struct Lift {
    towards: Vector3<f64>,
    step_m: f64,
}

impl Lift {
    fn of(link: &HapticLink) -> Self {
        let facing = link.facing();
        Self {
            towards: Vector3::new(facing.x, facing.y, facing.z).cast(),
            step_m: link.line_lift_m(),
        }
    }

    /// A point of a line on the surface, drawn `steps` lifts out of it.
    fn up(&self, point_m: &Vector3<f64>, steps: f64) -> Vec3 {
        to_bevy(&(point_m + self.towards * self.step_m * steps))
    }

    /// The line from `from_m` to `to_m` in steps of three lifts, each point set on the
    /// `surface` (its vertices, m) at the height of the vertex nearest it, and lifted twice.
    fn over<'a>(
        &'a self,
        surface: &'a [[f32; 3]],
        from_m: &Vector3<f64>,
        to_m: &Vector3<f64>,
    ) -> impl Iterator<Item = Vec3> + 'a {
        let (from_m, to_m) = (*from_m, *to_m);
        let steps = ((to_m - from_m).norm() / (3.0 * self.step_m))
            .ceil()
            .max(1.0) as usize;
        (0..=steps).map(move |k| {
            let point = from_m + (to_m - from_m) * (k as f64 / steps as f64);
            self.up(&self.onto(surface, point), 2.0)
        })
    }

    /// `point` moved along the lift's direction to the height of the `surface` vertex nearest
    /// it.
    fn onto(&self, surface: &[[f32; 3]], point: Vector3<f64>) -> Vector3<f64> {
        let distance = |v: &Vector3<f64>| (v - point).norm_squared();
        let nearest = surface
            .iter()
            .map(|v| Vector3::from(*v).cast::<f64>())
            .min_by(|a, b| distance(a).total_cmp(&distance(b)));
        nearest.map_or(point, |v| {
            point + self.towards * (v - point).dot(&self.towards)
        })
    }
}
