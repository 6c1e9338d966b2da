//! The systems of a haptic tick, one stage each, in [`super::HapticSet`] order.

use bevy::ecs::query::QueryData;
use bevy::prelude::*;
use nalgebra::Vector3;

use super::biliary::Biliary;
use super::cautery::OrganBurns;
use super::components::{
    HandTouches, OrganBody, OrganDeformation, OrganIndex, OrganMotion, ToolTouch,
};
use super::cutting::OrganCut;
use super::hand::{
    DeviceForce, FaultLog, ForceTrace, GraspForce, HandIndex, HandState, MAX_HANDS, Safety,
    TRAINEE_HANDS, Tool,
};
use super::resources::{OrganBeds, OrganCoupling, TickClock};
use super::snapshot::{HandSnapshot, InstrumentsView, LoopTiming, SnapshotPublisher};
use crate::contact::{Target, follow, press};
use crate::devices::{Action, Fault, Fulcrum};
use crate::dissection::TiedOrgans;
use crate::pgd::{Deformation, Patch, SurfacePoint};

/// Reads each hand's device into its [`Tool::hand`], mapped onto the scene. A non-finite
/// sample or a device error is a fault of that hand, whose tool keeps its last good position;
/// a streak of overrun ticks is a fault of every hand.
pub fn read_device(clock: Res<TickClock>, mut hands: Query<HandState>) {
    for hand in &mut hands {
        let faults = hand.faults.into_inner();
        faults.this_tick.clear();
        faults.this_tick.append(&mut faults.next_tick);
        let (Some(mut device), Some(safety)) = (hand.device, hand.safety) else {
            continue;
        };
        let tool = hand.tool.into_inner();
        match device.0.read(clock.time_s) {
            Ok(sample) if sample.is_finite() => tool.hand = Some(tool.workspace.to_scene(sample)),
            Ok(_) => faults.this_tick.push(Fault::NonFiniteDevice),
            Err(e) => faults.this_tick.push(Fault::Device(e.to_string())),
        }
        if clock.overruns_in_a_row >= safety.0.settings().overrun_streak {
            faults
                .this_tick
                .push(Fault::Overruns(clock.overruns_in_a_row));
        }
    }
}

/// A hand's change button puts the instrument in it down and takes up the next, while the one
/// in hand touches and holds nothing (so the hand feels no step of force).
pub fn change_instrument(
    mut tools: Query<(&HandIndex, &mut Tool)>,
    organs: Query<(&HandTouches, Option<&OrganMotion>)>,
) {
    for (hand, mut tool) in &mut tools {
        let Some(read) = tool.hand else {
            continue;
        };
        let free = || {
            organs.iter().all(|(touches, motion)| {
                let holds = motion.is_some_and(|m| m.organ.holding() && m.hand == hand.0);
                touches.0[hand.0].contact.is_none() && !holds
            })
        };
        let tip = tool.sample.map_or(read.tip_m, |s| s.tip_m);
        if tool.rack.take(read.buttons, &read.tip_m, &tip, free) {
            tool.pose = None;
        }
    }
}

/// Places each hand's instrument for its device's sample: its tip, or through a port, its
/// handle, the tip then where the shaft through the port puts it and the instrument along the
/// shaft, rolled as the hand rolls the handle (a handle on the port itself keeps the last pose).
pub fn place_instrument(mut tools: Query<&mut Tool>) {
    for mut tool in &mut tools {
        place(&mut tool);
    }
}

fn place(tool: &mut Tool) {
    let Some(mut sample) = tool.hand else {
        return;
    };
    sample.tip_m = tool.rack.handle_m(&sample.tip_m);
    if let Some(port) = tool.port() {
        match port.pose(&sample.tip_m) {
            Some(pose) => tool.pose = Some(pose),
            None if tool.pose.is_none() => return,
            None => {}
        }
        let pose = tool.pose.expect("set above");
        sample.tip_m = pose.tip_m;
        sample.orientation = Fulcrum::instrument_orientation(&pose, &sample.orientation);
    }
    tool.sample = Some(sample);
}

