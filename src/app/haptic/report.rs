//! The summary of a headless run: ticks, forces, tick compute times, overruns, faults.

use std::fmt;
use std::time::Duration;

use serde::Serialize;

use super::hand::{DeviceForce, FaultLog};
use crate::devices::{Histogram, TICK_S};

/// Quantiles of a tick duration (µs).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TickTimes {
    pub count: u64,
    pub p50_us: f64,
    pub p99_us: f64,
    pub max_us: f64,
}

impl TickTimes {
    pub fn of(histogram: &Histogram) -> Self {
        let us = |d: Duration| d.as_secs_f64() * 1e6;
        Self {
            count: histogram.count(),
            p50_us: us(histogram.quantile(0.5)),
            p99_us: us(histogram.quantile(0.99)),
            max_us: us(histogram.max()),
        }
    }
}

/// What the device was sent over a run (N).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ForceSummary {
    pub contact_ticks: u64,
    /// Ticks the hand's jaws held an organ.
    pub holding_ticks: u64,
    pub max_desired_n: f64,
    pub max_sent_n: f64,
    /// Mean magnitude of the sent force over the ticks in contact.
    pub mean_sent_in_contact_n: f64,
    /// The largest change of the sent force from one tick to the next.
    pub max_change_n_per_tick: f64,
    pub final_n: [f64; 3],
}

impl ForceSummary {
    pub(super) fn record(&mut self, force: &DeviceForce, touching: bool, holding: bool) {
        self.holding_ticks += u64::from(holding);
        let sent = force.sent_n.norm();
        let change = (force.sent_n - nalgebra::Vector3::from(self.final_n)).norm();
        self.max_change_n_per_tick = self.max_change_n_per_tick.max(change);
        self.max_desired_n = self.max_desired_n.max(force.desired_n.norm());
        self.max_sent_n = self.max_sent_n.max(sent);
        if touching {
            let n = self.contact_ticks as f64;
            self.mean_sent_in_contact_n = (self.mean_sent_in_contact_n * n + sent) / (n + 1.0);
            self.contact_ticks += 1;
        }
        self.final_n = force.sent_n.into();
    }
}

impl fmt::Display for ForceSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "max {:.3} N, mean in contact {:.3} N, largest change {:.4} N/tick \
             (physics asked up to {:.3} N)",
            self.max_sent_n,
            self.mean_sent_in_contact_n,
            self.max_change_n_per_tick,
            self.max_desired_n
        )
    }
}

/// How often and how far the tool pressed beyond what an organ's nonlinear vademecum covers
/// (until a position of the tool's patch carries a load deeper than the last load step):
/// there the felt force goes on at the stiffness of the last load-step interval, so a tissue
/// that firms up goes on firming up, but no longer as the law computed.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RangeSummary {
    pub beyond_ticks: u64,
    /// The farthest the tip reached beyond the range (mm).
    pub max_beyond_mm: f64,
    /// The organs pressed beyond their range, each with its deepest load step (mm): the depth
    /// one position's load makes alone, which the tool's own depth at the range's edge
    /// falls short of where one position carries most of the patch.
    pub organs: Vec<(String, f64)>,
}

impl RangeSummary {
    /// Records a tick in which the tool pressed `beyond_m` past the range `valid_m` of
    /// `organ`; ticks within range (`beyond_m` zero) are not recorded.
    pub(super) fn record(&mut self, organ: &str, beyond_m: f64, valid_m: f64) {
        if beyond_m <= 0.0 {
            return;
        }
        self.beyond_ticks += 1;
        self.max_beyond_mm = self.max_beyond_mm.max(beyond_m * 1e3);
        if !self.organs.iter().any(|(name, _)| name == organ) {
            self.organs.push((organ.to_owned(), valid_m * 1e3));
        }
    }
}

