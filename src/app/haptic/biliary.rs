//! The biliary tree in the tick, after the organs' contact and the hook: the tubes' ends
//! follow the gallbladder they enter; each hand's instrument pushes the tubes it touches (a
//! grasper holds the node its jaws close on), closes a clip or divides a tube when its button
//! goes down, burns or tears the triangle's fat and coagulates an open stump; the rods settle;
//! the open stumps let out what they do; and a few times a second the critical view of safety
//! is judged from the laparoscope. What the tick did is [`Biliary::sample`], which scoring
//! reads; what the tubes push the hands with is [`Biliary::push_n`].

use bevy::prelude::*;
use nalgebra::Vector3;

use super::components::{OrganBody, OrganDeformation, OrganIndex, OrganMotion};
use super::hand::{HandIndex, MAX_HANDS, Tool};
use super::resources::{OrganBeds, Scope};
use crate::biliary::critical_view::{LowerThird, lower_third_released};
use crate::biliary::{
    BiliaryTree, Clip, CriticalView, CriticalViewRule, Division, Fluid, Judging, Leak, OrganPatch,
    Segment, Structure, ViewRecord,
};
use crate::devices::{Action, DeviceSample, TICK_S};
use crate::dissection::{CauteryMode, TiedOrgans};
use crate::mesh::organs::{Abdomen, OrganSettings};
use crate::parry_interop::SightBlockers;
use crate::pgd::{SurfacePoint, Vademecum};
use crate::scenario::{BiliarySample, ViewSample};

/// A scene's biliary tree at rest, and what its critical view of safety asks.
#[derive(Clone, Debug)]
pub struct SceneBiliary {
    pub tree: BiliaryTree,
    pub rule: CriticalViewRule,
}

/// The critical view is judged once every this many ticks (20 times a second).
const JUDGE_EVERY: u64 = 50;
/// A settled rod's forces left (N), and the Newton steps a rod may take a tick: where they are
/// not enough, it settles on over the next ticks.
const SETTLED_N: f64 = 1e-6;
const STEPS_PER_TICK: usize = 3;
/// The most clips, divisions and open stumps a tree keeps (room reserved at the start).
const ROOM: usize = 32;
/// Where the optic is taken to be without a laparoscope: in front of the triangle (m).
const OPEN_VIEW_M: [f64; 3] = [0.0, 0.2, -0.1];

/// Where a tube's end enters the gallbladder: the surface point nearest it at rest.
#[derive(Clone, Copy, Debug)]
struct Anchor {
    at: SurfacePoint,
    rest_m: Vector3<f64>,
}

/// How many clips and open stumps a tree keeps at most.
#[derive(Clone, Copy, Debug)]
pub struct Room {
    pub clips: usize,
    pub leaks: usize,
}

/// A tube's node an instrument holds this tick: pushed aside by its tip, or in its jaws.
#[derive(Clone, Copy, Debug, PartialEq)]
struct HeldNode {
    hand: usize,
    tube: usize,
    node: usize,
}

/// The biliary tree in the haptic world, with its clips, divisions and open stumps.
#[derive(Resource)]
pub struct Biliary {
    tree: BiliaryTree,
    /// The tree at rest, which a new attempt starts from.
    at_rest: BiliaryTree,
    rule: CriticalViewRule,
    /// The gallbladder's place among the organs, and each tube's end on it, found in the
    /// first tick (the organs' surfaces are the haptic world's).
    gallbladder: Option<usize>,
    anchors: [Option<Anchor>; 3],
    anchored: bool,
    /// The organs at rest, for the sight lines to the optic.
    occluders: SightBlockers,
    /// How far each organ (in the scene's order) has moved where the tubes enter it: the
    /// gallbladder's is the mean of its anchors' displacements, the others' none. Sight lines
    /// meet the organs' surfaces at rest moved by these.
    organ_shifts_m: Vec<Vector3<f64>>,
    lower_third: LowerThird,
    clips: Vec<Clip>,
    divisions: Vec<Division>,
    leaks: Vec<Leak>,
    held: Vec<HeldNode>,
    /// Each hand's jaws' node, while its grasper holds a tube.
    grasped: [Option<HeldNode>; MAX_HANDS],
    button_was_down: [bool; MAX_HANDS],
    push_n: [Vector3<f64>; MAX_HANDS],
    /// The critical view as judged last, from where, and whether that was this tick.
    judged: Option<(CriticalView, Vector3<f64>)>,
    judged_now: bool,
    pub sample: BiliarySample,
}

