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

use super::{DeviceLimits, MAX_FORCE_LIMIT_N, TICK_S, usable_limit_n};

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

impl SafetySettings {
    /// Whether every setting is one the filter can honour: a force limit from 0 to
    /// [`MAX_FORCE_LIMIT_N`], a rate limit above zero and finite, a fade of at least one tick.
    /// A negative limit would reverse every force, so it is refused rather than mended.
    pub fn check(&self) -> Result<(), String> {
        check_force_limit(self.max_force_n).map_err(|e| format!("max_force_n: {e}"))?;
        let rate = self.max_change_n_per_tick;
        if !(rate.is_finite() && rate > 0.0 && rate <= MAX_FORCE_LIMIT_N) {
            return Err(format!(
                "max_change_n_per_tick: {rate} is not a rate limit: more than 0 and at most \
                 {MAX_FORCE_LIMIT_N} N a tick"
            ));
        }
        if self.fade_ticks == 0 {
            return Err("fade_ticks: 0 is not a fade: at least 1 tick".into());
        }
        Ok(())
    }
}

/// A force limit (N) a person may set: finite, from 0 to [`MAX_FORCE_LIMIT_N`].
pub fn check_force_limit(force_n: f64) -> Result<f64, String> {
    match force_n.is_finite() && (0.0..=MAX_FORCE_LIMIT_N).contains(&force_n) {
        true => Ok(force_n),
        false => Err(format!(
            "{force_n} is not a force limit: from 0 to {MAX_FORCE_LIMIT_N} N (a firm press on \
             the liver is about 0.3 N; the Geomagic Touch renders 3.3 N at most)"
        )),
    }
}

/// The limit a filter applies: the smaller of the settings' and the device's peak, and zero for
/// either that is not a force limit, so that no setting can turn the force round.
fn applied_limit_n(settings: &SafetySettings, limits: &DeviceLimits) -> f64 {
    usable_limit_n(settings.max_force_n).min(usable_limit_n(limits.peak_force_n))
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
    /// The filter's own output was not a number (it sends the fade instead).
    NonFiniteOutput,
    /// The device reported an error.
    Device(String),
    /// Ticks overran their period this many times in a row.
    Overruns(u32),
    /// An organ's dynamics could not be stepped.
    Physics(String),
}

impl Fault {
    /// The fault's kind, without its details: what a count of faults is kept by.
    pub fn kind(&self) -> &'static str {
        match self {
            Fault::NonFiniteDevice => "non-finite device",
            Fault::NonFiniteForce => "non-finite force",
            Fault::NonFiniteOutput => "non-finite output",
            Fault::Device(_) => "device error",
            Fault::Overruns(_) => "overruns",
            Fault::Physics(_) => "physics",
        }
    }
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Fault::NonFiniteDevice => write!(f, "the device reported a non-finite position"),
            Fault::NonFiniteForce => write!(f, "the computed force is not finite"),
            Fault::NonFiniteOutput => write!(f, "the safety filter's output is not finite"),
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
    /// Whether the last output computed was not finite (and the fade sent instead).
    refused_output: bool,
}

impl SafetyFilter {
    /// A filter for a device with `limits`.
    pub fn new(settings: SafetySettings, limits: DeviceLimits) -> Self {
        Self {
            max_force_n: applied_limit_n(&settings, &limits),
            settings,
            limits,
            output: Vector3::zeros(),
            heat_n2: 0.0,
            state: State::Rendering,
            refused_output: false,
        }
    }

    pub fn settings(&self) -> &SafetySettings {
        &self.settings
    }