/// Presses each hand's tool into every organ it touches, on the surface as the organ's other
/// loads (the other hand's among them) have moved it, and sets the hand's load on the organ.
/// Every hand reads the others' loads as the last tick left them, and the new loads are set
/// once all have pressed: a hand's press on a cut organ is settled by the cut stage, after
/// this one, and a second hand must not read the first's unsettled press.
pub fn tool_contact(
    tools: Query<(&HandIndex, &Tool)>,
    mut organs: Query<(
        &OrganBody,
        &mut HandTouches,
        &mut OrganDeformation,
        Option<&OrganMotion>,
    )>,
) {
    for (hand, tool) in &tools {
        for (body, mut touches, deformation, motion) in &mut organs {
            let organ = PressedOrgan {
                body,
                deformation: &deformation.0,
                motion,
            };
            press_organ(hand.0, tool, &organ, &mut touches.0[hand.0]);
        }
    }
    for (_, mut touches, mut deformation, _) in &mut organs {
        let loads = deformation.0.loads.iter_mut();
        for (load, touch) in loads.zip(touches.0.iter_mut()) {
            std::mem::swap(load, &mut touch.next_load);
        }
    }
}

/// An organ as a tool presses it: its surface, its static field and, if it moves, its
/// motion (the surface the tool meets is where the window draws it).
struct PressedOrgan<'a> {
    body: &'a OrganBody,
    deformation: &'a Deformation,
    motion: Option<&'a OrganMotion>,
}

/// Hand `slot`'s tool pressed into one organ: its contact, and its load next. Jaws that hold
/// the organ, or are letting it go (the hand's force fading), press none of it: held, the
/// grasp stage sets their load; opening, they leave the tissue they held, which is where they
/// are.
fn press_organ(slot: usize, tool: &Tool, organ: &PressedOrgan, touch: &mut ToolTouch) {
    let jaws_on_it = (organ.motion)
        .is_some_and(|m| m.hand == slot && (m.organ.holding() || m.organ.releasing()));
    let Some(sample) = tool.sample.as_ref().filter(|_| !jaws_on_it) else {
        touch.next_load.release();
        touch.contact = None;
        return;
    };
    let (vademecum, deformation) = (&organ.body.vademecum, organ.deformation);
    let target = Target {
        vademecum,
        surface: &organ.body.surface,
        moved_by_others: |patch: &Patch| {
            let moved = organ
                .motion
                .map_or(Vector3::zeros(), |m| m.moved_at(&patch.blend));
            deformation.patch_displacement_without(vademecum, patch, slot) + moved
        },
        moved_by_all: |at: &SurfacePoint| {
            let moved =
                (organ.motion).map_or(Vector3::zeros(), |m| m.moved_at_point(vademecum, at));
            deformation.displacement(vademecum, at) + moved
        },
    };
    let previous = touch.contact.map(|contact| contact.hit.at);
    touch.contact = press(
        &target,
        &tool.probe,
        &sample.tip_m,
        previous.as_ref(),
        &mut touch.patch,
        &mut touch.next_load,
    );
}

/// One hand's grasper jaws this tick.
#[derive(Clone, Copy, Debug)]
struct Jaws {
    tip_m: Vector3<f64>,
    closed: bool,
    /// Closed this tick, open the last.
    closing: bool,
}

