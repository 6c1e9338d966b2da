//! One trait for every haptic device. Hardware backends (OpenHaptics for the Geomagic Touch,
//! Haply, Force Dimension) implement it in their own modules and map their workspace into the
//! scene's frame, so the rest of the loop never knows which device it serves.

use nalgebra::{UnitQuaternion, Vector3};

/// What a device reports at one tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceSample {
    /// Centre of the tool tip in the scene's frame (m).
    pub tip_m: Vector3<f64>,
    /// Orientation of the tool's handle in the scene's frame.
    pub orientation: UnitQuaternion<f64>,
    /// Button states, one bit each.
    pub buttons: u32,
}

impl DeviceSample {
    pub fn at(tip_m: Vector3<f64>) -> Self {
        Self {
            tip_m,
            orientation: UnitQuaternion::identity(),
            buttons: 0,
        }
    }

    /// Whether every number in the sample is finite: a NaN is a fault, not a position.
    pub fn is_finite(&self) -> bool {
        self.tip_m.iter().all(|c| c.is_finite())
            && self.orientation.coords.iter().all(|c| c.is_finite())
    }
}

/// What a device can render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceLimits {
    /// The largest force (N) it renders continuously.
    pub max_force_n: f64,
}

impl Default for DeviceLimits {
    /// The Geomagic Touch's continuous force, the device the papers used.
    fn default() -> Self {
        Self { max_force_n: 3.3 }
    }
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DeviceError {
    #[error("{device}: {message}")]
    Failed { device: String, message: String },
    #[error("{device}: disconnected")]
    Disconnected { device: String },
}

/// A haptic device, served by the 1 kHz loop: read at the start of a tick, written at its end.
pub trait HapticDevice: Send + Sync {
    fn name(&self) -> &str;
    fn limits(&self) -> DeviceLimits;
    /// The device's state at `time_s` seconds into the run.
    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError>;
    /// Sets the force (N) the device renders: already clamped and made safe by the caller.
    fn write_force(&mut self, force_n: &Vector3<f64>) -> Result<(), DeviceError>;
}
