//! The objective motion metrics of laparoscopic trainers, from the tool tip's trajectory as
//! the haptic loop samples it: path length, economy of motion, number of movements, idle time
//! smoothness (jerk), and, under a laparoscope, the time the tip is out of the camera's view.
//!
//! The tip is read every tick, but velocity and its derivatives are taken on a 100 Hz
//! subsample (every [`STRIDE`] ticks): a device's position quantization, differentiated three
//! times at 1 kHz, would drown the hand's jerk in noise. Everything is kept in fixed-size state:
//! the real-time thread allocates nothing.

use nalgebra::Vector3;
use serde::Serialize;

use crate::devices::MAX_INSTRUMENTS;

/// Ticks between the samples velocity and jerk are taken on (100 Hz at 1 kHz).
pub const STRIDE: u64 = 10;

/// Above this tip speed (m/s) the hand is moving: a movement starts...
pub const MOVING_M_PER_S: f64 = 0.010;
/// ...and it ends once the speed falls below this one (m/s); below it, the hand is idle.
pub const IDLE_M_PER_S: f64 = 0.005;

/// The tip has left its start once the shortest path it needs is this long (m).
const LEFT_START_M: f64 = 0.001;

/// What the tip's motion over a task measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MotionMetrics {
    /// The length of the tip's path (mm).
    pub path_length_mm: f64,
    /// The path over the shortest one that reaches as far from the start and ends where it
    /// ended (1 = no wasted motion); none when the tip never left its start. With several
    /// instruments, the shortest path is summed over the spells between changes.
    pub economy: Option<f64>,
    /// Movements: spells of the tip's speed above [`MOVING_M_PER_S`], each ended by its fall
    /// below [`IDLE_M_PER_S`].
    pub movements: usize,
    /// Time with the tip slower than [`IDLE_M_PER_S`] (s).
    pub idle_s: f64,
    /// The root mean square of the tip's jerk (m/s³): the lower, the smoother.
    pub rms_jerk_m_per_s3: f64,
    /// Under a laparoscope, the time the tip was out of the camera's view (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub out_of_view_s: Option<f64>,
    /// When the trainee changed instruments: how many times...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instrument_changes: Option<usize>,
    /// ...and each instrument's tip path (mm), in the scenario's order, to the last one used.
    /// The tip's path above is their sum: the jump from one instrument's tip to the next's is
    /// no motion of the hand.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub path_length_by_instrument_mm: Vec<f64>,
}

/// The running measurement.
#[derive(Clone, Debug, Default)]
pub struct MotionTracker {
    metrics: MotionMetrics,
    path_m: f64,
    start: Option<Vector3<f64>>,
    last: Option<Vector3<f64>>,
    /// Where the path since the last change of instrument started, and its farthest point
    /// from there; the shortest path the segments before needed (m).
    segment_start: Option<Vector3<f64>>,
    farthest_m: f64,
    farthest: Vector3<f64>,
    need_before_m: f64,
    ticks: u64,
    /// The last four subsamples (oldest first) and how many there are.
    recent: [Vector3<f64>; 4],
    count: usize,
    moving: bool,
    jerk_sum: f64,
    jerk_samples: usize,
    /// The instrument in hand, once known, how many changes, how many instruments were
    /// used (the last one's place, plus one), and each one's path (m).
    instrument: Option<usize>,
    changes: usize,
    used: usize,
    path_by_instrument_m: [f64; MAX_INSTRUMENTS],
}