/// The graspers on the organs that move: pressing a hand's button closes its jaws on the
/// organ its tool touches (one organ a hand, one hand an organ), and every moving organ is
/// stepped, held or swinging back. While the jaws hold, the holding hand's load on the organ
/// is their pull at their patch (its static field the vademecum's, the kept modes' motion the
/// correction) and that hand feels the grasp, not a press. Jaws on an organ tied in a bed pull
/// the ties near them through its wall (`TiedOrgans::grip`), solved with the grasp.
pub fn grasp(
    mut was_closed: Local<[bool; MAX_HANDS]>,
    mut hands: Query<(&HandIndex, &Tool, &mut GraspForce, &mut FaultLog)>,
    mut organs: Query<MovingOrgan>,
    mut beds: Option<ResMut<OrganBeds>>,
) {
    let mut jaws = [None; MAX_HANDS];
    for (hand, tool, mut force, _) in &mut hands {
        force.0 = Vector3::zeros();
        let Some(sample) = tool.sample else {
            continue;
        };
        // Only a grasper's jaws close; an organ let go swings back whatever is in hand.
        let closed = sample.buttons & 1 != 0 && tool.action() == Action::Grasp;
        // Jaws close on tissue when the button goes down, not while it stays down: tissue
        // that escaped a closed grasper is not taken again until the trainee opens and
        // closes it.
        let closing = closed && !was_closed[hand.0];
        was_closed[hand.0] = closed;
        let tip_m = sample.tip_m;
        jaws[hand.0] = Some(Jaws {
            tip_m,
            closed,
            closing,
        });
    }
    for (slot, hand) in jaws.iter().enumerate() {
        if hand.is_some_and(|j| j.closing) {
            take_first(
                slot,
                &hand.expect("closing").tip_m,
                &mut organs,
                beds.as_deref_mut(),
            );
        }
    }
    for organ in &mut organs {
        let (mut touches, mut deformation) = (organ.touch, organ.deformation);
        let motion = &mut *organ.motion.into_inner();
        // An organ not held swings back whichever hand is read.
        let Some(hand) = jaws[motion.hand].or_else(|| jaws.iter().flatten().next().copied()) else {
            continue;
        };
        motion.tore = false;
        let mut bed = bed_of(beds.as_deref_mut(), organ.index.0);
        motion
            .organ
            .set_tether(bed.as_ref().and_then(|b| b.wall_tether()));
        match motion.organ.tick(&hand.tip_m, hand.closed) {
            Ok(outcome) => {
                match (bed.as_mut(), outcome.point_m) {
                    (Some(bed), Some(jaws_m)) => _ = bed.pull_wall(&jaws_m),
                    (Some(bed), None) => bed.let_go(),
                    (None, _) => {}
                }
                let holder = hands.iter_mut().find(|h| h.0.0 == motion.hand);
                if let Some((_, _, mut force, _)) = holder {
                    force.0 += outcome.hand_force_n;
                }
                motion.tore = outcome.damaged_now;
            }
            Err(e) => {
                let holder = hands.iter_mut().find(|h| h.0.0 == motion.hand);
                if let Some((_, _, _, mut faults)) = holder {
                    let fault = Fault::Physics(format!("{}: {e}", organ.body.name));
                    faults.this_tick.push(fault);
                }
            }
        }
        motion
            .organ
            .correction(&motion.model.basis.omega2, &mut motion.correction);
        motion
            .model
            .fit
            .coefficients_into(&motion.correction, &mut motion.in_vademecum_modes);
        if motion.organ.holding() {
            touches.0[motion.hand].contact = None;
            let load = &mut deformation.0.loads[motion.hand];
            load.shares.clone_from(&motion.shares);
            load.force_n = motion.organ.applied_n();
        }
    }
}

/// The bed that ties organ `index` to another, if any.
fn bed_of(beds: Option<&mut OrganBeds>, index: usize) -> Option<&mut TiedOrgans> {
    beds.and_then(|b| b.0.iter_mut().find(|bed| bed.freed_index() == index))
}

/// Hand `slot`'s jaws, closing at `tip_m`, take hold of the first free organ its tool touches,
/// unless they hold one already; the wall of an organ tied in a bed takes the ties near them.
fn take_first(
    slot: usize,
    tip_m: &Vector3<f64>,
    organs: &mut Query<MovingOrgan>,
    beds: Option<&mut OrganBeds>,
) {
    let holds = |m: &OrganMotion| m.organ.holding() && m.hand == slot;
    if organs.iter().any(|o| holds(o.motion)) {
        return;
    }
    let free = organs
        .iter_mut()
        .find(|o| !o.motion.organ.holding() && o.touch.0[slot].contact.is_some());
    if let Some(organ) = free {
        let motion = organ.motion.into_inner();
        take_hold(organ.body, &organ.touch.0[slot], motion, tip_m);
        motion.hand = slot;
        if let Some(bed) = bed_of(beds, organ.index.0) {
            let point = &motion.organ.point;
            bed.grip(&(point.rest_m + motion.organ.point_displacement()));
        }
    }
}

