//! The device layer, free of Bevy: the device trait and its backends (scripted, recorder,
//! virtual, and the OpenHaptics, Force Dimension and Haply hardware over the servo link and its
//! watchdog), the trajectory files they replay and record, the map from the device's workspace
//! to the scene, the instruments through ports (one in hand at a time) and the laparoscope,
//! the safety filter between the physics and the motors, and the clock that paces the 1 kHz
//! loop.

mod device;
#[cfg(not(target_arch = "wasm32"))]
mod forcedimension;
mod fulcrum;
#[cfg(not(target_arch = "wasm32"))]
pub mod haply;
mod laparoscope;
#[cfg(not(target_arch = "wasm32"))]
mod openhaptics;
mod rack;
mod recorder;
mod release;
mod safety;
mod scripted;
mod seqlock;
mod servo;
mod spec;
mod sweep;
mod timing;
mod trajectory;
#[cfg(not(target_arch = "wasm32"))]
mod vendor;
mod virtual_device;
mod workspace;

use device::usable_limit_n;
pub use device::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, EdgeRefusal, HapticDevice,
    MAX_FORCE_LIMIT_N,
};
#[cfg(not(target_arch = "wasm32"))]
pub use forcedimension::ForceDimension;
pub use fulcrum::{Fulcrum, HANDLE_AXIS, MIN_OUTSIDE_M, Pose};
#[cfg(not(target_arch = "wasm32"))]
pub use haply::Haply;
pub use laparoscope::{
    Laparoscope, MIN_INSIDE_M, ScopeHandle, ScopePose, ScopeScript, Steer, View,
};
#[cfg(not(target_arch = "wasm32"))]
pub use openhaptics::OpenHaptics;
pub use rack::{Action, CHANGE_BUTTON, Instrument, MAX_INSTRUMENTS, Rack};
pub use recorder::Recorder;
#[cfg(not(target_arch = "wasm32"))]
pub use release::install_exit_guards;
pub use release::{Release, hold_registry_for, register, release_all, stop_requested};
pub use safety::{Fault, SafetyFilter, SafetySettings, check_force_limit};
pub use scripted::Scripted;
pub use servo::{ServoLink, WATCHDOG_S, WatchdogRecord, halt_every_link};
pub use spec::DeviceSpec;
pub use sweep::{GRASP_PULL_M, PressMotion, PressTarget, grasp_and_hold, press_and_slide};
pub use timing::{Histogram, Metronome, TimerMode};
pub use trajectory::{Trajectory, TrajectoryError, TrajectoryRow};
#[cfg(not(target_arch = "wasm32"))]
use vendor::held_to_ceiling;
pub use virtual_device::{VirtualDevice, VirtualHandle};
pub use workspace::Workspace;

/// The haptic rate: one tick a millisecond.
pub const TICK_S: f64 = 1e-3;
