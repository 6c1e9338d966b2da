//! What the render side sees of the haptic world: the latest complete tick, through a
//! triple buffer (wait-free on both sides: the haptic thread never blocks on a frame, and a
//! frame never sees half a tick).

use bevy::prelude::*;
use nalgebra::Vector3;

use super::biliary::Biliary;
use crate::biliary::{FatStrand, Fluid, Structure};
use crate::contact::ToolContact;
use crate::cutting::Stroke;
use crate::devices::{MAX_INSTRUMENTS, Rack};
use crate::dissection::{BurnMark, MAX_BURN_MARKS, TieEnds, TiedOrgans};
use crate::pgd::{Deformation, SurfacePoint};
use crate::scenario::Progress;
use crate::scenario::ViewSample;

#[derive(Clone, Debug, Default)]
pub struct OrganSnapshot {
    pub deformation: Deformation,
    pub contact: Option<ToolContact>,
    /// A moving organ's kept modes' correction to the static field (empty when it does not
    /// move): the window adds the modes times these to the deformed surface.
    pub motion: Vec<f64>,
    /// Whether the grasper's jaws hold it.
    pub grasped: bool,
    /// The scalpel's strokes on it, the one under way last.
    pub strokes: Vec<Stroke>,
}

#[derive(Clone, Debug, Default)]
pub struct HapticSnapshot {
    pub tick: u64,
    pub time_s: f64,
    /// Each of the trainee's hands' instrument and force, by hand index (the right hand
    /// first).
    pub hands: Vec<HandSnapshot>,
    /// The assistant's instrument, where the scene has one.
    pub assistant: Option<HandSnapshot>,
    /// In the scene's organ order.
    pub organs: Vec<OrganSnapshot>,
    /// How the real-time loop has kept time so far (refreshed once a second).
    pub timing: LoopTiming,
    /// Where the scenario's exercise stands, once started.
    pub exercise: Option<Progress>,
    /// Each bed's ties, in the scene's order of beds.
    pub beds: Vec<BedView>,
    /// The burns the hook left on the organs' walls.
    pub burns: BurnsView,
    /// The ducts, the artery, the triangle's fat, the clips and what the open stumps let out.
    pub biliary: Option<BiliaryView>,
}

/// The biliary tree as the window draws it, with room for every clip and stump the tree
/// keeps (so that the loop allocates nothing).
#[derive(Clone, Debug, Default)]
pub struct BiliaryView {
    pub tubes: Vec<TubeView>,
    pub fat: Vec<FatStrand>,
    pub clips: Vec<ClipView>,
    pub leaks: Vec<LeakView>,
    /// The critical view of safety as last judged.
    pub view: ViewSample,
}

/// A tube where it is: its nodes (m), which of its segments are divided, its outer radius.
#[derive(Clone, Debug)]
pub struct TubeView {
    pub structure: Structure,
    pub nodes_m: Vec<Vector3<f64>>,
    pub divided: Vec<bool>,
    pub radius_m: f64,
}

/// A clip where it is: on its tube's axis, the tube's direction there and its radius.
#[derive(Clone, Copy, Debug)]
pub struct ClipView {
    pub at_m: Vector3<f64>,
    pub along: Vector3<f64>,
    pub radius_m: f64,
    pub closes: bool,
}

/// An open stump: where it is, what it lets out and how much it has (m³).
#[derive(Clone, Copy, Debug)]
pub struct LeakView {
    pub at_m: Vector3<f64>,
    pub fluid: Fluid,
    pub lost_m3: f64,
    pub stopped: bool,
}

impl BiliaryView {
    /// `biliary` as it stands, with room for all it may come to hold.
    pub fn of(biliary: &Biliary) -> Self {
        let tree = biliary.tree();
        let mut view = Self {
            tubes: (tree.tubes.iter())
                .map(|tube| TubeView {
                    structure: tube.structure,
                    nodes_m: tube.rod.positions.clone(),
                    divided: vec![false; tube.rod.nodes() - 1],
                    radius_m: tube.section.outer_radius_m,
                })
                .collect(),
            fat: tree.fat.strands.clone(),
            clips: Vec::with_capacity(biliary.room().clips),
            leaks: Vec::with_capacity(biliary.room().leaks),
            view: ViewSample::default(),
        };
        view.update(biliary);
        view
    }

    /// The tree as `biliary` stands this tick.
    pub fn update(&mut self, biliary: &Biliary) {
        let tree = biliary.tree();
        for (view, tube) in self.tubes.iter_mut().zip(&tree.tubes) {
            view.nodes_m.copy_from_slice(&tube.rod.positions);
            for (segment, divided) in view.divided.iter_mut().enumerate() {
                *divided = tube.rod.is_divided(segment);
            }
        }
        self.fat.copy_from_slice(&tree.fat.strands);
        self.clips.clear();
        self.clips.extend(biliary.clips().iter().map(|clip| {
            let tube = tree.tube(clip.structure);
            let at = clip.arc_length_m;
            let along = tube.point_at(at + 1e-4) - tube.point_at(at - 1e-4);
            ClipView {
                at_m: clip.position_m(tree),
                along: along.try_normalize(1e-12).unwrap_or_else(Vector3::x),
                radius_m: tube.section.outer_radius_m,
                closes: clip.closes_lumen(),
            }
        }));
        self.leaks.clear();
        self.leaks
            .extend(biliary.leaks().iter().map(|leak| LeakView {
                at_m: tree.tube(leak.structure).point_at(leak.arc_length_m),
                fluid: leak.fluid,
                lost_m3: leak.lost_m3,
                stopped: leak.stopped,
            }));
        self.view = biliary.sample.view;
    }
}

