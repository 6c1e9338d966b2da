//! The scalpel: when tissue parts under its blade, and the incision each stroke makes.
//!
//! The tissue parts when the blade presses into it with the tissue's fracture toughness times
//! the length of edge pressed in (the work of parting a unit area of tissue, over a unit
//! advance of the edge: the energy balance of cutting soft solids). Below that force the
//! blade only presses, and the trainee feels the tissue's resistance. Once it parts, the
//! tissue above the blade's edge no longer holds it along the normal: the force drops to what
//! the tissue below the cut answers (the give, as in Mahvash and Hayward's deformation,
//! rupture and cutting phases, IEEE Computer Graphics and Applications 24(2), 2004). The blade
//! then cuts along its edge as the hand moves it, and as deep as it is pressed: each step of
//! the edge is a segment of the incision, which the cut state turns into enriched functions.

use nalgebra::{Point3, Unit, Vector3};
use serde::Serialize;

/// Fracture toughness of porcine liver cut with a blade (J/m²): 187–225 J/m² (Chanthasopeephan,
/// Desai and Lau, *Measuring forces in liver cutting: new equipment and experimental results*,
/// Annals of Biomedical Engineering 31(11):1372–1382, 2003); the lower end is taken. Needle
/// insertion into bovine liver gives 164 ± 6 J/m² (Gokgol, Basdogan and Canadinc, Medical
/// Engineering & Physics 34(7):882–891, 2012).
pub const LIVER_TOUGHNESS_J_PER_M2: f64 = 187.0;

/// Fracture toughness of porcine cornea (J/m²): 3390 ± 570 to 5400 ± 480 J/m² from trouser
/// tear tests, as tabulated by Liu et al., *Recent advances in soft biological tissue
/// manipulating technologies*, Chinese Journal of Mechanical Engineering 35:89, 2022
/// (Table 2); the lower end is taken.
pub const CORNEA_TOUGHNESS_J_PER_M2: f64 = 3390.0;

/// A scalpel's blade as it meets the tissue.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blade {
    /// The length of edge pressed into the tissue (m): the tissue parts under a force of its
    /// toughness times this length.
    pub edge_m: f64,
    /// The incision advances in steps of this length (m), each a segment of the cut.
    pub step_m: f64,
    /// Turning the blade further than this (rad) from the face it sweeps starts a new face.
    pub turn_rad: f64,
    /// A blade pressed deeper than the incision by this share of its depth deepens it.
    pub deepen_share: f64,
    /// Where the surface under the blade has curved away from the face's line by more than
    /// this share of the cut's depth, the cut follows it and a new face starts (a straight
    /// face over the cornea's curve would leave its far end uncut, above the surface).
    pub follow_share: f64,
}

impl Default for Blade {
    /// A No. 10 blade's belly pressed 5 mm into the tissue, advancing the cut every 2 mm.
    fn default() -> Self {
        Self {
            edge_m: 0.005,
            step_m: 0.002,
            turn_rad: 15f64.to_radians(),
            deepen_share: 0.15,
            follow_share: 0.1,
        }
    }
}

impl Blade {
    /// The force (N) into the tissue at which tissue of `toughness_j_per_m2` parts.
    pub fn threshold_n(&self, toughness_j_per_m2: f64) -> f64 {
        toughness_j_per_m2 * self.edge_m
    }
}

/// The blade on an organ this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BladeContact {
    /// The point under the blade, on the organ's rest surface (m).
    pub point_m: Point3<f64>,
    /// Into the tissue: the surface's inward normal there.
    pub inward: Unit<Vector3<f64>>,
    /// The blade's edge, in the scene (from the device's orientation); only its part along
    /// the surface counts.
    pub edge: Vector3<f64>,
    /// How deep the blade reaches below the rest surface (m).
    pub depth_m: f64,
    /// The force the blade presses into the tissue with (N).
    pub pressing_n: f64,
}