/// A moving organ as the grasp stage steps it.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct MovingOrgan {
    index: &'static OrganIndex,
    body: &'static OrganBody,
    touch: &'static mut HandTouches,
    deformation: &'static mut OrganDeformation,
    motion: &'static mut OrganMotion,
}

/// Closes the jaws on the patch the tool touches (its shares, its centre and the vademecum's
/// compliance there), starting from the press's force.
fn take_hold(body: &OrganBody, touch: &ToolTouch, motion: &mut OrganMotion, hand_m: &Vector3<f64>) {
    let vademecum = &body.vademecum;
    motion.patch_nodes.clone_from(&touch.patch.blend);
    let compliance = vademecum.compliance(&touch.patch, &Vector3::zeros());
    let centre = touch.contact.map_or(Vector3::zeros(), |c| c.hit.point_m);
    let basis = &motion.model.basis;
    (motion.organ.point).move_to(basis, &motion.patch_nodes, centre, &compliance);
    motion.shares.clone_from(&touch.patch.shares);
    let pressing = touch.contact.map_or(Vector3::zeros(), |c| c.force_n);
    motion.organ.close(hand_m, &pressing);
}

/// Sums every organ's loads into its modal coefficients.
pub fn evaluate_modes(mut organs: Query<(&OrganBody, &mut OrganDeformation)>) {
    for (body, mut deformation) in &mut organs {
        deformation.0.evaluate(&body.vademecum);
    }
}

/// Organ against organ: hands every organ's coefficients (a moving organ's motion included,
/// every hand's load in them) and the hold of the first hand that presses it to the coupling,
/// ticks its pairs and attachments, then the beds' ties, and gives each organ its coupling
/// loads and carry. The holding hand's load
/// follows the contact's push in the same tick, so the trainee feels the organ behind at
/// once; another hand's press on the same organ answers it next tick.
pub fn organ_contact(
    mut coupling: ResMut<OrganCoupling>,
    mut beds: Option<ResMut<OrganBeds>>,
    mut organs: Query<CoupledOrgan>,
) {
    let coupling = &mut coupling.0;
    for organ in &organs {
        let deformation = &organ.deformation.0;
        let moved = (organ.motion.as_ref()).map_or(&[][..], |m| &m.in_vademecum_modes[..]);
        coupling.read(organ.index.0, deformation, moved);
        let slot = organ.touch.pressing().unwrap_or(0);
        let contact = organ.touch.0[slot].contact.as_ref();
        coupling.hold(organ.index.0, contact, &deformation.loads[slot]);
    }
    coupling.tick();
    for bed in beds.iter_mut().flat_map(|b| b.0.iter_mut()) {
        bed.tick(coupling);
        restrain(bed, &mut organs);
    }
    for mut organ in &mut organs {
        let index = organ.index.0;
        let deformation = &mut organ.deformation.0;
        coupling.write(index, deformation);
        let Some(slot) = organ.touch.pressing() else {
            continue;
        };
        follow(
            &mut organ.touch.0[slot].contact,
            &mut deformation.loads[slot],
            &coupling.tool_moved_m(index),
        );
    }
}

/// Hands a bed's hold on its freed organ's kept modes to that organ's motion, if it moves.
fn restrain(bed: &TiedOrgans, organs: &mut Query<CoupledOrgan>) {
    let Some((freed, stiffness)) = bed.restraint() else {
        return;
    };
    let moving = organs.iter_mut().find(|o| o.index.0 == freed);
    if let Some(mut motion) = moving.and_then(|o| o.motion) {
        let motion = &mut *motion;
        (motion.organ).set_restraint(&motion.model.basis.omega2, stiffness);
    }
}