impl Biliary {
    /// The tree of `scene`, among `organs` (the scene's, in order), ticked by `hands` hands.
    pub fn new(scene: &SceneBiliary, organs: &[(String, std::sync::Arc<Vademecum>)]) -> Self {
        let occluders = SightBlockers::new(
            (organs.iter()).map(|(_, v)| (&v.position_coords_m[..], &v.triangles[..])),
        );
        let nodes: usize = scene.tree.tubes.iter().map(|t| t.rod.nodes()).sum();
        Self {
            tree: scene.tree.clone(),
            at_rest: scene.tree.clone(),
            rule: scene.rule,
            gallbladder: organs.iter().position(|(name, _)| name == "gallbladder"),
            anchors: [None; 3],
            anchored: false,
            occluders,
            organ_shifts_m: vec![Vector3::zeros(); organs.len()],
            lower_third: lower_third(),
            clips: Vec::with_capacity(ROOM),
            divisions: Vec::with_capacity(ROOM),
            leaks: Vec::with_capacity(2 * ROOM),
            held: Vec::with_capacity(nodes),
            grasped: [None; MAX_HANDS],
            button_was_down: [false; MAX_HANDS],
            push_n: [Vector3::zeros(); MAX_HANDS],
            judged: None,
            judged_now: false,
            sample: BiliarySample::default(),
        }
    }

    /// Back to the tree at rest, without a clip, a cut or a strand of fat cleared, and
    /// without allocating: a new attempt.
    pub fn heal(&mut self) {
        for (tube, rest) in self.tree.tubes.iter_mut().zip(&self.at_rest.tubes) {
            tube.rod.restore(&rest.rod);
        }
        self.tree
            .fat
            .strands
            .copy_from_slice(&self.at_rest.fat.strands);
        self.clips.clear();
        self.divisions.clear();
        self.leaks.clear();
        self.held.clear();
        self.organ_shifts_m.fill(Vector3::zeros());
        self.grasped = [None; MAX_HANDS];
        self.push_n = [Vector3::zeros(); MAX_HANDS];
        self.judged = None;
        self.judged_now = false;
        self.sample = BiliarySample::default();
    }

    /// How many clips and open stumps it keeps at most.
    pub fn room(&self) -> Room {
        Room {
            clips: self.clips.capacity(),
            leaks: self.leaks.capacity(),
        }
    }

    pub fn tree(&self) -> &BiliaryTree {
        &self.tree
    }

    pub fn clips(&self) -> &[Clip] {
        &self.clips
    }

    pub fn leaks(&self) -> &[Leak] {
        &self.leaks
    }

    /// What the tubes push hand `hand`'s tip with this tick (N).
    pub fn push_n(&self, hand: usize) -> Vector3<f64> {
        self.push_n.get(hand).copied().unwrap_or_default()
    }

    /// Finds each tube's end on the gallbladder, once.
    fn anchor(&mut self, organs: &Query<OrganState>) {
        if self.anchored {
            return;
        }
        self.anchored = true;
        let Some(body) = self.gallbladder_body(organs) else {
            return;
        };
        for (tube, anchor) in self.tree.tubes.iter().zip(&mut self.anchors) {
            if !tube.enters_gallbladder {
                continue;
            }
            let end = tube.rod.positions[tube.rod.nodes() - 1];
            *anchor = body.surface.closest(&end).map(|hit| Anchor {
                at: hit.at,
                rest_m: end,
            });
        }
    }

