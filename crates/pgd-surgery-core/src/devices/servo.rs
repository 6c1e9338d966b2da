//! What a hardware backend's servo thread and the haptic loop share: the device's latest sample,
//! the force to render, and the watchdog between them.
//!
//! A vendor's servo (OpenHaptics' scheduler callback, or a thread of ours for an SDK without
//! one) runs at the device's own rate, apart from the haptic loop. It publishes each sample and
//! renders the last force the loop commanded, but only while the loop keeps commanding: a
//! command older than [`ServoLink::watchdog_s`] is treated as zero. So a haptic loop that
//! stalls, panics or exits leaves the motors at zero force within that time, whatever the rest
//! of the program does.
//!
//! Everything is held in atomics: neither side ever waits for the other. A sample read while
//! the servo writes may mix two consecutive samples, a millisecond apart.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::{DeviceSample, EdgeForce};

/// How long a commanded force stays valid without a new command: ten missed 1 ms ticks.
pub const WATCHDOG_S: f64 = 0.010;

/// How long a started servo may take to publish its first sample.
pub const FIRST_SAMPLE_WITHIN: Duration = Duration::from_secs(1);

/// The state a backend's servo and the haptic loop share.
pub struct ServoLink {
    start: Instant,
    watchdog: Duration,
    /// Tip (m, the scene's axes), orientation quaternion (x, y, z, w), as `f64` bits.
    sample: [AtomicU64; 7],
    buttons: AtomicU32,
    /// Samples published so far.
    samples: AtomicU64,
    /// The commanded force (N), as `f64` bits, and when it was commanded (ns since `start`).
    force: [AtomicU64; 3],
    commanded_at_ns: AtomicU64,
    /// Whether any command has been given yet.
    commanded: AtomicBool,
    /// The servo's last error (0: none) and the vendor's own code with it.
    error: AtomicU32,
    internal_error: AtomicU32,
    /// Servo frames that rendered zero because the command had expired.
    expired_frames: AtomicU64,
    /// Set when the device is being released: zero from then on, whatever is commanded.
    halted: AtomicBool,
    /// The command's age (ns) at the latest servo frame that rendered it, and at the first
    /// frame that found it expired (0 until one has): the watchdog measured in the servo's own
    /// frames, whatever the machine's load does to their spacing.
    rendered_age_ns: AtomicU64,
    expired_age_ns: AtomicU64,
}

impl Default for ServoLink {
    fn default() -> Self {
        Self::new(Duration::from_secs_f64(WATCHDOG_S))
    }
}

impl ServoLink {
    pub fn new(watchdog: Duration) -> Self {
        Self {
            start: Instant::now(),
            watchdog,
            sample: std::array::from_fn(|k| {
                AtomicU64::new(if k == 6 { 1f64.to_bits() } else { 0 })
            }),
            buttons: AtomicU32::new(0),
            samples: AtomicU64::new(0),
            force: std::array::from_fn(|_| AtomicU64::new(0)),
            commanded_at_ns: AtomicU64::new(0),
            commanded: AtomicBool::new(false),
            error: AtomicU32::new(0),
            internal_error: AtomicU32::new(0),
            expired_frames: AtomicU64::new(0),
            halted: AtomicBool::new(false),
            rendered_age_ns: AtomicU64::new(0),
            expired_age_ns: AtomicU64::new(0),
        }
    }

    /// How long a command stays valid (s).
    pub fn watchdog_s(&self) -> f64 {
        self.watchdog.as_secs_f64()
    }

    fn now_ns(&self) -> u64 {
        self.start.elapsed().as_nanos() as u64
    }

    /// Servo side: the device's sample this frame.
    pub fn publish(&self, sample: &DeviceSample) {
        let q = sample.orientation.quaternion().coords;
        let values = [
            sample.tip_m.x,
            sample.tip_m.y,
            sample.tip_m.z,
            q.x,
            q.y,
            q.z,
            q.w,
        ];
        for (slot, v) in self.sample.iter().zip(values) {
            slot.store(v.to_bits(), Ordering::Relaxed);
        }
        self.buttons.store(sample.buttons, Ordering::Relaxed);
        self.samples.fetch_add(1, Ordering::Release);
    }

