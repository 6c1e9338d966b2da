//! The systems of a haptic tick, one stage each, in [`super::HapticSet`] order.

use bevy::ecs::query::QueryData;
use bevy::prelude::*;
use nalgebra::Vector3;

use super::components::{
    OrganBody, OrganDeformation, OrganIndex, OrganMotion, ToolTouch, patch_nodes,
};
use super::cutting::OrganCut;
use super::resources::{
    Device, DeviceForce, FaultLog, ForceTrace, GraspForce, OrganCoupling, Safety, TickClock, Tool,
};
use super::snapshot::{InstrumentsView, LoopTiming, SnapshotPublisher};
use crate::contact::{Target, follow, press};
use crate::devices::{Action, Fault, Fulcrum};
use crate::pgd::SurfacePoint;

/// Reads the device into [`Tool::hand`], mapped onto the scene. A non-finite sample or a
/// device error is a fault and the tool keeps its last good position; so is a streak of
/// overrun ticks.
pub fn read_device(
    clock: Res<TickClock>,
    safety: Res<Safety>,
    mut device: ResMut<Device>,
    mut tool: ResMut<Tool>,
    mut faults: ResMut<FaultLog>,
) {
    let faults = &mut *faults;
    faults.this_tick.clear();
    faults.this_tick.append(&mut faults.next_tick);
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

/// The device's change button puts the instrument in hand down and takes up the next, while
/// the one in hand touches and holds nothing (so the hand feels no step of force).
pub fn change_instrument(
    mut tool: ResMut<Tool>,
    touches: Query<&ToolTouch>,
    motions: Query<&OrganMotion>,
) {
    let Some(hand) = tool.hand else {
        return;
    };
    let free = || {
        touches.iter().all(|t| t.contact.is_none()) && motions.iter().all(|m| !m.organ.holding())
    };
    let tip = tool.sample.map_or(hand.tip_m, |s| s.tip_m);
    if tool.rack.take(hand.buttons, &hand.tip_m, &tip, free) {
        tool.pose = None;
    }
}

/// Places the instrument in hand for the device's sample: its tip, or through a port, its
/// handle, the tip then where the shaft through the port puts it and the instrument along the
/// shaft, rolled as the hand rolls the handle (a handle on the port itself keeps the last pose).
pub fn place_instrument(mut tool: ResMut<Tool>) {
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

/// Presses the tool into every organ it touches, on the surface as the organ's other loads have
/// moved it, and sets the organ's tool load.
pub fn tool_contact(
    tool: Res<Tool>,
    mut organs: Query<(&OrganBody, &mut ToolTouch, &mut OrganDeformation)>,
) {
    for (body, mut touch, mut deformation) in &mut organs {
        let Some(sample) = &tool.sample else {
            deformation.0.loads[OrganDeformation::TOOL].release();
            touch.contact = None;
            continue;
        };
        let deformation = &mut deformation.0;
        let touch = &mut *touch;
        let target = Target {
            vademecum: &body.vademecum,
            surface: &body.surface,
            moved_by_others: |position: usize| {
                let tool = OrganDeformation::TOOL;
                deformation.position_displacement_without(&body.vademecum, position, tool)
            },
            moved_by_all: |at: &SurfacePoint| deformation.displacement(&body.vademecum, at),
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
        std::mem::swap(
            &mut deformation.loads[OrganDeformation::TOOL],
            &mut touch.next_load,
        );
    }
}

/// The grasper on the organs that move: pressing the device's button closes the jaws on the
/// organ the tool touches (one at a time), and every moving organ is stepped, held or swinging back.
/// While the jaws hold, the organ's tool load is their pull at their patch (its static field
/// the vademecum's, the kept modes' motion the correction) and the hand feels the grasp, not
/// a press.
pub fn grasp(
    tool: Res<Tool>,
    mut was_closed: Local<bool>,
    mut grasp_force: ResMut<GraspForce>,
    mut faults: ResMut<FaultLog>,
    mut organs: Query<MovingOrgan>,
) {
    grasp_force.0 = Vector3::zeros();
    let Some(sample) = tool.sample else {
        return;
    };
    // Only a grasper's jaws close; an organ let go swings back whatever is in hand.
    let closed = sample.buttons & 1 != 0 && tool.action() == Action::Grasp;
    // Jaws close on tissue when the button goes down, not while it stays down: tissue that
    // escaped a closed grasper is not taken again until the trainee opens and closes it.
    let closing = closed && !*was_closed;
    *was_closed = closed;
    let mut held_elsewhere = organs.iter().any(|o| o.motion.organ.holding());
    for organ in &mut organs {
        let (mut touch, mut deformation) = (organ.touch, organ.deformation);
        let motion = &mut *organ.motion.into_inner();
        let holding = motion.organ.holding();
        let grasping = closing && !holding && !held_elsewhere && touch.contact.is_some();
        if grasping {
            take_hold(organ.body, &touch, motion, &sample.tip_m);
            held_elsewhere = true;
        }
        motion.tore = false;
        match motion.organ.tick(&sample.tip_m, closed) {
            Ok(outcome) => {
                grasp_force.0 += outcome.hand_force_n;
                motion.tore = outcome.damaged_now;
            }
            Err(e) => faults
                .this_tick
                .push(Fault::Physics(format!("{}: {e}", organ.body.name))),
        }
        motion
            .organ
            .correction(&motion.model.basis.omega2, &mut motion.correction);
        motion
            .model
            .fit
            .coefficients_into(&motion.correction, &mut motion.in_vademecum_modes);
        if motion.organ.holding() {
            touch.contact = None;
            let load = &mut deformation.0.loads[OrganDeformation::TOOL];
            load.shares.clone_from(&motion.shares);
            load.force_n = motion.organ.applied_n();
        }
    }
}

/// A moving organ as the grasp stage steps it.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct MovingOrgan {
    body: &'static OrganBody,
    touch: &'static mut ToolTouch,
    deformation: &'static mut OrganDeformation,
    motion: &'static mut OrganMotion,
}

/// Closes the jaws on the patch the tool touches (its shares, its centre and the vademecum's
/// compliance there), starting from the press's force.
fn take_hold(body: &OrganBody, touch: &ToolTouch, motion: &mut OrganMotion, hand_m: &Vector3<f64>) {
    let vademecum = &body.vademecum;
    patch_nodes(&touch.patch, vademecum, &mut motion.patch_nodes);
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

/// Organ against organ: hands every organ's coefficients (a moving organ's motion included)
/// and the tool's hold on it to the coupling, ticks its pairs and attachments, and gives each
/// organ its coupling loads and carry. The tool's load follows the contact's push in the same
/// tick, so the trainee feels the organ behind at once.
pub fn organ_contact(mut coupling: ResMut<OrganCoupling>, mut organs: Query<CoupledOrgan>) {
    let coupling = &mut coupling.0;
    for organ in &organs {
        let deformation = &organ.deformation.0;
        let moved = organ.motion.map_or(&[][..], |m| &m.in_vademecum_modes);
        coupling.read(organ.index.0, deformation, moved);
        let load = &deformation.loads[OrganDeformation::TOOL];
        coupling.hold(organ.index.0, organ.touch.contact.as_ref(), load);
    }
    coupling.tick();
    for mut organ in &mut organs {
        let index = organ.index.0;
        let deformation = &mut organ.deformation.0;
        coupling.write(index, deformation);
        follow(
            &mut organ.touch.contact,
            &mut deformation.loads[OrganDeformation::TOOL],
            &coupling.tool_moved_m(index),
        );
    }
}

/// An organ as the organ/organ contact stage reads and loads it.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct CoupledOrgan {
    index: &'static OrganIndex,
    touch: &'static mut ToolTouch,
    deformation: &'static mut OrganDeformation,
    motion: Option<&'static OrganMotion>,
}

/// The force on the tool: the opposite of what it applies to the organs; through a port, as
/// the hand feels it through the shaft's lever.
pub fn compute_force(
    tool: Res<Tool>,
    touches: Query<&ToolTouch>,
    grasp: Res<GraspForce>,
    mut force: ResMut<DeviceForce>,
) {
    let at_tip = grasp.0
        - touches
            .iter()
            .filter_map(|t| t.contact.map(|c| c.felt_n()))
            .sum::<Vector3<f64>>();
    force.desired_n = match &tool.pose {
        Some(pose) => Fulcrum::hand_force(pose, &at_tip),
        None => at_tip,
    };
}

/// Clamps, rate-limits and, on a fault, fades the force; logs each fault as it starts (a fault
/// of the same kind as the last logged one is counted, not logged again).
pub fn apply_safety(
    clock: Res<TickClock>,
    mut safety: ResMut<Safety>,
    mut force: ResMut<DeviceForce>,
    mut faults: ResMut<FaultLog>,
) {
    let faults = &mut *faults;
    if !force.desired_n.iter().all(|c| c.is_finite()) {
        faults.this_tick.push(Fault::NonFiniteForce);
    }
    force.sent_n = safety.0.filter(&force.desired_n, &faults.this_tick);
    if safety.0.refused_output() {
        faults.this_tick.push(Fault::NonFiniteOutput);
    }
    if faults.this_tick.is_empty() {
        return;
    }
    faults.faulted_ticks += 1;
    for fault in &faults.this_tick {
        let known = faults
            .log
            .last()
            .is_some_and(|(_, last)| std::mem::discriminant(last) == std::mem::discriminant(fault));
        if !known {
            warn!("haptic tick {}: {fault}; fading the force", clock.tick);
            faults.log.push((clock.tick, fault.clone()));
        }
    }
}

/// Sends the force; a failed write is a fault of the next tick.
pub fn write_device(
    force: Res<DeviceForce>,
    mut device: ResMut<Device>,
    mut faults: ResMut<FaultLog>,
) {
    if let Err(e) = device.0.write_force(&force.sent_n) {
        faults.next_tick.push(Fault::Device(e.to_string()));
    }
}

/// Keeps the tick's forces (run when a trace was asked for).
pub fn trace_force(force: Res<DeviceForce>, mut trace: ResMut<ForceTrace>) {
    trace.desired_n.push(force.desired_n);
    trace.sent_n.push(force.sent_n);
}

/// What the snapshot takes of an organ entity.
#[derive(QueryData)]
pub struct PublishedOrgan {
    index: &'static OrganIndex,
    touch: &'static ToolTouch,
    deformation: &'static OrganDeformation,
    motion: Option<&'static OrganMotion>,
    cut: Option<&'static OrganCut>,
}

/// Hands the render side the tick's state, when one is listening; never waits.
pub fn publish_snapshot(
    clock: Res<TickClock>,
    tool: Res<Tool>,
    force: Res<DeviceForce>,
    safety: Res<Safety>,
    organs: Query<PublishedOrgan>,
    timing: Option<Res<LoopTiming>>,
    mut publisher: ResMut<SnapshotPublisher>,
) {
    let snapshot = publisher.0.input_buffer_mut();
    snapshot.tick = clock.tick;
    snapshot.time_s = clock.time_s;
    snapshot.tip_m = tool.sample.map(|s| s.tip_m);
    snapshot.handle_m = tool
        .port()
        .zip(tool.pose)
        .map(|(port, pose)| port.port_m - pose.along * pose.outside_m);
    snapshot.instruments = InstrumentsView::of(&tool.rack);
    snapshot.force_n = force.sent_n;
    snapshot.faulted = safety.0.is_faulted();
    snapshot.timing = timing.map_or_else(LoopTiming::default, |t| *t);
    let cuts = organs.iter().any(|o| o.cut.is_some()) && tool.action() == Action::Cut;
    snapshot.blade_edge = tool
        .sample
        .filter(|_| cuts)
        .map(|s| s.orientation * Vector3::x());
    for published in &organs {
        let organ = &mut snapshot.organs[published.index.0];
        organ.contact = published.touch.contact;
        organ.deformation.clone_from(&published.deformation.0);
        if let Some(motion) = published.motion {
            organ.motion.clone_from(&motion.correction);
            organ.grasped = motion.organ.holding();
        }
        if let Some(cut) = published.cut {
            organ.strokes.clear();
            organ.strokes.extend_from_slice(cut.scalpel.strokes());
        }
    }
    publisher.0.publish();
}
