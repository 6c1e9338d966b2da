//! The safety filter between the physics and the device's motors. A wrong force is felt, a
//! jumping one is felt worse, and a runaway one hurts: every force is clamped to the device's
//! peak limit and rate-limited per tick, a sustained force is brought down to the device's
//! continuous limit, and on any fault the force fades to zero within a few ticks and stays
//! there until the fault has been gone for a while.
//!
//! The continuous limit bounds the force's mean square over the motors' thermal window, kept
//! as an exponential average (the motors' heat, `I²` filtered by a first-order lag). The
//! force allowed falls from the peak, with the motors cold, to the continuous limit as they
//! reach it; a sustained demand above the continuous limit settles on it, and the heat never
//! passes it (each tick adds at most a thousandth of the gap to it, and the allowance shrinks
//! faster than that).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::{DeviceLimits, TICK_S};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SafetySettings {
    /// The largest force (N) sent to the device (also capped by the device's own peak).
    pub max_force_n: f64,
    /// The largest change (N) of the force from one tick to the next.
    pub max_change_n_per_tick: f64,
    /// Ticks over which the force fades to zero on a fault.
    pub fade_ticks: u32,
    /// This many overrun ticks in a row is a fault.
    pub overrun_streak: u32,
    /// Ticks without a fault before the force is rendered again (ramped by the rate limit).
    pub recovery_ticks: u32,
}

impl Default for SafetySettings {
    /// 3.3 N: the Geomagic Touch's peak force. 20 mN a tick (20 N/s) is ten times what a
    /// fast jab into liver asks for, and a fade over 5 ticks (5 ms) is quicker than a hand
    /// reacts. Recovery after 200 ms clean.
    fn default() -> Self {
        Self {
            max_force_n: 3.3,
            max_change_n_per_tick: 0.02,
            fade_ticks: 5,
            overrun_streak: 3,
            recovery_ticks: 200,
        }
    }
}

/// Why the force was faded.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Fault {
    /// The device reported a position or orientation that is not a number.
    NonFiniteDevice,
    /// The physics produced a force that is not a number.
    NonFiniteForce,
    /// The device reported an error.
    Device(String),
    /// Ticks overran their period this many times in a row.
    Overruns(u32),
    /// An organ's dynamics could not be stepped.
    Physics(String),
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Fault::NonFiniteDevice => write!(f, "the device reported a non-finite position"),
            Fault::NonFiniteForce => write!(f, "the computed force is not finite"),
            Fault::Device(message) => write!(f, "device error: {message}"),
            Fault::Overruns(n) => write!(f, "{n} ticks in a row overran the 1 ms period"),
            Fault::Physics(message) => write!(f, "the physics failed: {message}"),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum State {
    Rendering,
    /// Fading from `from` to zero; `tick` of `fade_ticks` done.
    Fading {
        from: Vector3<f64>,
        tick: u32,
    },
    /// Zero force; `clean` ticks without a fault so far.
    Held {
        clean: u32,
    },
}

pub struct SafetyFilter {
    settings: SafetySettings,
    limits: DeviceLimits,
    max_force_n: f64,
    output: Vector3<f64>,
    /// The exponential average of the squared force sent (N²) over the thermal window.
    heat_n2: f64,
    state: State,
}

impl SafetyFilter {
    /// A filter for a device with `limits`.
    pub fn new(settings: SafetySettings, limits: DeviceLimits) -> Self {
        Self {
            max_force_n: settings.max_force_n.min(limits.peak_force_n),
            settings,
            limits,
            output: Vector3::zeros(),
            heat_n2: 0.0,
            state: State::Rendering,
        }
    }

    pub fn settings(&self) -> &SafetySettings {
        &self.settings
    }

    /// New settings (another scene's), keeping the force being sent and any fault: the force
    /// then moves from what the hand feels now at the allowed rate, as it would within a scene.
    pub fn retune(&mut self, settings: SafetySettings, limits: DeviceLimits) {
        self.max_force_n = settings.max_force_n.min(limits.peak_force_n);
        self.settings = settings;
        self.limits = limits;
    }

    /// The peak limit actually applied (N): the smaller of the settings' and the device's.
    pub fn max_force_n(&self) -> f64 {
        self.max_force_n
    }

    /// The RMS force (N) over the thermal window so far: what the continuous limit bounds.
    pub fn rms_force_n(&self) -> f64 {
        self.heat_n2.sqrt()
    }

    /// The largest force (N) the motors' heat allows now: the peak while they are cold,
    /// falling linearly in the heat to the continuous limit when the heat reaches its square
    /// (below it beyond, so that an overshoot is paid back).
    fn thermal_cap_n(&self) -> f64 {
        let continuous = self.limits.continuous_force_n;
        let spare = 1.0 - self.heat_n2 / (continuous * continuous);
        (continuous + (self.max_force_n - continuous).max(0.0) * spare).max(0.0)
    }

    /// Whether the force is being faded or held at zero after a fault.
    pub fn is_faulted(&self) -> bool {
        self.state != State::Rendering
    }

    /// The force to send this tick for the `desired` one, given the faults seen this tick.
    pub fn filter(&mut self, desired: &Vector3<f64>, faults: &[Fault]) -> Vector3<f64> {
        let faulted = !faults.is_empty() || !desired.iter().all(|c| c.is_finite());
        self.state = match (self.state, faulted) {
            (State::Rendering, true) => State::Fading {
                from: self.output,
                tick: 0,
            },
            (State::Fading { from, tick }, _) => State::Fading {
                from,
                tick: tick + 1,
            },
            (State::Held { .. }, true) => State::Held { clean: 0 },
            (State::Held { clean }, false) if clean + 1 >= self.settings.recovery_ticks => {
                State::Rendering
            }
            (State::Held { clean }, false) => State::Held { clean: clean + 1 },
            (State::Rendering, false) => State::Rendering,
        };
        self.output = match self.state {
            State::Rendering => self.limited(desired),
            State::Fading { from, tick } => {
                let left = self.settings.fade_ticks.saturating_sub(tick + 1);
                if left == 0 {
                    self.state = State::Held { clean: 0 };
                }
                from * (left as f64 / self.settings.fade_ticks.max(1) as f64)
            }
            State::Held { .. } => Vector3::zeros(),
        };
        let window = (self.limits.thermal_window_s / TICK_S).max(1.0);
        self.heat_n2 += (self.output.norm_squared() - self.heat_n2) / window;
        self.output
    }

    /// `desired` clamped to the peak and thermal limits, then moved towards from the last
    /// output by at most the change allowed per tick.
    fn limited(&self, desired: &Vector3<f64>) -> Vector3<f64> {
        let clamped = desired.cap_magnitude(self.max_force_n.min(self.thermal_cap_n()));
        let change = (clamped - self.output).cap_magnitude(self.settings.max_change_n_per_tick);
        self.output + change
    }
}
