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
//! Everything is held in atomics: neither side ever waits for the other. The command (the force
//! and when it was given) crosses whole, through a sequence lock, and the servo clamps it to
//! the device's peak once more before the vendor's call. A sample read while the servo writes
//! may mix two consecutive samples, a millisecond apart.
//!
//! A panic or a signal halts every link at once through [`halt_every_link`], which takes no
//! lock: whatever thread holds the release registry, no servo renders force after it.

#[cfg(not(target_arch = "wasm32"))]
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
#[cfg(not(target_arch = "wasm32"))]
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::seqlock::SeqWords;
use super::{DeviceSample, EdgeForce, usable_limit_n};

/// Set once by [`halt_every_link`]: every link renders zero from then on.
static EVERY_LINK_HALTED: AtomicBool = AtomicBool::new(false);

/// Zero force on every link of the process from its servo's next frame on, without taking any
/// lock: what the panic hook and the signal handler do first, before they release the devices.
pub fn halt_every_link() {
    EVERY_LINK_HALTED.store(true, Ordering::Release);
}

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
    /// The commanded force (N, as `f64` bits) and when it was commanded (ns since `start`),
    /// written and read as one.
    command: SeqWords<4>,
    /// Whether any command has been given yet.
    commanded: AtomicBool,
    /// The device's peak force (N, as `f64` bits): the servo renders no more, whatever it is
    /// commanded. Zero until the backend has read the device's limits.
    peak_force_n: AtomicU64,
    /// Servo frames that found a command being written throughout their read and rendered zero.
    contended_frames: AtomicU64,
    /// Servo frames so far.
    frames: AtomicU64,
    /// The servo's last error (0: none) and the vendor's own code with it.
    error: AtomicU32,
    internal_error: AtomicU32,
    /// Servo frames that rendered zero because the command had expired.
    expired_frames: AtomicU64,
    /// Set when the device is being released: zero from then on, whatever is commanded.
    halted: AtomicBool,
    /// The command's age (ns) at the latest servo frame that rendered it, and at the first
    /// frame that found it expired (0 until one has), with those frames' numbers: the
    /// watchdog measured in the servo's own frames, whatever the machine's load does to their
    /// spacing.
    rendered_age_ns: AtomicU64,
    rendered_frame: AtomicU64,
    expired_age_ns: AtomicU64,
    expired_frame: AtomicU64,
}

