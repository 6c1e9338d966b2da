//! The virtual device: a tool driven by mouse and keyboard from the trainer window, for
//! trainees without hardware. The window writes the tool's target and reads the force the
//! device would render through a [`VirtualHandle`]; both sides only load and store atomics,
//! so neither ever waits for the other.

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use nalgebra::{UnitQuaternion, Vector3};

use super::{DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice};

/// Three f64 in atomics: each component is consistent, the triple may mix two writes for one
/// tick, which a tool moved by hand cannot tell.
#[derive(Default)]
struct AtomicVector([AtomicU64; 3]);

impl AtomicVector {
    fn store(&self, v: &Vector3<f64>) {
        for (slot, c) in self.0.iter().zip(v.iter()) {
            slot.store(c.to_bits(), Ordering::Relaxed);
        }
    }

    fn load(&self) -> Vector3<f64> {
        Vector3::from_fn(|i, _| f64::from_bits(self.0[i].load(Ordering::Relaxed)))
    }
}

/// The window's side of the virtual device.
#[derive(Default)]
pub struct VirtualHandle {
    tip_m: AtomicVector,
    force_n: AtomicVector,
    buttons: AtomicU32,
    /// The handle's turn about the scene's anterior axis (rad, as f64 bits): a scalpel's
    /// edge, along the handle's x, turns in the plane facing the surgeon.
    turn_rad: AtomicU64,
}

impl VirtualHandle {
    /// Moves the tool tip to `tip_m` (m, scene frame).
    pub fn set_tip(&self, tip_m: &Vector3<f64>) {
        self.tip_m.store(tip_m);
    }

    pub fn tip_m(&self) -> Vector3<f64> {
        self.tip_m.load()
    }

    pub fn set_buttons(&self, buttons: u32) {
        self.buttons.store(buttons, Ordering::Relaxed);
    }

    /// Turns the handle to `turn_rad` about the scene's anterior axis.
    pub fn set_turn(&self, turn_rad: f64) {
        self.turn_rad.store(turn_rad.to_bits(), Ordering::Relaxed);
    }

    pub fn turn_rad(&self) -> f64 {
        f64::from_bits(self.turn_rad.load(Ordering::Relaxed))
    }

    /// The force (N) the device would render now: shown on screen in place of a motor.
    pub fn force_n(&self) -> Vector3<f64> {
        self.force_n.load()
    }
}

pub struct VirtualDevice {
    handle: Arc<VirtualHandle>,
    limits: DeviceLimits,
}

impl VirtualDevice {
    /// A virtual device with its tip at `tip_m`, and the handle the window drives it with.
    pub fn new(tip_m: &Vector3<f64>) -> (Self, Arc<VirtualHandle>) {
        let handle = Arc::new(VirtualHandle::default());
        handle.set_tip(tip_m);
        let device = Self {
            handle: handle.clone(),
            limits: DeviceLimits::default(),
        };
        (device, handle)
    }
}

impl HapticDevice for VirtualDevice {
    fn name(&self) -> &str {
        "virtual (mouse and keyboard)"
    }

    fn limits(&self) -> DeviceLimits {
        self.limits
    }

    fn read(&mut self, _time_s: f64) -> Result<DeviceSample, DeviceError> {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), self.handle.turn_rad());
        Ok(DeviceSample {
            buttons: self.handle.buttons.load(Ordering::Relaxed),
            orientation: turn,
            ..DeviceSample::at(self.handle.tip_m())
        })
    }

    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.handle.force_n.store(force.newtons());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The handle's turn is the device's orientation about the anterior axis: a quarter turn
    /// brings the handle's x (a scalpel's edge) from the patient's left to the feet (−z), and
    /// the tip stays where it was.
    #[test]
    fn turning_the_handle_turns_the_sample() {
        let tip = Vector3::new(0.01, 0.02, 0.03);
        let (mut device, handle) = VirtualDevice::new(&tip);
        let edge =
            |device: &mut VirtualDevice| device.read(0.0).unwrap().orientation * Vector3::x();
        assert!((edge(&mut device) - Vector3::x()).norm() < 1e-15);
        handle.set_turn(std::f64::consts::FRAC_PI_2);
        assert!((edge(&mut device) + Vector3::z()).norm() < 1e-15);
        assert_eq!(device.read(0.0).unwrap().tip_m, tip);
    }
}