/// What a tick of the scalpel does to the organ's cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CutStep {
    /// The tissue parts: an incision begins at `at`, the blade along `blade`, `depth_m` deep.
    Start {
        at: Point3<f64>,
        blade: Vector3<f64>,
        depth_m: f64,
    },
    /// The incision under way reaches `to`.
    Advance { to: Point3<f64> },
    /// The incision under way cuts `depth_m` deep.
    Deepen { depth_m: f64 },
}

/// One stroke of the blade: from where the tissue parted to where the cut reached.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stroke {
    pub start_m: [f64; 3],
    pub end_m: [f64; 3],
    /// The length cut (m), along the faces.
    pub length_m: f64,
    /// The deepest the blade cut (m).
    pub max_depth_m: f64,
}

/// The stroke under way: the face being swept starts at `face_from` and runs along `along`
/// (its sense unknown until the blade first moves a step), `reach_m` far, the blade along
/// `down`.
#[derive(Clone, Copy, Debug)]
struct Sweep {
    face_from: Point3<f64>,
    along: Unit<Vector3<f64>>,
    down: Unit<Vector3<f64>>,
    sensed: bool,
    reach_m: f64,
    depth_m: f64,
}

impl Sweep {
    /// Where the cut's front is on the surface under the blade at `point`: the point in the
    /// face's plane (its part across the plane dropped), so that a surface curving away from
    /// the straight face does not count as straying off it.
    fn front(&self, point: &Point3<f64>) -> Point3<f64> {
        let across = self.along.cross(&self.down);
        let Some(across) = across.try_normalize(1e-9) else {
            return *point;
        };
        point - across * (point - self.face_from).dot(&across)
    }
}

/// Strokes a scalpel has room for from the start: an attempt making more grows the list (a
/// radial keratotomy makes 4 to 8, an incision one or a few).
pub const STROKES_RESERVED: usize = 64;

/// A scalpel on one organ: the tissue's threshold, the stroke under way and the strokes made.
#[derive(Clone, Debug)]
pub struct Scalpel {
    blade: Blade,
    threshold_n: f64,
    sweep: Option<Sweep>,
    strokes: Vec<Stroke>,
}

impl Scalpel {
    /// The blade on tissue of fracture toughness `toughness_j_per_m2`.
    pub fn new(blade: Blade, toughness_j_per_m2: f64) -> Self {
        Self {
            blade,
            threshold_n: blade.threshold_n(toughness_j_per_m2),
            sweep: None,
            strokes: Vec::with_capacity(STROKES_RESERVED),
        }
    }

    /// The blade on uncut tissue again: no stroke made, none under way.
    pub fn heal(&mut self) {
        self.sweep = None;
        self.strokes.clear();
    }

    /// The force (N) into the tissue at which it parts.
    pub fn threshold_n(&self) -> f64 {
        self.threshold_n
    }

    /// The strokes made so far, the one under way last.
    pub fn strokes(&self) -> &[Stroke] {
        &self.strokes
    }

    /// Whether a stroke is under way (the blade is in its cut).
    pub fn cutting(&self) -> bool {
        self.sweep.is_some()
    }

    /// How deep the tissue has parted under the blade (m), while a stroke is under way: the
    /// tissue above that depth no longer holds the blade along the normal, only the tissue
    /// below it does (the give).
    pub fn parted_depth_m(&self) -> Option<f64> {
        self.sweep.map(|sweep| sweep.depth_m)
    }

    /// The blade this tick, `None` off the tissue: what it does to the cut. Lifting the
    /// blade off ends the stroke; the next cut starts only where the tissue parts again.
    pub fn tick(&mut self, contact: Option<&BladeContact>) -> Option<CutStep> {
        let Some(contact) = contact else {
            self.sweep = None;
            return None;
        };
        match self.sweep {
            None => self.part(contact),
            Some(_) => self.sweep(contact),
        }
    }