    fn gallbladder_body<'a>(&self, organs: &'a Query<OrganState>) -> Option<&'a OrganBody> {
        let index = self.gallbladder?;
        organs.iter().find(|o| o.0.0 == index).map(|o| o.1)
    }

    /// Moves the tubes' ends on the gallbladder with it.
    fn follow_gallbladder(&mut self, organs: &Query<OrganState>) {
        let Some(index) = self.gallbladder else {
            return;
        };
        let Some((_, body, deformation, motion)) = organs.iter().find(|o| o.0.0 == index) else {
            return;
        };
        let moved = motion.map_or(&[][..], |m| &m.in_vademecum_modes[..]);
        let (mut shift, mut anchored) = (Vector3::zeros(), 0.0);
        for (tube, anchor) in self.tree.tubes.iter_mut().zip(&self.anchors) {
            let Some(anchor) = anchor else { continue };
            let u = deformation.0.displacement(&body.vademecum, &anchor.at)
                + moved_at(&body.vademecum, &anchor.at, moved);
            let last = tube.rod.nodes() - 1;
            tube.rod.positions[last] = anchor.rest_m + u;
            shift += u;
            anchored += 1.0;
        }
        if anchored > 0.0 {
            self.organ_shifts_m[index] = shift / anchored;
        }
    }

    /// Lets go of what the instruments pushed last tick.
    fn release_pushed(&mut self) {
        for held in self.held.drain(..) {
            self.tree.tubes[held.tube].rod.release(held.node);
        }
    }

    /// Hand `hand`'s instrument at `tip` this tick: what its button does, the tubes it
    /// pushes aside and the one its jaws hold.
    fn hand(&mut self, hand: usize, tool: &Tool, sample: &DeviceSample) {
        let down = sample.buttons & 1 != 0;
        let pressed = down && !self.button_was_down[hand];
        self.button_was_down[hand] = down;
        let tip = sample.tip_m;
        let radius = tool.probe.tip_radius_m;
        // Along the shaft through a port; in open surgery, whose tool has no shaft, downwards.
        let along = tool.pose.map_or(-Vector3::z(), |p| p.along);
        // Jaws and blades reach on beyond the instrument's tip, from their hinge at its
        // surface.
        let ahead = |length_m: f64| {
            let hinge = tip + along * radius;
            Segment::new(hinge, hinge + along * length_m)
        };
        match tool.action() {
            Action::Clip { jaw_m } if pressed => self.clip(&ahead(jaw_m)),
            Action::Divide { blade_m } if pressed => self.divide(&ahead(blade_m)),
            Action::Cauterize(hook) if down => {
                let reach = radius + 0.5 * hook.mode.zone_width_m();
                (self.tree.fat).heat(tip, reach, hook.energy_j(TICK_S), hook.mode);
                if hook.mode == CauteryMode::Coagulate {
                    self.coagulate(&tip, reach);
                }
            }
            Action::Grasp if pressed => {
                self.tree.fat.tear_within(tip, radius);
                self.grasped[hand] = self.nearest_node(hand, &tip, radius);
            }
            _ => {}
        }
        if !down {
            self.grasped[hand] = None;
        }
        if let Some(jaws) = self.grasped[hand] {
            self.hold(jaws, tip);
        }
        // A clip applier's and scissors' open jaws straddle the tube rather than push it.
        if !matches!(tool.action(), Action::Clip { .. } | Action::Divide { .. }) {
            self.push_aside(hand, &tip, radius);
        }
    }

    fn clip(&mut self, jaws: &Segment) {
        let Some(clip) = Clip::place(&self.tree, jaws) else {
            return;
        };
        if clip.closes_lumen() {
            (self.leaks.iter_mut())
                .filter(|l| l.stump_holds(clip.structure, clip.arc_length_m))
                .for_each(Leak::stop);
        }
        if self.clips.len() < ROOM {
            self.clips.push(clip);
        }
        self.sample.clip = Some(clip);
    }

    fn divide(&mut self, blades: &Segment) {
        let Some((division, open)) = Division::cut(&self.tree, &self.clips, blades) else {
            return;
        };
        let tube = self.tree.tube_mut(division.structure);
        let segment = (division.arc_length_m / tube.rod.segment_m()) as usize;
        let segment = segment.min(tube.rod.nodes() - 2);
        if tube.rod.is_divided(segment) {
            return;
        }
        tube.rod.divide(segment).expect("a segment of the rod");
        let room = 2 * ROOM - self.leaks.len();
        self.leaks.extend(open.into_iter().flatten().take(room));
        if self.divisions.len() < ROOM {
            self.divisions.push(division);
        }
        self.sample.division = Some(division);
    }

    /// Stops the open stumps within `reach` of `tip`.
    fn coagulate(&mut self, tip: &Vector3<f64>, reach: f64) {
        for leak in self.leaks.iter_mut().filter(|l| !l.stopped) {
            let tube = self.tree.tube(leak.structure);
            if (tube.point_at(leak.arc_length_m) - tip).norm()
                <= reach + tube.section.outer_radius_m
            {
                leak.stop();
            }
        }
    }

    /// The free node nearest `tip` within its reach, for jaws closing there.
    fn nearest_node(&self, hand: usize, tip: &Vector3<f64>, radius: f64) -> Option<HeldNode> {
        let mut best: Option<(f64, HeldNode)> = None;
        for (t, tube) in self.tree.tubes.iter().enumerate() {
            for (node, p) in tube.rod.positions.iter().enumerate() {
                let distance = (p - tip).norm();
                let free = !tube.rod.is_held(node);
                if free
                    && distance <= radius + tube.section.outer_radius_m
                    && best.is_none_or(|(d, _)| distance < d)
                {
                    best = Some((
                        distance,
                        HeldNode {
                            hand,
                            tube: t,
                            node,
                        },
                    ));
                }
            }
        }
        best.map(|(_, held)| held)
    }

    /// Holds `held`'s node at `at_m` for this tick.
    fn hold(&mut self, held: HeldNode, at_m: Vector3<f64>) {
        let rod = &mut self.tree.tubes[held.tube].rod;
        if rod.is_held(held.node) {
            return;
        }
        rod.positions[held.node] = at_m;
        rod.hold(held.node).expect("a node of the rod");
        self.held.push(held);
    }

    /// Moves the free nodes inside hand `hand`'s tip to its surface and holds them there for
    /// this tick.
    fn push_aside(&mut self, hand: usize, tip: &Vector3<f64>, radius: f64) {
        for tube in 0..self.tree.tubes.len() {
            let (nodes, reach) = {
                let t = &self.tree.tubes[tube];
                (t.rod.nodes(), radius + t.section.outer_radius_m)
            };
            for node in 0..nodes {
                let p = self.tree.tubes[tube].rod.positions[node];
                let out = p - tip;
                let distance = out.norm();
                if distance >= reach || self.tree.tubes[tube].rod.is_held(node) {
                    continue;
                }
                let away = out.try_normalize(1e-12).unwrap_or_else(Vector3::x);
                self.hold(HeldNode { hand, tube, node }, tip + away * reach);
            }
        }
    }

    /// Settles each rod, the common duct first so that the cystic duct's junction follows
    /// it, and totals what the held nodes push each hand with.
    fn settle(&mut self) {
        let junction = self.tree.junction_node;
        let order = [
            Structure::CommonDuct,
            Structure::CysticDuct,
            Structure::CysticArtery,
        ];
        for structure in order {
            if structure == Structure::CysticDuct {
                let at = self.tree.tube(Structure::CommonDuct).rod.positions[junction];
                self.tree.tube_mut(Structure::CysticDuct).rod.positions[0] = at;
            }
            // A rod that could not take a step keeps its shape; the next tick tries again.
            let _ = (self.tree.tube_mut(structure).rod).step(&[], SETTLED_N, STEPS_PER_TICK);
        }
        self.follow_ducts_with_fat();
        self.push_n = [Vector3::zeros(); MAX_HANDS];
        for held in &self.held {
            let forces = self.tree.tubes[held.tube].rod.node_forces_n();
            if let Some(f) = forces.get(held.node) {
                self.push_n[held.hand] -= f;
            }
        }
    }

    /// Moves the triangle's fat as its corners (the junction, the cystic duct's end and the
    /// hilum) have moved from rest.
    fn follow_ducts_with_fat(&mut self) {
        let moved = |structure: Structure, node: Option<usize>| {
            let (now, rest) = (
                &self.tree.tube(structure).rod,
                &self.at_rest.tube(structure).rod,
            );
            let node = node.unwrap_or(rest.nodes() - 1);
            now.positions[node] - rest.positions[node]
        };
        let corners = [
            moved(Structure::CysticDuct, Some(0)),
            moved(Structure::CysticDuct, None),
            moved(Structure::CommonDuct, Some(0)),
        ];
        self.tree.fat.follow(&self.at_rest.fat, corners);
    }

    fn bleed(&mut self) {
        let (mut blood, mut bile) = (0.0, 0.0);
        for leak in &mut self.leaks {
            leak.advance(TICK_S);
            match leak.fluid {
                Fluid::Blood => blood += leak.lost_m3,
                Fluid::Bile => bile += leak.lost_m3,
            }
        }
        self.sample.blood_lost_m3 = blood;
        self.sample.bile_spilled_m3 = bile;
        self.sample.bleeding = (self.leaks.iter()).any(|l| l.fluid == Fluid::Blood && !l.stopped);
    }

    /// Judges the critical view from `optic_m`, the gallbladder's lower third as its bed in
    /// `beds` has been freed (all of it without a bed).
    fn judge(
        &mut self,
        optic_m: Vector3<f64>,
        beds: Option<&OrganBeds>,
        organs: &Query<OrganState>,
    ) {
        let lower_third = self.lower_third(beds, organs);
        let (occluders, shifts) = (&self.occluders, &self.organ_shifts_m[..]);
        // From just off the tube, so that the organ it enters does not count.
        const OFF_M: f64 = 2e-3;
        let organs_hide =
            |sight: &Segment| occluders.block(&sight.from_m, &sight.to_m, OFF_M, shifts);
        let view = CriticalView::judge(&self.tree, lower_third, optic_m, organs_hide, self.rule);
        self.judged = Some((view, optic_m));
        self.judged_now = true;
    }

    /// Keeps in `record` what the critical view was judged on this tick, at `time_s`
    /// (nothing on a tick it was not judged); `beds` hold the gallbladder's ties.
    pub fn keep_judging(&self, record: &mut ViewRecord, time_s: f64, beds: Option<&OrganBeds>) {
        let Some((view, optic_m)) = self.judged.as_ref().filter(|_| self.judged_now) else {
            return;
        };
        let bed = (self.gallbladder.zip(beds))
            .and_then(|(index, beds)| beds.0.iter().find(|b| b.freed_index() == index))
            .map(|tied| (&tied.bed, tied.ends_m()));
        record.keep(&Judging {
            time_s,
            optic_m: *optic_m,
            view,
            tree: &self.tree,
            clips: &self.clips,
            bed,
            organ_shifts_m: &self.organ_shifts_m,
        });
    }

    fn lower_third(&self, beds: Option<&OrganBeds>, organs: &Query<OrganState>) -> f64 {
        let (Some(index), Some(beds)) = (self.gallbladder, beds) else {
            return 1.0;
        };
        let Some(bed) = beds.0.iter().find(|b| b.freed_index() == index) else {
            return 1.0;
        };
        let Some(body) = self.gallbladder_body(organs) else {
            return 1.0;
        };
        lower_third_released(
            &bed.bed,
            &body.vademecum.position_coords_m,
            &self.lower_third,
        )
    }
}

