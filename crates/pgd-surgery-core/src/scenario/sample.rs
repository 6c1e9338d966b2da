//! What the haptic loop tells the tasks of one tick, and where the scenario's points lie on
//! the scene's organs.

use nalgebra::Vector3;

use super::incision::BladeSample;
use crate::biliary::{Clip, Division};
use crate::pgd::SurfacePoint;

/// What the haptic loop knows of one tick, for scoring.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub tip_m: Option<Vector3<f64>>,
    /// The force sent to the device (N).
    pub force_n: f64,
    /// The organs the tool touches: bit `k` for the scenario's `organs[k]`.
    pub touching: u64,
    /// Whether the device's first button is held (the mark in palpation).
    pub button: bool,
    /// The instrument in hand, in the scenario's order (0 with one).
    pub instrument: usize,
    /// Retraction: how far (m) the watched region ([`Exercise::watched_region`]) has moved
    /// along its direction; 0 when nothing is watched.
    pub region_moved_m: f64,
    /// Retraction: the force (N) on the organs other than the watched region's, from the tool
    /// and from the organs they touch.
    pub surrounding_force_n: f64,
    /// The organs the grasper's jaws hold: bit `k` for the scenario's `organs[k]`.
    pub grasping: u64,
    /// Whether the grasper tore tissue this tick (a tear before the task began, in an
    /// earlier attempt, does not count against it).
    pub tore: bool,
    /// The scalpel's cut under way, if it is cutting.
    pub blade: Option<BladeSample>,
    /// Under a laparoscope: whether the tool's tip is in the camera's view...
    pub tip_in_view: Option<bool>,
    /// ...and whether the point the scenario has the trainee keep in view is.
    pub target_in_view: Option<bool>,
    /// How far (m) the tool pressed beyond the depth the tissue model covers (the deepest
    /// load step of the organ's nonlinear vademecum), on the organ it presses deepest so;
    /// zero within range.
    pub beyond_range_m: f64,
    /// In a bimanual exercise, the left hand's (the fields above that name the tool, the
    /// force, what it touches and holds are the right hand's).
    pub left: Option<HandSample>,
    /// The hook's energy in this tick and where it went (either hand's).
    pub hook: HookSample,
    /// The share (0–1, by area) of the scene's attachments released so far.
    pub released_share: f64,
    /// Ties a grasper's pull tore in this tick (blunt dissection).
    pub ties_torn: u32,
    /// What happened to the biliary tree in this tick (nothing without one).
    pub biliary: BiliarySample,
}

/// The biliary tree in one tick: a clip placed or a tube divided in it, what the open stumps
/// have let out so far and the critical view of safety as it stands.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BiliarySample {
    pub clip: Option<Clip>,
    pub division: Option<Division>,
    pub blood_lost_m3: f64,
    pub bile_spilled_m3: f64,
    /// Whether an open stump still bleeds (neither clipped nor coagulated).
    pub bleeding: bool,
    pub view: ViewSample,
}

/// The critical view of safety's criteria, as [`crate::biliary::CriticalView`] measures them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewSample {
    pub triangle_cleared: f64,
    pub lower_third_released: f64,
    /// The tubes entering the gallbladder, and how many of them are seen.
    pub entering: u8,
    pub seen: u8,
    pub reached: bool,
}

impl ViewSample {
    pub fn of(view: &crate::biliary::CriticalView) -> Self {
        Self {
            triangle_cleared: view.triangle_cleared,
            lower_third_released: view.lower_third_released,
            entering: view.entering().count() as u8,
            seen: view.seen() as u8,
            reached: view.reached(),
        }
    }
}

/// The energy an electrocautery hook delivered in one tick, and what took it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HookSample {
    pub energy_j: f64,
    pub on: HookTarget,
}

/// What took the hook's energy in a tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum HookTarget {
    /// No energy: the button is up, or the instrument is not a hook.
    #[default]
    Off,
    /// The connective tissue within the hook's reach: `heated` ties shared it, `divided` of
    /// them were divided.
    Ties { heated: u32, divided: u32 },
    /// An organ's wall (no ties within reach): a non-target burn.
    Wall(WallSample),
    /// Nothing: the hook touched no tissue.
    Air,
}

/// A burn on an organ's wall in one tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallSample {
    /// The organ, bit `k`'s organ of [`Sample::touching`].
    pub organ: usize,
    /// The mark burned, in the scene's list of marks...
    pub mark: usize,
    /// ...a mark of its own (not one deepened), and its area (m²).
    pub new_mark: bool,
    pub area_m2: f64,
    /// The wall gave way in this tick: a hollow organ perforated (`hollow`), a solid one's
    /// capsule burned through.
    pub through_now: bool,
    pub hollow: bool,
}

/// One hand's part of a tick's sample: its tool and force, what it touches and holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HandSample {
    pub tip_m: Option<Vector3<f64>>,
    /// The force sent to the hand's device (N).
    pub force_n: f64,
    /// Bit `k` for the scenario's `organs[k]`, as in [`Sample::touching`].
    pub touching: u64,
    pub grasping: u64,
    pub button: bool,
    pub instrument: usize,
    pub tip_in_view: Option<bool>,
}

impl HandSample {
    /// Whether the hand's tool is on tissue: touching or holding it.
    pub fn working(&self) -> bool {
        self.touching != 0 || self.grasping != 0
    }

    /// Whether the hand holds the scenario's `organ`-th organ: in its jaws or under its tool.
    pub fn holds(&self, organ: usize) -> bool {
        organ < 64 && (self.touching | self.grasping) & (1 << organ) != 0
    }
}

impl Sample {
    /// The right hand's part of the sample (the only hand of a one-hand exercise).
    pub fn right(&self) -> HandSample {
        HandSample {
            tip_m: self.tip_m,
            force_n: self.force_n,
            touching: self.touching,
            grasping: self.grasping,
            button: self.button,
            instrument: self.instrument,
            tip_in_view: self.tip_in_view,
        }
    }

    /// The sample as the left hand's task sees it: the left hand's tool, force, touch and
    /// hold in place of the right's (the right hand's, if there is no left).
    pub fn of_left_hand(&self) -> Sample {
        let Some(left) = self.left else {
            return *self;
        };
        Sample {
            tip_m: left.tip_m,
            force_n: left.force_n,
            touching: left.touching,
            grasping: left.grasping,
            button: left.button,
            instrument: left.instrument,
            tip_in_view: left.tip_in_view,
            left: Some(self.right()),
            ..*self
        }
    }

    pub fn touches(&self, organ: usize) -> bool {
        organ < 64 && self.touching & (1 << organ) != 0
    }

    pub fn grasps(&self, organ: usize) -> bool {
        organ < 64 && self.grasping & (1 << organ) != 0
    }
}

/// Where a nodule of the scenario lies: its centre, and the outward normal of the organ's
/// surface nearest to it, along which a mark right above it lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoduleSite {
    pub centre_m: Vector3<f64>,
    pub outward: Vector3<f64>,
}

impl NoduleSite {
    /// How far (m) `point_m` is from the nodule across the surface: its distance from the
    /// line through the centre along the outward normal, so that depth does not count.
    pub fn lateral_distance_m(&self, point_m: &Vector3<f64>) -> f64 {
        let offset = point_m - self.centre_m;
        (offset - self.outward * offset.dot(&self.outward)).norm()
    }
}

/// Where a retraction task's region lies: the surface point of its organ (the scene's
/// `organ`-th) nearest the scenario's point, and the unit direction it is to move in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionSite {
    pub organ: usize,
    pub at: SurfacePoint,
    pub towards: Vector3<f64>,
}