    /// New settings (another scene's), keeping any fault. A limit raised leaves the force
    /// being sent, which then moves at the allowed rate as it would within a scene; a limit
    /// lowered bites at once: the force being sent, and a fade's starting force, are clamped
    /// to it, so that the very next tick sends no more than the new limit.
    pub fn retune(&mut self, settings: SafetySettings, limits: DeviceLimits) {
        self.max_force_n = applied_limit_n(&settings, &limits);
        self.settings = settings;
        self.limits = limits;
        self.output = self.output.cap_magnitude(self.max_force_n);
        if let State::Fading { from, tick } = self.state {
            self.state = State::Fading {
                from: from.cap_magnitude(self.max_force_n),
                tick,
            };
        }
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
        if !(continuous.is_finite() && continuous > 0.0) {
            return 0.0;
        }
        let spare = 1.0 - self.heat_n2 / (continuous * continuous);
        (continuous + (self.max_force_n - continuous).max(0.0) * spare).max(0.0)
    }

    /// Whether the force is being faded or held at zero after a fault.
    pub fn is_faulted(&self) -> bool {
        self.state != State::Rendering
    }

    /// The force to send this tick for the `desired` one, given the faults seen this tick.
    /// Whatever comes in, what comes out is finite and within the peak limit: an output that
    /// is not finite (arithmetic gone wrong) is itself a fault, and the fade is sent instead.
    pub fn filter(&mut self, desired: &Vector3<f64>, faults: &[Fault]) -> Vector3<f64> {
        let faulted = !faults.is_empty() || !is_finite(desired);
        self.state = self.next_state(faulted);
        let mut output = self.output_for(desired);
        self.refused_output = !is_finite(&output);
        if self.refused_output {
            self.state = self.next_state(true);
            output = self.output_for(desired);
        }
        self.output = output;
        let window = (self.limits.thermal_window_s / TICK_S).max(1.0);
        self.heat_n2 += (self.output.norm_squared() - self.heat_n2) / window;
        self.output
    }

    /// Whether the last [`Self::filter`] found its own output not finite and faded instead.
    pub fn refused_output(&self) -> bool {
        self.refused_output
    }

    /// The state after this tick's faults (or their absence).
    fn next_state(&self, faulted: bool) -> State {
        match (self.state, faulted) {
            (State::Rendering, true) => State::Fading {
                from: finite_or_zero(self.output),
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
        }
    }

    /// The force the state gives for `desired`; a fade that ends holds at zero.
    fn output_for(&mut self, desired: &Vector3<f64>) -> Vector3<f64> {
        match self.state {
            State::Rendering => self.limited(desired),
            State::Fading { from, tick } => {
                let fade_ticks = self.settings.fade_ticks.max(1);
                let left = fade_ticks.saturating_sub(tick + 1);
                if left == 0 {
                    self.state = State::Held { clean: 0 };
                }
                from * (left as f64 / fade_ticks as f64)
            }
            State::Held { .. } => Vector3::zeros(),
        }
    }

    /// `desired` clamped to the peak and thermal limits, then moved towards from the last
    /// output by at most the change allowed per tick.
    fn limited(&self, desired: &Vector3<f64>) -> Vector3<f64> {
        let clamped = desired.cap_magnitude(self.max_force_n.min(self.thermal_cap_n()));
        let rate = self.settings.max_change_n_per_tick.max(0.0);
        let change = (clamped - self.output).cap_magnitude(rate);
        self.output + change
    }
}

fn is_finite(force_n: &Vector3<f64>) -> bool {
    force_n.iter().all(|c| c.is_finite())
}

fn finite_or_zero(force_n: Vector3<f64>) -> Vector3<f64> {
    match is_finite(&force_n) {
        true => force_n,
        false => Vector3::zeros(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whatever state the filter is in (here its last output made NaN, as a bug elsewhere
    /// could), what it sends is finite: the non-finite output is refused, counted as a fault,
    /// and the fade is sent instead.
    #[test]
    fn a_non_finite_output_is_refused_and_faded() {
        let mut filter = SafetyFilter::new(SafetySettings::default(), DeviceLimits::touch());
        filter.output = Vector3::new(f64::NAN, 0.0, 0.0);
        let sent = filter.filter(&Vector3::new(0.0, 0.0, 0.5), &[]);
        assert!(filter.refused_output());
        assert_eq!(sent, Vector3::zeros());
        assert!(filter.is_faulted());
        assert!(filter.heat_n2.is_finite());
    }
}
