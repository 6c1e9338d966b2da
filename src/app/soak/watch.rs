//! What the soak's ticks show: their compute times at the start and the end, the force the
//! device is sent from one tick to the next across every attempt (its NaNs, its steps, where
//! the largest step outside a fault's fade was), the faults by kind, and the resident memory
//! every simulated minute.

use std::collections::BTreeMap;
use std::time::Duration;

use nalgebra::Vector3;
use serde::Serialize;

use super::memory::{MemorySample, resident_bytes};
use crate::app::haptic::{DeviceForce, FaultLog, HapticLoop, Safety};
use crate::devices::{Histogram, TICK_S};

/// Ticks between two samples of the resident memory: a simulated minute.
const MEMORY_EVERY_TICKS: u64 = 60_000;

/// A step of the force sent between two ticks, and where it was.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StepPlace {
    pub step_n: f64,
    pub simulated_s: f64,
    /// The scenario file of the attempt, and the tick within it.
    pub scenario: String,
    pub tick: u64,
}

pub struct Watch {
    pub ticks: u64,
    window_ticks: u64,
    total_ticks: u64,
    pub first: Histogram,
    pub last: Histogram,
    pub nan_count: u64,
    last_sent_n: Vector3<f64>,
    pub max_force_step_n: f64,
    /// The largest step outside a fault's fade and a lowered limit's clamp: what the rate
    /// limit holds.
    pub largest_plain_step: StepPlace,
    /// Steps at the first tick of a scene whose force limit is lower than the one before (the
    /// filter clamps to it at once).
    pub lowered_limit_steps: u64,
    /// Faults by kind, over every attempt.
    pub faults: BTreeMap<&'static str, u64>,
    pub memory: Vec<MemorySample>,
    /// The attempt under way: its scenario, its ticks so far, and the force limit before it.
    scenario: &'static str,
    attempt_tick: u64,
    limit_before_n: f64,
    faulted_before: bool,
    pub attempts: u64,
}

impl Watch {
    pub fn new(total_ticks: u64, window_ticks: u64) -> Self {
        Self {
            ticks: 0,
            window_ticks,
            total_ticks,
            first: Histogram::default(),
            last: Histogram::default(),
            nan_count: 0,
            last_sent_n: Vector3::zeros(),
            max_force_step_n: 0.0,
            largest_plain_step: StepPlace::default(),
            lowered_limit_steps: 0,
            faults: BTreeMap::new(),
            memory: Vec::new(),
            scenario: "",
            attempt_tick: 0,
            limit_before_n: f64::INFINITY,
            faulted_before: false,
            attempts: 0,
        }
    }

    pub fn left(&self) -> u64 {
        self.total_ticks.saturating_sub(self.ticks)
    }

    /// An attempt at `scenario` begins.
    pub fn begin(&mut self, scenario: &'static str) {
        self.scenario = scenario;
        self.attempt_tick = 0;
    }

    /// The attempt ended in `haptic`: its faults counted, its limit kept for the next.
    pub fn end(&mut self, haptic: &HapticLoop) {
        for (_, fault) in &haptic.hand::<FaultLog>(0).expect("the soak's one hand").log {
            *self.faults.entry(fault.kind()).or_default() += 1;
        }
        self.limit_before_n = haptic.hand::<Safety>(0).map_or(0.0, |s| s.0.max_force_n());
        self.attempts += 1;
    }

    /// One tick's compute time and forces.
    pub fn record(&mut self, haptic: &HapticLoop, compute: Duration) {
        if self.ticks < self.window_ticks {
            self.first.record(compute);
        }
        if self.ticks >= self.total_ticks.saturating_sub(self.window_ticks) {
            self.last.record(compute);
        }
        self.record_force(haptic);
        self.ticks += 1;
        self.attempt_tick += 1;
        if self.ticks.is_multiple_of(MEMORY_EVERY_TICKS)
            && let Ok(bytes) = resident_bytes()
        {
            self.memory.push(MemorySample {
                simulated_s: self.ticks as f64 * TICK_S,
                attempts: self.attempts,
                bytes,
            });
        }
    }

    /// The force sent this tick against the last one, whichever attempt that was in.
    fn record_force(&mut self, haptic: &HapticLoop) {
        let force = haptic.hand::<DeviceForce>(0).expect("the soak's one hand");
        let finite = |f: &Vector3<f64>| f.iter().all(|c| c.is_finite());
        if !finite(&force.desired_n) || !finite(&force.sent_n) {
            self.nan_count += 1;
            return;
        }
        let step_n = (force.sent_n - self.last_sent_n).norm();
        self.last_sent_n = force.sent_n;
        self.max_force_step_n = self.max_force_step_n.max(step_n);
        let Some(Safety(filter)) = haptic.hand::<Safety>(0) else {
            return;
        };
        let in_fault = filter.is_faulted() || self.faulted_before;
        self.faulted_before = filter.is_faulted();
        let lowered = self.attempt_tick == 0 && filter.max_force_n() < self.limit_before_n;
        self.lowered_limit_steps += u64::from(lowered && step_n > 0.0);
        if !in_fault && !lowered && step_n > self.largest_plain_step.step_n {
            self.largest_plain_step = StepPlace {
                step_n,
                simulated_s: self.ticks as f64 * TICK_S,
                scenario: self.scenario.to_owned(),
                tick: self.attempt_tick,
            };
        }
    }
}
