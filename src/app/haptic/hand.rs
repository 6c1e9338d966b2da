//! A hand of the trainee's as an entity of the haptic world: its device, the instrument in
//! it (its rack of instruments and their ports), the force on its way to the device through
//! the safety filter, its grasp and its faults. A one-hand scene has one; a bimanual scene
//! two, the right hand first. The organs keep each hand's touch and load by its index.

use bevy::ecs::query::QueryData;
use bevy::prelude::*;
use nalgebra::Vector3;

use crate::contact::Probe;
use crate::devices::{
    Action, DeviceSample, Fault, Fulcrum, HapticDevice, Pose, Rack, SafetyFilter, Workspace,
};

/// The most hands the trainee works with: a surgeon's two.
pub const TRAINEE_HANDS: usize = 2;

/// The most hands a scene has: the trainee's two and an assistant's.
pub const MAX_HANDS: usize = TRAINEE_HANDS + 1;

/// A hand's place among the scene's hands: its organs' touch and load slot, its column of a
/// bimanual trajectory. 0 is the right hand (the only one of a one-hand scene), 1 the left;
/// the assistant's, when the scene has one, comes after the trainee's.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct HandIndex(pub usize);

impl HandIndex {
    /// The hand in words, as faults, the HUD and the reports name it.
    pub fn name(self) -> &'static str {
        match self.0 {
            0 => "right hand",
            1 => "left hand",
            _ => "assistant",
        }
    }
}

/// The device a hand holds. A hand without one (a loop parked before it takes over a running
/// loop's devices, or a hand the running loop had none for) reads nothing and sends nothing.
#[derive(Component)]
pub struct Device(pub Box<dyn HapticDevice>);

/// The tool as the last good device sample left it.
#[derive(Component, Default)]
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

/// The force (N) on its way to the device: what the physics asks for, what is sent.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct DeviceForce {
    pub desired_n: Vector3<f64>,
    pub sent_n: Vector3<f64>,
}

#[derive(Component)]
pub struct Safety(pub SafetyFilter);

/// Faults: those of this tick (read by the safety filter), those found after it (a failed
/// write, carried to the next tick), and a log of every change of fault.
#[derive(Component, Default)]
pub struct FaultLog {
    pub this_tick: Vec<Fault>,
    pub next_tick: Vec<Fault>,
    /// (tick, fault) each time a fault starts or changes kind.
    pub log: Vec<(u64, Fault)>,
    /// Ticks that had at least one fault.
    pub faulted_ticks: u64,
}

/// Every tick's desired and sent force, kept when asked for (tests, `--json` traces).
#[derive(Component, Default)]
pub struct ForceTrace {
    pub desired_n: Vec<Vector3<f64>>,
    pub sent_n: Vec<Vector3<f64>>,
}

/// The force the grasper's jaws pull the hand with this tick (N): the opposite of what they
/// pull the organ with, and the release's fade.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct GraspForce(pub Vector3<f64>);

/// A hand as the stages that serve its device read and write it.
#[derive(QueryData)]
#[query_data(mutable)]
pub struct HandState {
    pub index: &'static HandIndex,
    pub device: Option<&'static mut Device>,
    pub tool: &'static mut Tool,
    pub force: &'static mut DeviceForce,
    pub safety: Option<&'static mut Safety>,
    pub faults: &'static mut FaultLog,
}