impl fmt::Display for RangeSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.beyond_ticks == 0 {
            return write!(f, "range: the tool stayed within every vademecum's range");
        }
        let organs: Vec<String> = self
            .organs
            .iter()
            .map(|(name, valid_mm)| format!("{name} (load steps to {valid_mm:.1} mm)"))
            .collect();
        write!(
            f,
            "range: the tool pressed beyond the vademecum's range for {} ticks, up to {:.1} mm \
             deeper, on {}; the tissue's stiffening was held at the range's edge there",
            self.beyond_ticks,
            self.max_beyond_mm,
            organs.join(", ")
        )
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeadlessReport {
    pub device: String,
    pub organs: Vec<String>,
    pub ticks: u64,
    pub simulated_s: f64,
    /// What the right hand's device was sent (the only one of a one-hand run)...
    pub force: ForceSummary,
    /// ...and the left hand's, in a bimanual run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub left_force: Option<ForceSummary>,
    pub range: RangeSummary,
    /// Wall-clock compute time of each tick.
    pub compute: TickTimes,
    /// Ticks whose compute exceeded the 1 ms period.
    pub overruns: u64,
    pub faulted_ticks: u64,
    /// (tick, fault) each time a fault started.
    pub faults: Vec<(u64, String)>,
}

impl HeadlessReport {
    /// The report of `ticks` ticks that sent `forces` (a hand's each) from `device` to
    /// `organs`, with `faults` and the compute times of `compute`.
    pub(super) fn new(
        device: String,
        organs: Vec<String>,
        faults: FaultSummary,
        ticks: u64,
        forces: Vec<ForceSummary>,
        range: RangeSummary,
        compute: &Histogram,
    ) -> Self {
        let period = Duration::from_secs_f64(TICK_S);
        let overruns = compute.count_above(period);
        let mut forces = forces.into_iter();
        Self {
            device,
            faulted_ticks: faults.faulted_ticks,
            faults: faults.faults,
            organs,
            ticks,
            simulated_s: ticks as f64 * TICK_S,
            force: forces.next().unwrap_or_default(),
            left_force: forces.next(),
            range,
            compute: TickTimes::of(compute),
            overruns,
        }
    }
}

/// The faults of a run, every hand's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaultSummary {
    /// The most ticks any one hand had a fault in.
    pub faulted_ticks: u64,
    /// (tick, fault) each time a fault started, in tick order, each named with its hand
    /// where one is given.
    pub faults: Vec<(u64, String)>,
}

impl FaultSummary {
    /// The faults of `logs`, each with the name of its hand (`None`: one hand, unnamed).
    pub fn of<'a>(logs: impl Iterator<Item = (Option<&'a str>, &'a FaultLog)>) -> Self {
        let mut summary = Self::default();
        for (hand, log) in logs {
            summary.faulted_ticks = summary.faulted_ticks.max(log.faulted_ticks);
            summary
                .faults
                .extend(log.log.iter().map(|(tick, fault)| match hand {
                    Some(hand) => (*tick, format!("{hand}: {fault}")),
                    None => (*tick, fault.to_string()),
                }));
        }
        summary.faults.sort_by_key(|(tick, _)| *tick);
        summary
    }
}

impl fmt::Display for HeadlessReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "device: {}", self.device)?;
        writeln!(f, "organs: {}", self.organs.join(", "))?;
        writeln!(
            f,
            "ticks: {} ({:.3} s simulated), {} in contact",
            self.ticks, self.simulated_s, self.force.contact_ticks
        )?;
        writeln!(f, "force sent: {}", self.force)?;
        if let Some(left) = &self.left_force {
            writeln!(f, "left hand's force sent: {left}")?;
        }
        writeln!(
            f,
            "tick compute: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs; {} overruns of 1 ms",
            self.compute.p50_us, self.compute.p99_us, self.compute.max_us, self.overruns
        )?;
        writeln!(f, "{}", self.range)?;
        write!(f, "faults: {} ticks faulted", self.faulted_ticks)?;
        for (tick, fault) in &self.faults {
            write!(f, "\n  tick {tick}: {fault}")?;
        }
        Ok(())
    }
}