/// An organ as the organ/organ contact stage reads and loads it.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct CoupledOrgan {
    index: &'static OrganIndex,
    touch: &'static mut HandTouches,
    deformation: &'static mut OrganDeformation,
    motion: Option<&'static mut OrganMotion>,
}

/// The force on each hand's tool: the opposite of what it applies to the organs, and what the
/// biliary tree's tubes push it with; through a port, as the hand feels it through the
/// shaft's lever.
pub fn compute_force(
    mut hands: Query<(&HandIndex, &Tool, &GraspForce, &mut DeviceForce)>,
    touches: Query<&HandTouches>,
    biliary: Option<Res<Biliary>>,
) {
    for (hand, tool, grasp, mut force) in &mut hands {
        let pressed: Vector3<f64> = touches
            .iter()
            .filter_map(|t| t.0[hand.0].contact.map(|c| c.felt_n()))
            .sum();
        let tubes = biliary
            .as_ref()
            .map_or(Vector3::zeros(), |b| b.push_n(hand.0));
        let at_tip = grasp.0 - pressed + tubes;
        force.desired_n = match &tool.pose {
            Some(pose) => Fulcrum::hand_force(pose, &at_tip),
            None => at_tip,
        };
    }
}

/// Clamps, rate-limits and, on a fault, fades each hand's force; logs each fault as it starts
/// (a fault of the same kind as the hand's last logged one is counted, not logged again),
/// naming the hand when there are two. A fault of one hand fades that hand's force only.
pub fn apply_safety(clock: Res<TickClock>, mut hands: Query<HandState>) {
    let two_hands = hands.iter().len() > 1;
    for hand in &mut hands {
        let Some(mut safety) = hand.safety else {
            continue;
        };
        let (force, faults) = (hand.force.into_inner(), hand.faults.into_inner());
        if !force.desired_n.iter().all(|c| c.is_finite()) {
            faults.this_tick.push(Fault::NonFiniteForce);
        }
        force.sent_n = safety.0.filter(&force.desired_n, &faults.this_tick);
        if safety.0.refused_output() {
            faults.this_tick.push(Fault::NonFiniteOutput);
        }
        let name = two_hands.then(|| hand.index.name());
        log_faults(clock.tick, name, faults);
    }
}

/// Counts a faulted tick and logs the faults that start in it.
fn log_faults(tick: u64, hand: Option<&str>, faults: &mut FaultLog) {
    if faults.this_tick.is_empty() {
        return;
    }
    faults.faulted_ticks += 1;
    for fault in &faults.this_tick {
        let known = faults
            .log
            .last()
            .is_some_and(|(_, last)| std::mem::discriminant(last) == std::mem::discriminant(fault));
        if known {
            continue;
        }
        match hand {
            Some(hand) => warn!("haptic tick {tick}: {hand}: {fault}; fading its force"),
            None => warn!("haptic tick {tick}: {fault}; fading the force"),
        }
        faults.log.push((tick, fault.clone()));
    }
}

/// Sends each hand's force; a failed write is a fault of the hand's next tick.
pub fn write_device(mut hands: Query<HandState>) {
    for hand in &mut hands {
        let Some(mut device) = hand.device else {
            continue;
        };
        if let Err(e) = device.0.write_force(&hand.force.sent_n) {
            hand.faults
                .into_inner()
                .next_tick
                .push(Fault::Device(e.to_string()));
        }
    }
}

/// Keeps the tick's forces of each hand that keeps a trace.
pub fn trace_force(mut hands: Query<(&DeviceForce, &mut ForceTrace)>) {
    for (force, mut trace) in &mut hands {
        trace.desired_n.push(force.desired_n);
        trace.sent_n.push(force.sent_n);
    }
}

/// What the snapshot takes of an organ entity.
#[derive(QueryData)]
pub struct PublishedOrgan {
    index: &'static OrganIndex,
    touch: &'static HandTouches,
    deformation: &'static OrganDeformation,
    motion: Option<&'static OrganMotion>,
    cut: Option<&'static OrganCut>,
}

