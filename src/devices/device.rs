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

/// What a device can render. A motor takes a peak force for a moment but heats under a
/// sustained one: the continuous limit holds for the force's root mean square over the motors'
/// thermal window, the peak at every tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceLimits {
    /// The largest force (N) it renders at any tick.
    pub peak_force_n: f64,
    /// The largest force (N) it renders continuously: the bound on the RMS force over
    /// `thermal_window_s`.
    pub continuous_force_n: f64,
    /// The time constant (s) of the exponential window the RMS force is taken over.
    pub thermal_window_s: f64,
}

impl DeviceLimits {
    /// A device without motors to heat (scripted, virtual): one limit, the peak.
    pub fn peak_only(peak_force_n: f64) -> Self {
        Self {
            peak_force_n,
            continuous_force_n: peak_force_n,
            thermal_window_s: 1.0,
        }
    }

    /// The Geomagic Touch, the device the papers used: 3.3 N peak, 0.88 N continuous (its
    /// data sheet). The data sheet gives no thermal window; 2 s is chosen short, so that a
    /// sustained press falls to the continuous limit well before the motors could heat.
    pub fn touch() -> Self {
        Self {
            peak_force_n: 3.3,
            continuous_force_n: 0.88,
            thermal_window_s: 2.0,
        }
    }
}

impl Default for DeviceLimits {
    /// The Touch's peak force, as the limit of a device without motors.
    fn default() -> Self {
        Self::peak_only(3.3)
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