/// The organs drawn around the triangle in the critical view's pictures, and how far from
/// its centre (m).
const PICTURED: [&str; 2] = ["gallbladder", "liver"];
const PICTURED_WITHIN_M: f64 = 0.05;

/// Room for what the critical view of `scene`'s tree is judged on, among `organs` (the
/// scene's, in order) some of which lie in `beds`, with the organs around it at rest.
pub fn view_record(
    scene: &SceneBiliary,
    organs: &[(String, std::sync::Arc<Vademecum>)],
    beds: &[TiedOrgans],
) -> ViewRecord {
    let tree = &scene.tree;
    let gallbladder = (organs.iter()).position(|(name, _)| name == "gallbladder");
    let lower_third_ties = gallbladder
        .and_then(|index| {
            let tied = beds.iter().find(|b| b.freed_index() == index)?;
            let coords = &organs[index].1.position_coords_m;
            Some(lower_third().tie_indices(&tied.bed, coords).collect())
        })
        .unwrap_or_default();
    let mut record = ViewRecord::new(tree, ROOM, lower_third_ties, Vec::new());
    let centre_m = record.centre_m();
    record.organs = (organs.iter().enumerate())
        .filter(|(_, (name, _))| PICTURED.contains(&name.as_str()))
        .map(|(k, (name, v))| {
            let (positions, triangles) = (&v.position_coords_m, &v.triangles);
            OrganPatch::near((name, k), positions, triangles, centre_m, PICTURED_WITHIN_M)
        })
        .collect();
    record
}