/// What the snapshot takes of a hand entity.
#[derive(QueryData)]
pub struct PublishedHand {
    index: &'static HandIndex,
    tool: &'static Tool,
    force: &'static DeviceForce,
    safety: Option<&'static Safety>,
}

/// Hands the render side the tick's state, when one is listening; never waits.
pub fn publish_snapshot(
    clock: Res<TickClock>,
    hands: Query<PublishedHand>,
    organs: Query<PublishedOrgan>,
    timing: Option<Res<LoopTiming>>,
    beds: Option<Res<OrganBeds>>,
    burns: Option<Res<OrganBurns>>,
    mut publisher: ResMut<SnapshotPublisher>,
) {
    let snapshot = publisher.0.input_buffer_mut();
    let beds = beds.as_ref().map_or(&[][..], |b| &b.0[..]);
    for (view, bed) in snapshot.beds.iter_mut().zip(beds) {
        view.update(bed);
    }
    if let Some(burns) = burns {
        snapshot.burns.set(burns.0.marks());
    }
    snapshot.tick = clock.tick;
    snapshot.time_s = clock.time_s;
    snapshot.timing = timing.map_or_else(LoopTiming::default, |t| *t);
    let cut_organs = organs.iter().any(|o| o.cut.is_some());
    for hand in &hands {
        let published = match hand.index.0 {
            TRAINEE_HANDS => snapshot.assistant.as_mut(),
            index => snapshot.hands.get_mut(index),
        };
        if let Some(published) = published {
            publish_hand(&hand, cut_organs, published);
        }
    }
    for published in &organs {
        let k = published.index.0;
        let organ = &mut snapshot.organs[k];
        let touching = published.touch.pressing();
        organ.contact = touching.and_then(|slot| published.touch.0[slot].contact);
        organ.deformation.clone_from(&published.deformation.0);
        if let Some(motion) = published.motion {
            organ.motion.clone_from(&motion.correction);
            organ.grasped = motion.organ.holding();
        }
        for (hand, touch) in snapshot.hands.iter_mut().zip(&published.touch.0) {
            let bit = 1u64.checked_shl(k as u32).unwrap_or(0);
            hand.touching = match touch.contact.is_some() {
                true => hand.touching | bit,
                false => hand.touching & !bit,
            };
        }
        if let Some(motion) = published.motion.filter(|m| m.organ.holding())
            && let Some(hand) = snapshot.hands.get_mut(motion.hand)
        {
            hand.holding = Some(k);
        }
        if let Some(cut) = published.cut {
            organ.strokes.clear();
            organ.strokes.extend_from_slice(cut.scalpel.strokes());
        }
    }
    publisher.0.publish();
}

/// Hands the biliary tree as it stands to the snapshot the tick publishes.
pub fn publish_biliary(biliary: Res<Biliary>, mut publisher: ResMut<SnapshotPublisher>) {
    if let Some(view) = publisher.0.input_buffer_mut().biliary.as_mut() {
        view.update(&biliary);
    }
}

/// A hand's instrument and force as the window draws them.
fn publish_hand(hand: &PublishedHandItem, cut_organs: bool, published: &mut HandSnapshot) {
    let tool = hand.tool;
    published.tip_m = tool.sample.map(|s| s.tip_m);
    published.handle_m = tool
        .port()
        .zip(tool.pose)
        .map(|(port, pose)| port.port_m - pose.along * pose.outside_m);
    published.instruments = InstrumentsView::of(&tool.rack);
    published.force_n = hand.force.sent_n;
    published.faulted = hand.safety.is_some_and(|s| s.0.is_faulted());
    // Found again with the organs.
    published.holding = None;
    published.cautery = match tool.action() {
        Action::Cauterize(_) => Some(tool.sample.is_some_and(|s| s.buttons & 1 != 0)),
        _ => None,
    };
    let cuts = cut_organs && tool.action() == Action::Cut;
    published.blade_edge = tool
        .sample
        .filter(|_| cuts)
        .map(|s| s.orientation * Vector3::x());
}