impl MotionTracker {
    /// Takes the tip at one tick (`dt` s after the last); no tip (no device sample) is skipped.
    pub fn step(&mut self, tip_m: Option<Vector3<f64>>, dt: f64) {
        let Some(tip) = tip_m else { return };
        self.start.get_or_insert(tip);
        let start = match self.segment_start {
            Some(start) => start,
            None => {
                self.farthest = tip;
                self.farthest_m = 0.0;
                *self.segment_start.insert(tip)
            }
        };
        if let Some(last) = self.last {
            let step_m = (tip - last).norm();
            self.path_m += step_m;
            let instrument = self.instrument.unwrap_or(0).min(MAX_INSTRUMENTS - 1);
            self.path_by_instrument_m[instrument] += step_m;
        }
        self.last = Some(tip);
        let reach = (tip - start).norm();
        if reach > self.farthest_m {
            self.farthest_m = reach;
            self.farthest = tip;
        }
        if self.ticks.is_multiple_of(STRIDE) {
            self.subsample(tip, dt * STRIDE as f64);
        }
        self.ticks += 1;
    }

    /// One 100 Hz subsample, `h` s after the last.
    fn subsample(&mut self, tip: Vector3<f64>, h: f64) {
        self.recent.rotate_left(1);
        self.recent[3] = tip;
        self.count = (self.count + 1).min(4);
        if self.count < 2 || h <= 0.0 {
            return;
        }
        let r = &self.recent;
        let speed = (r[3] - r[2]).norm() / h;
        if speed < IDLE_M_PER_S {
            self.metrics.idle_s += h;
        }
        match self.moving {
            false if speed > MOVING_M_PER_S => {
                self.moving = true;
                self.metrics.movements += 1;
            }
            true if speed < IDLE_M_PER_S => self.moving = false,
            _ => {}
        }
        if self.count == 4 {
            let jerk = (r[3] - r[2] * 3.0 + r[1] * 3.0 - r[0]) / (h * h * h);
            self.jerk_sum += jerk.norm_squared();
            self.jerk_samples += 1;
        }
    }

    /// Takes the instrument in hand (its place in the scenario's list) before a tick's
    /// [`step`](Self::step). A change starts the tip's path afresh at the new instrument's tip:
    /// neither the jump between tips nor its speed counts as motion.
    pub fn in_hand(&mut self, instrument: usize) {
        self.used = self.used.max(instrument + 1);
        match self.instrument.replace(instrument) {
            Some(before) if before != instrument => {
                self.changes += 1;
                self.need_before_m += self.segment_need_m();
                self.segment_start = None;
                self.last = None;
                self.count = 0;
                self.moving = false;
            }
            _ => {}
        }
    }

    /// Takes whether the tip is in the camera's view at one tick (`dt` s after the last).
    pub fn view(&mut self, in_view: bool, dt: f64) {
        let out = self.metrics.out_of_view_s.get_or_insert(0.0);
        if !in_view {
            *out += dt;
        }
    }

    /// The length (m) of the tip's path so far.
    pub fn path_length_m(&self) -> f64 {
        self.path_m
    }

    /// Where the tip was first seen.
    pub fn start(&self) -> Option<Vector3<f64>> {
        self.start
    }

    /// The metrics so far.
    pub fn metrics(&self) -> MotionMetrics {
        let mut m = self.metrics.clone();
        m.path_length_mm = self.path_m * 1e3;
        let need_m = self.need_before_m + self.segment_need_m();
        if self.start.is_some() {
            m.economy = (need_m >= LEFT_START_M).then(|| self.path_m / need_m);
        }
        if self.jerk_samples > 0 {
            m.rms_jerk_m_per_s3 = (self.jerk_sum / self.jerk_samples as f64).sqrt();
        }
        if self.changes > 0 {
            // Allocates, once a task, only when instruments were changed.
            let paths = &self.path_by_instrument_m[..self.used.min(MAX_INSTRUMENTS)];
            m.instrument_changes = Some(self.changes);
            m.path_length_by_instrument_mm = paths.iter().map(|p| p * 1e3).collect();
        }
        m
    }

    /// The shortest path (m) the tip's path since the last change needed: out to its farthest
    /// point from where it started, then to where it is.
    fn segment_need_m(&self) -> f64 {
        self.last
            .map_or(0.0, |end| self.farthest_m + (end - self.farthest).norm())
    }
}