/// The generated gallbladder's lower third, whose release from its bed the critical view asks.
pub fn lower_third() -> LowerThird {
    LowerThird::of(&Abdomen::new(&OrganSettings::default()))
}

/// What an organ's motion adds at `at`: its modes' displacement there, `moved` the
/// coefficients it adds to the first load step's.
fn moved_at(vademecum: &Vademecum, at: &SurfacePoint, moved: &[f64]) -> Vector3<f64> {
    let corners = vademecum.triangles[at.triangle];
    let mut u = Vector3::zeros();
    for (mode, &c) in moved.iter().enumerate().filter(|(_, c)| **c != 0.0) {
        for (k, &corner) in corners.iter().enumerate() {
            let node = vademecum.positions[corner as usize] as usize;
            u += vademecum.mode_at_node(0, mode, node) * (c * at.barycentric[k]);
        }
    }
    u
}

type OrganState = (
    &'static OrganIndex,
    &'static OrganBody,
    &'static OrganDeformation,
    Option<&'static OrganMotion>,
);

/// The biliary tree's tick.
pub fn tick_biliary(
    clock: Res<super::TickClock>,
    mut biliary: ResMut<Biliary>,
    beds: Option<Res<OrganBeds>>,
    scope: Option<Res<Scope>>,
    hands: Query<(&HandIndex, &Tool)>,
    organs: Query<OrganState>,
) {
    let biliary = &mut *biliary;
    biliary.sample.clip = None;
    biliary.sample.division = None;
    biliary.judged_now = false;
    biliary.anchor(&organs);
    biliary.follow_gallbladder(&organs);
    biliary.release_pushed();
    for (hand, tool) in &hands {
        if let Some(sample) = tool.sample.filter(|_| hand.0 < MAX_HANDS) {
            biliary.hand(hand.0, tool, &sample);
        }
    }
    biliary.settle();
    biliary.bleed();
    if clock.tick.is_multiple_of(JUDGE_EVERY) {
        let optic = scope
            .as_ref()
            .map_or(Vector3::from(OPEN_VIEW_M), |s| s.rig.scope.eye_m(&s.pose));
        biliary.judge(optic, beds.as_deref(), &organs);
    }
    biliary.sample.view = (biliary.judged.as_ref())
        .map_or_else(ViewSample::default, |(view, _)| ViewSample::of(view));
}
