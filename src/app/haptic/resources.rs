//! The haptic world's resources: the device, the tool, the clock, the force on its way to the
//! device, and the fault log.

use bevy::prelude::*;

use crate::contact::Coupling;
use nalgebra::Vector3;

use crate::contact::Probe;
use std::sync::Arc;

use crate::devices::{
    Action, DeviceSample, Fault, Fulcrum, HapticDevice, Laparoscope, Pose, Rack, SafetyFilter,
    ScopeHandle, ScopePose, ScopeScript, Workspace,
};

#[derive(Resource)]
pub struct Device(pub Box<dyn HapticDevice>);

/// The tool as the last good device sample left it.
#[derive(Resource, Default)]
pub struct Tool {
    pub probe: Probe,
    /// How the device's motion maps onto the scene.
    pub workspace: Workspace,
    /// The instruments, one in hand; through a port the device moves its handle.
    pub rack: Rack,
    /// The device's last good sample, in the scene's frame.
    pub hand: Option<DeviceSample>,
    /// Through a port, where the instrument in hand is.
    pub pose: Option<Pose>,
    /// The instrument's tip, in the scene's frame; none until the device has reported a finite
    /// position.
    pub sample: Option<DeviceSample>,
}

impl Tool {
    /// What the instrument in hand does besides pressing.
    pub fn action(&self) -> Action {
        self.rack.in_hand().1.action
    }

    /// The port of the instrument in hand, if it goes through one.
    pub fn port(&self) -> Option<Fulcrum> {
        self.rack.in_hand().1.port
    }
}

/// The tick being run, set by the runner before each run of the schedule.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct TickClock {
    pub tick: u64,
    pub time_s: f64,
    /// Ticks in a row that missed their deadline.
    pub overruns_in_a_row: u32,
}

/// The force (N) on its way to the device: what the physics asks for, what is sent.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct DeviceForce {
    pub desired_n: Vector3<f64>,
    pub sent_n: Vector3<f64>,
}

#[derive(Resource)]
pub struct Safety(pub SafetyFilter);

/// Faults: those of this tick (read by the safety filter), those found after it (a failed
/// write, carried to the next tick), and a log of every change of fault.
#[derive(Resource, Default)]
pub struct FaultLog {
    pub this_tick: Vec<Fault>,
    pub next_tick: Vec<Fault>,
    /// (tick, fault) each time a fault starts or changes kind.
    pub log: Vec<(u64, Fault)>,
    /// Ticks that had at least one fault.
    pub faulted_ticks: u64,
}

/// Every tick's desired and sent force, kept when asked for (tests, `--json` traces).
#[derive(Resource, Default)]
pub struct ForceTrace {
    pub desired_n: Vec<Vector3<f64>>,
    pub sent_n: Vec<Vector3<f64>>,
}

/// The organs' contact and attachments, with their state from tick to tick.
#[derive(Resource, Clone)]
pub struct OrganCoupling(pub Coupling);

/// The force the grasper's jaws pull the hand with this tick (N): the opposite of what they
/// pull the organ with, and the release's fade.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct GraspForce(pub Vector3<f64>);

/// A scene's laparoscope: its optic, its pose (shared with the window, which steers it), and
/// the point the trainee is to keep in view, if any.
#[derive(Clone, Debug)]
pub struct SceneScope {
    pub scope: Laparoscope,
    pub pose: Arc<ScopeHandle>,
    pub keep_in_view_m: Option<Vector3<f64>>,
    /// The camera moved by the scenario, if the trainee does not steer it.
    pub script: Option<ScopeScript>,
}

/// The laparoscope inside the haptic world, with the pose it was last read at.
#[derive(Resource, Debug)]
pub struct Scope {
    pub rig: SceneScope,
    pub pose: ScopePose,
}

impl Scope {
    pub fn new(rig: SceneScope) -> Self {
        let pose = rig.pose.get();
        Self { rig, pose }
    }

    /// Moves a scripted camera to where it is `elapsed_s` into the exercise (and tells the
    /// window), or reads the pose the trainee steered it to (keeping the last one while the
    /// window holds it); then says whether the tip (if known) and the point to keep in view
    /// are in view.
    pub fn in_view(
        &mut self,
        tip_m: Option<&Vector3<f64>>,
        elapsed_s: f64,
    ) -> (Option<bool>, Option<bool>) {
        match &self.rig.script {
            Some(script) => {
                if let Some(pose) = script.pose_at(&self.rig.scope, elapsed_s) {
                    self.pose = pose;
                    self.rig.pose.try_set(pose);
                }
            }
            None => {
                if let Some(pose) = self.rig.pose.try_get() {
                    self.pose = pose;
                }
            }
        }
        let sees = |point: &Vector3<f64>| self.rig.scope.sees(&self.pose, point);
        (tip_m.map(sees), self.rig.keep_in_view_m.as_ref().map(sees))
    }
}