/// What the watchdog did, on the servo's own clock: the age of the last command at the last
/// frame that rendered it and at the first frame that rendered zero instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WatchdogRecord {
    pub rendered_age_s: f64,
    pub rendered_frame: u64,
    /// The first expired frame's command age (s) and number, once there has been one.
    pub expired: Option<(f64, u64)>,
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
            command: SeqWords::new([0; 4]),
            commanded: AtomicBool::new(false),
            peak_force_n: AtomicU64::new(0),
            contended_frames: AtomicU64::new(0),
            frames: AtomicU64::new(0),
            error: AtomicU32::new(0),
            internal_error: AtomicU32::new(0),
            expired_frames: AtomicU64::new(0),
            halted: AtomicBool::new(false),
            rendered_age_ns: AtomicU64::new(0),
            rendered_frame: AtomicU64::new(0),
            expired_age_ns: AtomicU64::new(0),
            expired_frame: AtomicU64::new(0),
        }
    }

    /// The device's peak force (N): the servo clamps every command to it. A peak that is not
    /// a positive number renders nothing.
    pub fn set_peak_force_n(&self, peak_force_n: f64) {
        let peak = usable_limit_n(peak_force_n);
        self.peak_force_n.store(peak.to_bits(), Ordering::Release);
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

    /// Servo side: the force to render this frame: the last command clamped to the device's
    /// peak, or zero once it is older than the watchdog allows, before any, while the link is
    /// halted, or when the command was being rewritten throughout the read.
    pub fn force_to_render(&self) -> Vector3<f64> {
        let frame = self.frames.fetch_add(1, Ordering::Relaxed) + 1;
        if self.is_halted() || !self.commanded.load(Ordering::Acquire) {
            return Vector3::zeros();
        }
        let Some([x, y, z, at_ns]) = self.command.read() else {
            self.contended_frames.fetch_add(1, Ordering::Relaxed);
            return Vector3::zeros();
        };
        let age_ns = self.now_ns().saturating_sub(at_ns);
        if age_ns > self.watchdog.as_nanos() as u64 {
            self.note_expired(age_ns, frame);
            return Vector3::zeros();
        }
        self.rendered_age_ns.store(age_ns, Ordering::Relaxed);
        self.rendered_frame.store(frame, Ordering::Relaxed);
        let force = Vector3::new(f64::from_bits(x), f64::from_bits(y), f64::from_bits(z));
        let peak = f64::from_bits(self.peak_force_n.load(Ordering::Acquire));
        match force.iter().all(|c| c.is_finite()) {
            true => force.cap_magnitude(peak),
            false => Vector3::zeros(),
        }
    }

    /// Counts a frame that found the command expired, keeping the first one's age and number.
    fn note_expired(&self, age_ns: u64, frame: u64) {
        self.expired_frames.fetch_add(1, Ordering::Relaxed);
        let first =
            self.expired_age_ns
                .compare_exchange(0, age_ns, Ordering::Relaxed, Ordering::Relaxed);
        if first.is_ok() {
            self.expired_frame.store(frame, Ordering::Relaxed);
        }
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
        let f = force.newtons();
        let at_ns = self.now_ns();
        self.command
            .write([f.x.to_bits(), f.y.to_bits(), f.z.to_bits(), at_ns]);
        self.expired_age_ns.store(0, Ordering::Relaxed);
        self.commanded.store(true, Ordering::Release);
    }

    /// What the watchdog did with the last command: it holds when the command was rendered
    /// within [`Self::watchdog_s`] and the very next frame rendered zero, past it.
    pub fn watchdog_record(&self) -> WatchdogRecord {
        let expired_ns = self.expired_age_ns.load(Ordering::Relaxed);
        WatchdogRecord {
            rendered_age_s: self.rendered_age_ns.load(Ordering::Relaxed) as f64 * 1e-9,
            rendered_frame: self.rendered_frame.load(Ordering::Relaxed),
            expired: (expired_ns > 0).then(|| {
                (
                    expired_ns as f64 * 1e-9,
                    self.expired_frame.load(Ordering::Relaxed),
                )
            }),
        }
    }

    /// Zero force from now on, whatever the loop commands: the device is being released (its
    /// backend closing, a panic, a signal).
    pub fn halt(&self) {
        self.halted.store(true, Ordering::Release);
    }

    /// Whether [`Self::halt`] or [`halt_every_link`] has been called.
    pub fn is_halted(&self) -> bool {
        self.halted.load(Ordering::Acquire) || EVERY_LINK_HALTED.load(Ordering::Acquire)
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

    /// Servo frames so far that rendered zero because the command was being rewritten
    /// throughout their read.
    pub fn contended_frames(&self) -> u64 {
        self.contended_frames.load(Ordering::Relaxed)
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

/// A servo thread of ours (for an SDK without a scheduler of its own), stopped once when its
/// device is released: joined, unless the release runs on the servo thread itself, which
/// cannot wait for itself. A poisoned lock is taken as it is: release must not fail. (No
/// vendor backend runs in a web page, which has no threads.)
#[cfg(not(target_arch = "wasm32"))]
#[derive(Debug, Default)]
pub struct ServoThread(Mutex<Option<JoinHandle<()>>>);

#[cfg(not(target_arch = "wasm32"))]
impl ServoThread {
    /// The thread started for the device.
    pub fn set(&self, thread: JoinHandle<()>) {
        *self.0.lock().unwrap_or_else(|p| p.into_inner()) = Some(thread);
    }

    /// Waits for the thread to end (its `running` flag cleared by the caller), once.
    pub fn join(&self) {
        let thread = self.0.lock().unwrap_or_else(|p| p.into_inner()).take();
        if let Some(thread) = thread
            && thread.thread().id() != std::thread::current().id()
        {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    use super::*;

    /// The `k`-th command: its three components equal, so that a vector mixed from two
    /// commands shows, and its size from 0 to 1.5 × the peak and back, so that some are over.
    fn command_number(k: u64, peak_n: f64) -> EdgeForce {
        let size_n = 1.5 * peak_n * ((k % 1000) as f64 / 1000.0);
        let c = size_n / 3f64.sqrt() + k as f64 * 1e-9;
        EdgeForce::guard(&Vector3::new(c, c, c), 1e6).0
    }

    /// One thread commands as fast as it can while another renders as fast as it can: every
    /// vector rendered is one command whole (its components equal) and within the peak.
    #[test]
    fn the_servo_renders_each_command_whole_and_within_the_peak() {
        let peak_n = 2.0;
        let link = Arc::new(ServoLink::new(Duration::from_secs(1)));
        link.set_peak_force_n(peak_n);
        let done = Arc::new(AtomicBool::new(false));
        let writer = {
            let (link, done) = (link.clone(), done.clone());
            std::thread::spawn(move || {
                let mut k = 0;
                while !done.load(Ordering::Relaxed) {
                    k += 1;
                    link.command(&command_number(k, peak_n));
                }
                k
            })
        };
        let (mut rendered, mut over_peak, mut mixed) = (0u64, 0u64, 0u64);
        let until = Instant::now() + Duration::from_millis(300);
        while Instant::now() < until {
            let f = link.force_to_render();
            rendered += 1;
            over_peak += u64::from(f.norm() > peak_n * (1.0 + 1e-12));
            mixed += u64::from(f.x != f.y || f.y != f.z);
        }
        done.store(true, Ordering::Relaxed);
        let commands = writer.join().unwrap();
        eprintln!(
            "{commands} commands, {rendered} frames rendered, {} contended",
            link.contended_frames()
        );
        assert!(commands > 1000 && rendered > 1000);
        assert_eq!((over_peak, mixed), (0, 0));
    }

    /// Before the backend has given the device's peak, nothing is rendered.
    #[test]
    fn a_link_without_a_peak_renders_nothing() {
        let link = ServoLink::default();
        link.command(&EdgeForce::guard(&Vector3::new(0.0, 0.0, 1.0), 3.3).0);
        assert_eq!(link.force_to_render(), Vector3::zeros());
        link.set_peak_force_n(3.3);
        assert_eq!(link.force_to_render(), Vector3::new(0.0, 0.0, 1.0));
    }
}
