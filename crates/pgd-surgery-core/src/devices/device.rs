//! One trait for every haptic device. Hardware backends (OpenHaptics for the Geomagic Touch,
//! Force Dimension) implement it in their own modules and map their workspace into the scene's
//! frame, so the rest of the loop never knows which device it serves; every force reaches them
//! through the edge guard of [`HapticDevice::write_force`].

use nalgebra::{UnitQuaternion, Vector3};

/// The largest force (N) the product sends any device, and the largest limit a setting may
/// ask for: more than any haptic device it serves renders.
pub const MAX_FORCE_LIMIT_N: f64 = 20.0;

/// A force limit (N) as the guards apply it: itself when it is a positive number, zero
/// otherwise, so that no limit can turn a force round or let one through unbounded.
pub(super) fn usable_limit_n(limit_n: f64) -> f64 {
    match limit_n.is_finite() && limit_n > 0.0 {
        true => limit_n,
        false => 0.0,
    }
}

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

    /// The limits a driver reported, held to the product's ceiling ([`MAX_FORCE_LIMIT_N`]):
    /// no device this trainer serves renders more, so a driver reporting more is wrong, and
    /// believing it would switch the edge guard off. With the warning to show when it did.
    pub fn within_ceiling(self, device: &str) -> (Self, Option<String>) {
        if self.peak_force_n <= MAX_FORCE_LIMIT_N {
            return (self, None);
        }
        let warning = format!(
            "warning: {device} reports a {:.1} N peak force, more than any haptic device this \
             trainer serves; its forces are held to {MAX_FORCE_LIMIT_N} N",
            self.peak_force_n
        );
        let capped = Self {
            peak_force_n: MAX_FORCE_LIMIT_N,
            continuous_force_n: self.continuous_force_n.min(MAX_FORCE_LIMIT_N),
            ..self
        };
        (capped, Some(warning))
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
    /// The device's own guard refused a force the loop commanded (it rendered the guarded one).
    #[error("{device}: {refusal}")]
    Refused {
        device: String,
        refusal: EdgeRefusal,
    },
}

/// Why the device's edge guard did not pass a commanded force as it was.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum EdgeRefusal {
    /// A component was not a number: zero was rendered instead.
    #[error("a force that is not finite was commanded; zero was rendered")]
    NonFinite,
    /// More than the device's peak: the peak was rendered, along the force.
    #[error(
        "{asked_n:.3} N was commanded, over the device's {peak_n:.3} N peak; the peak was rendered"
    )]
    OverPeak { asked_n: f64, peak_n: f64 },
}

/// A force (N) that has passed a device's edge guard: finite and within the device's peak.
/// Backends render only these, so that no arithmetic before them, and no caller that skips
/// the safety filter, can put a NaN or more than the peak on the motors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeForce(Vector3<f64>);

/// Rounding slack over the peak before a force counts as over it: the safety filter's clamp
/// lands on the peak to within a few ulps.
const PEAK_SLACK: f64 = 1e-9;

impl EdgeForce {
    pub const ZERO: Self = Self(Vector3::new(0.0, 0.0, 0.0));

    /// `force_n` as a device whose peak is `peak_force_n` may render it: zero for a force
    /// that is not finite, the peak along it for one above the peak (a peak that is not a
    /// positive number renders nothing), with the refusal when it was not passed as asked.
    pub fn guard(force_n: &Vector3<f64>, peak_force_n: f64) -> (Self, Option<EdgeRefusal>) {
        let peak_n = usable_limit_n(peak_force_n);
        if !force_n.iter().all(|c| c.is_finite()) {
            return (Self::ZERO, Some(EdgeRefusal::NonFinite));
        }
        let asked_n = force_n.norm();
        match asked_n > peak_n * (1.0 + PEAK_SLACK) {
            true => (
                Self(force_n.cap_magnitude(peak_n)),
                Some(EdgeRefusal::OverPeak { asked_n, peak_n }),
            ),
            false => (Self(force_n.cap_magnitude(peak_n)), None),
        }
    }

    /// The force (N), in the scene's axes.
    pub fn newtons(&self) -> &Vector3<f64> {
        &self.0
    }
}

/// A haptic device, served by the 1 kHz loop: read at the start of a tick, written at its end.
pub trait HapticDevice: Send + Sync {
    fn name(&self) -> &str;
    fn limits(&self) -> DeviceLimits;
    /// The device's state at `time_s` seconds into the run.
    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError>;
    /// Renders a force that has passed the edge guard: what a backend implements.
    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError>;
    /// Sets the force (N) the device renders. The caller's safety filter has already clamped
    /// and rate-limited it; this is the last guard, independent of the filter: the force is
    /// clamped to the device's own peak and a non-finite one rendered as zero, each with the
    /// refusal as an error (a fault of the loop's next tick). Backends do not override it.
    fn write_force(&mut self, force_n: &Vector3<f64>) -> Result<(), DeviceError> {
        let (force, refusal) = EdgeForce::guard(force_n, self.limits().peak_force_n);
        self.render(force)?;
        match refusal {
            None => Ok(()),
            Some(refusal) => Err(DeviceError::Refused {
                device: self.name().to_owned(),
                refusal,
            }),
        }
    }
}
