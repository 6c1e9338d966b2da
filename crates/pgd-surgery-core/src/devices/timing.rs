//! Pacing the haptic loop on its own clock, and the figures that say how well it kept time.
//!
//! Deadlines are absolute (`start + k × period`), so one late tick does not shift every later
//! one. A plain `sleep` until the deadline wakes up whenever the OS scheduler gets round to it
//! (tens to hundreds of µs late on a shared machine); the hybrid timer sleeps until shortly
//! before and spins the rest, trading a little CPU for punctuality.

use std::time::{Duration, Instant};

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum TimerMode {
    /// Sleep until the deadline.
    Sleep,
    /// Sleep until `spin` before the deadline, then spin.
    Hybrid { spin: Duration },
}

impl Default for TimerMode {
    fn default() -> Self {
        TimerMode::Hybrid {
            spin: Duration::from_micros(300),
        }
    }
}

/// Absolute deadlines every `period`.
pub struct Metronome {
    start: Instant,
    period: Duration,
    next: u64,
    mode: TimerMode,
}

/// When a tick started, against its deadline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beat {
    /// Ticks since the metronome started, skipped ones included.
    pub tick: u64,
    /// How late the tick started (zero if on time).
    pub lateness: Duration,
    /// Deadlines that had already passed and were skipped rather than run in a burst.
    pub skipped: u64,
}

impl Metronome {
    pub fn new(period: Duration, mode: TimerMode) -> Self {
        Self {
            start: Instant::now(),
            period,
            next: 0,
            mode,
        }
    }

    /// Waits for the next deadline. A tick later than a whole period skips the deadlines it
    /// missed: a device wants the latest state now, not a burst of stale ticks.
    pub fn wait(&mut self) -> Beat {
        let deadline = self.start + self.period * self.next as u32;
        match self.mode {
            TimerMode::Sleep => sleep_until(deadline),
            TimerMode::Hybrid { spin } => {
                sleep_until(deadline.checked_sub(spin).unwrap_or(deadline));
                while Instant::now() < deadline {
                    std::hint::spin_loop();
                }
            }
        }
        let now = Instant::now();
        let lateness = now.saturating_duration_since(deadline);
        let skipped = (lateness.as_nanos() / self.period.as_nanos()) as u64;
        let beat = Beat {
            tick: self.next,
            lateness,
            skipped,
        };
        self.next += 1 + skipped;
        beat
    }
}

fn sleep_until(deadline: Instant) {
    let now = Instant::now();
    if deadline > now {
        std::thread::sleep(deadline - now);
    }
}

/// Durations in 1 µs bins up to 20 ms (longer ones in the last bin): percentiles to a
/// microsecond without storing every tick, and nothing allocated while recording.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    bins: Vec<u64>,
    count: u64,
    max: Duration,
}

const BINS: usize = 20_000;

impl Default for Histogram {
    fn default() -> Self {
        Self {
            bins: vec![0; BINS],
            count: 0,
            max: Duration::ZERO,
        }
    }
}

impl Histogram {
    pub fn record(&mut self, d: Duration) {
        let bin = (d.as_micros() as usize).min(BINS - 1);
        self.bins[bin] += 1;
        self.count += 1;
        self.max = self.max.max(d);
    }

    pub fn count(&self) -> u64 {
        self.count
    }

    pub fn max(&self) -> Duration {
        self.max
    }

    /// How many recorded durations exceeded `limit` (to the microsecond).
    pub fn count_above(&self, limit: Duration) -> u64 {
        let from = (limit.as_micros() as usize).min(BINS);
        self.bins[from..].iter().sum()
    }

    /// The `q`-quantile (0–1), to the microsecond: the upper edge of its bin.
    pub fn quantile(&self, q: f64) -> Duration {
        if self.count == 0 {
            return Duration::ZERO;
        }
        let rank = ((q * self.count as f64).ceil() as u64).clamp(1, self.count);
        let mut seen = 0;
        for (bin, &n) in self.bins.iter().enumerate() {
            seen += n;
            if seen >= rank {
                return Duration::from_micros(bin as u64 + 1).min(self.max);
            }
        }
        self.max
    }
}