    /// Servo side: the force to render this frame: the last command, or zero once it is older
    /// than the watchdog allows (or before any).
    pub fn force_to_render(&self) -> Vector3<f64> {
        if self.halted.load(Ordering::Acquire) {
            return Vector3::zeros();
        }
        if !self.commanded.load(Ordering::Acquire) {
            return Vector3::zeros();
        }
        let age_ns = (self.now_ns()).saturating_sub(self.commanded_at_ns.load(Ordering::Acquire));
        if age_ns > self.watchdog.as_nanos() as u64 {
            self.expired_frames.fetch_add(1, Ordering::Relaxed);
            let _ = self.expired_age_ns.compare_exchange(
                0,
                age_ns,
                Ordering::Relaxed,
                Ordering::Relaxed,
            );
            return Vector3::zeros();
        }
        self.rendered_age_ns.store(age_ns, Ordering::Relaxed);
        Vector3::from_fn(|c, _| f64::from_bits(self.force[c].load(Ordering::Relaxed)))
    }

    /// Servo side: a vendor error this frame (`code` non-zero), with the vendor's own code.
    pub fn report_error(&self, code: u32, internal: u32) {
        self.internal_error.store(internal, Ordering::Relaxed);
        self.error.store(code, Ordering::Release);
    }

    /// Loop side: the latest sample, once the servo has published one.
    pub fn latest(&self) -> Option<DeviceSample> {
        if self.samples.load(Ordering::Acquire) == 0 {
            return None;
        }
        let v: [f64; 7] =
            std::array::from_fn(|k| f64::from_bits(self.sample[k].load(Ordering::Relaxed)));
        let orientation = UnitQuaternion::from_quaternion(Quaternion::new(v[6], v[3], v[4], v[5]));
        Some(DeviceSample {
            tip_m: Vector3::new(v[0], v[1], v[2]),
            orientation,
            buttons: self.buttons.load(Ordering::Relaxed),
        })
    }

    /// Loop side: the force to render until the next command (one that has passed the
    /// device's edge guard).
    pub fn command(&self, force: &EdgeForce) {
        for (slot, v) in self.force.iter().zip(force.newtons().iter()) {
            slot.store(v.to_bits(), Ordering::Relaxed);
        }
        self.commanded_at_ns.store(self.now_ns(), Ordering::Release);
        self.expired_age_ns.store(0, Ordering::Relaxed);
        self.commanded.store(true, Ordering::Release);
    }

    /// The last command's age (s) at the latest servo frame that rendered it, and at the first
    /// frame that rendered zero instead (`None` while none has): the watchdog holds when the
    /// first is within [`Self::watchdog_s`] and the second past it.
    pub fn watchdog_ages_s(&self) -> (f64, Option<f64>) {
        let rendered = self.rendered_age_ns.load(Ordering::Relaxed) as f64 * 1e-9;
        let expired = self.expired_age_ns.load(Ordering::Relaxed);
        (rendered, (expired > 0).then_some(expired as f64 * 1e-9))
    }

    /// Zero force from now on, whatever the loop commands: the device is being released (its
    /// backend closing, a panic, a signal).
    pub fn halt(&self) {
        self.halted.store(true, Ordering::Release);
    }

    /// Whether [`Self::halt`] has been called.
    pub fn is_halted(&self) -> bool {
        self.halted.load(Ordering::Acquire)
    }

    /// Loop side: the servo's last error and the vendor's code with it, clearing it.
    pub fn take_error(&self) -> Option<(u32, u32)> {
        match self.error.swap(0, Ordering::Acquire) {
            0 => None,
            code => Some((code, self.internal_error.load(Ordering::Relaxed))),
        }
    }

    /// Servo frames so far that rendered zero because the loop's command had expired.
    pub fn expired_frames(&self) -> u64 {
        self.expired_frames.load(Ordering::Relaxed)
    }

    /// Loop side: waits for the servo's first sample, so that the loop's first read has one;
    /// whether it came within `FIRST_SAMPLE_WITHIN`.
    pub fn await_first_sample(&self) -> bool {
        let give_up = Instant::now() + FIRST_SAMPLE_WITHIN;
        while self.samples() == 0 {
            if Instant::now() > give_up {
                return false;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
        true
    }

    /// Samples the servo has published so far.
    pub fn samples(&self) -> u64 {
        self.samples.load(Ordering::Acquire)
    }
}