/// A bed's ties as the window draws them, in the bed's order.
#[derive(Clone, Debug, Default)]
pub struct BedView {
    pub ties: Vec<TieView>,
}

impl BedView {
    /// The bed's ties where it stands (at rest before the first tick).
    pub fn at_rest(bed: &TiedOrgans) -> Self {
        let mut view = Self {
            ties: vec![TieView::default(); bed.bed.ties.len()],
        };
        view.update(bed);
        view
    }

    /// The ties as `bed` stands this tick.
    pub fn update(&mut self, bed: &TiedOrgans) {
        let law = &bed.bed.law;
        let ties = bed.bed.ties.iter().zip(bed.ends_m());
        for (view, (tie, ends)) in self.ties.iter_mut().zip(ties) {
            *view = TieView {
                ends: *ends,
                damage: tie.state.damage(law),
                failed: tie.state.failed(law),
            };
        }
    }
}

/// A tie as the window draws it.
#[derive(Clone, Copy, Debug, Default)]
pub struct TieView {
    pub ends: TieEnds,
    /// Its damage, 0 whole to 1.
    pub damage: f64,
    /// Divided by the hook or torn.
    pub failed: bool,
}

/// The burn marks, in room for every mark the scene keeps (so the loop allocates nothing).
#[derive(Clone, Debug, Default)]
pub struct BurnsView {
    room: Vec<BurnMark>,
    count: usize,
}

impl BurnsView {
    /// No marks, with room for [`MAX_BURN_MARKS`].
    pub fn with_room() -> Self {
        let unburned = BurnMark {
            organ: 0,
            at: SurfacePoint {
                triangle: 0,
                barycentric: [1.0, 0.0, 0.0],
            },
            at_rest_m: Vector3::zeros(),
            area_m2: 0.0,
            energy_j: 0.0,
            depth_m: 0.0,
            through: false,
        };
        Self {
            room: vec![unburned; MAX_BURN_MARKS],
            count: 0,
        }
    }

    pub fn marks(&self) -> &[BurnMark] {
        &self.room[..self.count]
    }

    /// The marks `marks` (as many as there is room for).
    pub fn set(&mut self, marks: &[BurnMark]) {
        self.count = marks.len().min(self.room.len());
        self.room[..self.count].copy_from_slice(&marks[..self.count]);
    }
}

impl HapticSnapshot {
    /// The first hand's (the only one of a one-hand scene); a snapshot has one at least.
    pub fn first_hand(&self) -> &HandSnapshot {
        &self.hands[0]
    }
}

/// A hand's instrument and force, as the window draws them.
#[derive(Clone, Debug, Default)]
pub struct HandSnapshot {
    /// The tool tip (m), once the device has reported one.
    pub tip_m: Option<Vector3<f64>>,
    /// Through a port, the instrument's handle (m): its shaft runs from there through the
    /// port to the tip.
    pub handle_m: Option<Vector3<f64>>,
    /// Which instrument is in hand, and where the others were put down.
    pub instruments: InstrumentsView,
    /// The force sent to the device (N).
    pub force_n: Vector3<f64>,
    /// The scalpel's edge (unit, the scene's frame) when the tool is a scalpel.
    pub blade_edge: Option<Vector3<f64>>,
    /// With a hook in hand: whether its energy is on (the button held).
    pub cautery: Option<bool>,
    /// Whether the force is faded or held after a fault.
    pub faulted: bool,
    /// The organs the hand's tool touches (bit `k` for the scene's `k`th)...
    pub touching: u64,
    /// ...and the one its grasper's jaws hold, if any.
    pub holding: Option<usize>,
}

/// The instruments as the window draws and drives them (fixed-size: the loop allocates nothing).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InstrumentsView {
    /// The instrument in hand, in the scenario's order.
    pub in_hand: usize,
    /// Added to the device's position to place the handle in hand (m); the mouse, which places
    /// the tip, takes it off again.
    pub offset_m: Vector3<f64>,
    /// Where each instrument not in hand was put down (its handle, m).
    pub put_down: [Option<Vector3<f64>>; MAX_INSTRUMENTS],
}

impl InstrumentsView {
    pub fn of(rack: &Rack) -> Self {
        Self {
            in_hand: rack.in_hand().0,
            offset_m: rack.offset_m(),
            put_down: std::array::from_fn(|index| rack.put_down(index)),
        }
    }
}

/// How often the loop hands its timing to the snapshots: quantiles scan the histogram (tens of
/// µs), so once a second.
pub(super) const TIMING_EVERY_TICKS: u64 = 1000;

/// The real-time loop's timing so far, for the HUD (µs).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct LoopTiming {
    pub compute_p99_us: f64,
    pub lateness_p99_us: f64,
    pub skipped: u64,
}

/// The haptic thread's end of the triple buffer.
#[derive(Resource)]
pub struct SnapshotPublisher(pub triple_buffer::Input<HapticSnapshot>);
