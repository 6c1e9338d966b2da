//! Clips closed across a tube: where closed jaws cross a tube's axis ([`crossing`]), and the
//! clip they leave there ([`Clip`]), recorded with its place along the tube, its angle to the
//! tube's axis and the share of the tube's width it closes. A clip stays where it was put on
//! the tube and moves with it.

use nalgebra::Vector3;
use serde::Serialize;

use super::anatomy::{BiliaryTree, Part, Structure};
use super::geometry::Segment;

/// A clip closing at least this share of the tube's width closes its lumen.
const WHOLE: f64 = 1.0 - 1e-9;

/// Where closed jaws (or blades), from their hinge to their tips, cross a tube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub structure: Structure,
    /// Along the tube from its patient end, at rest (m).
    pub arc_length_m: f64,
    /// Between the jaws and the tube's axis (degrees, 90 square across).
    pub angle_deg: f64,
    /// The share of the tube's flattened width that lies between the jaws.
    pub closed_share: f64,
}

/// The crossing of `jaws` with the tube of `tree` whose axis they pass nearest, among those
/// they pass within the tube's outer radius; `None` where they close on no tube.
///
/// A tube closed between jaws lies flat, its width half its circumference (`π r`); along
/// jaws at an angle `θ` to its axis it spans `π r / sin θ`, centred where the jaws pass its
/// axis. The share of that span between the hinge and the tips is what they close.
pub fn crossing(tree: &BiliaryTree, jaws: &Segment) -> Option<Crossing> {
    let jaw_m = jaws.length_m();
    let mut best: Option<(f64, Crossing)> = None;
    for tube in &tree.tubes {
        let radius_m = tube.section.outer_radius_m;
        for (segment, axis) in tube.segments() {
            let closest = jaws.closest(&axis);
            if closest.distance_m > radius_m || best.is_some_and(|(d, _)| d <= closest.distance_m) {
                continue;
            }
            let along = (axis.to_m - axis.from_m).normalize();
            let across = (jaws.to_m - jaws.from_m) / jaw_m.max(f64::MIN_POSITIVE);
            let cos = along.dot(&across).abs().min(1.0);
            let sin = (1.0 - cos * cos).sqrt().max(1e-9);
            let width_m = std::f64::consts::PI * radius_m / sin;
            let centre_m = closest.on_first * jaw_m;
            let covered_m =
                (centre_m + width_m / 2.0).min(jaw_m) - (centre_m - width_m / 2.0).max(0.0);
            let crossing = Crossing {
                structure: tube.structure,
                arc_length_m: (segment as f64 + closest.on_second) * tube.rod.segment_m(),
                angle_deg: cos.acos().to_degrees(),
                closed_share: (covered_m / width_m).clamp(0.0, 1.0),
            };
            best = Some((closest.distance_m, crossing));
        }
    }
    best.map(|(_, crossing)| crossing)
}

/// A clip on a tube.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Clip {
    pub structure: Structure,
    pub part: Part,
    /// Along the tube from its patient end, at rest (m).
    pub arc_length_m: f64,
    /// Between the clip and the tube's axis (degrees, 90 square across).
    pub angle_deg: f64,
    /// The share of the tube's flattened width the clip closes.
    pub closed_share: f64,
}

impl Clip {
    /// The clip closed by `jaws` on the tube they cross, if any.
    pub fn place(tree: &BiliaryTree, jaws: &Segment) -> Option<Self> {
        let crossing = crossing(tree, jaws)?;
        Some(Self {
            structure: crossing.structure,
            part: tree.part_at(crossing.structure, crossing.arc_length_m),
            arc_length_m: crossing.arc_length_m,
            angle_deg: crossing.angle_deg,
            closed_share: crossing.closed_share,
        })
    }

    /// Whether it closes the whole width, and so the lumen.
    pub fn closes_lumen(&self) -> bool {
        self.closed_share >= WHOLE
    }

    /// Where it is now, on its tube as the tube has moved.
    pub fn position_m(&self, tree: &BiliaryTree) -> Vector3<f64> {
        tree.tube(self.structure).point_at(self.arc_length_m)
    }
}