    /// The tissue parts if pressed hard enough and the edge lies across the surface.
    fn part(&mut self, contact: &BladeContact) -> Option<CutStep> {
        if contact.pressing_n < self.threshold_n
            || contact.depth_m.is_nan()
            || contact.depth_m <= 0.0
        {
            return None;
        }
        let along = tangent(&contact.edge, &contact.inward)?;
        self.sweep = Some(Sweep {
            face_from: contact.point_m,
            along,
            down: contact.inward,
            sensed: false,
            reach_m: 0.0,
            depth_m: contact.depth_m,
        });
        let at = contact.point_m.coords.into();
        self.strokes.push(Stroke {
            start_m: at,
            end_m: at,
            length_m: 0.0,
            max_depth_m: contact.depth_m,
        });
        Some(CutStep::Start {
            at: contact.point_m,
            blade: contact.inward.into_inner(),
            depth_m: contact.depth_m,
        })
    }

    /// The blade in its cut: deeper, it deepens the cut; turned, it starts a new face from
    /// where the cut reached; moved a step along its edge, it advances the cut. Motion across
    /// the edge cuts nothing.
    fn sweep(&mut self, contact: &BladeContact) -> Option<CutStep> {
        let blade = self.blade;
        let sweep = self.sweep.as_mut().expect("a stroke under way");
        let stroke = self.strokes.last_mut().expect("a stroke under way");
        if contact.depth_m > sweep.depth_m * (1.0 + blade.deepen_share) {
            sweep.depth_m = contact.depth_m;
            stroke.max_depth_m = stroke.max_depth_m.max(contact.depth_m);
            return Some(CutStep::Deepen {
                depth_m: contact.depth_m,
            });
        }
        if let Some(edge) = tangent(&contact.edge, &contact.inward)
            && sweep.reach_m > 0.0
            && edge.dot(&sweep.along).abs() < blade.turn_rad.cos()
        {
            let sense = edge.dot(&sweep.along).signum();
            sweep.face_from += sweep.along.into_inner() * sweep.reach_m;
            sweep.along = Unit::new_unchecked(edge.into_inner() * sense);
            sweep.reach_m = 0.0;
        }
        let mut reach_m = (contact.point_m - sweep.face_from).dot(&sweep.along);
        if !sweep.sensed {
            if reach_m.abs() < blade.step_m {
                return None;
            }
            sweep.sensed = true;
            if reach_m < 0.0 {
                sweep.along = -sweep.along;
                reach_m = -reach_m;
            }
        }
        if reach_m < sweep.reach_m + blade.step_m {
            return None;
        }
        stroke.length_m += reach_m - sweep.reach_m;
        sweep.reach_m = reach_m;
        let front = sweep.front(&contact.point_m);
        stroke.end_m = front.coords.into();
        let on_line = sweep.face_from + sweep.along.into_inner() * reach_m;
        if ((front - on_line).dot(&sweep.down)).abs() <= blade.follow_share * sweep.depth_m {
            return Some(CutStep::Advance { to: on_line });
        }
        // The surface has curved away from the face's line: the cut follows it down (or up)
        // to the surface under the blade, and the next face starts there, square to it.
        sweep.face_from = front;
        sweep.down = contact.inward;
        sweep.along = tangent(&sweep.along, &contact.inward).unwrap_or(sweep.along);
        sweep.reach_m = 0.0;
        Some(CutStep::Advance { to: front })
    }
}

/// `edge`'s direction along the surface whose inward normal is `inward`, if it has one (a
/// blade whose edge points straight into the tissue has none).
fn tangent(edge: &Vector3<f64>, inward: &Unit<Vector3<f64>>) -> Option<Unit<Vector3<f64>>> {
    let along = edge - inward.into_inner() * edge.dot(inward);
    Unit::try_new(along, 0.1 * edge.norm().max(f64::MIN_POSITIVE))
}
