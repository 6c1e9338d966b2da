//! Press the organ and hold the force within a band for a while.

use serde::{Deserialize, Serialize};

use crate::scenario::task::{
    BandEnd, Hold, RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType,
    Tick,
};
use crate::scenario::units::{Newtons, Seconds};

/// `ForceControl(organ, min_force_n, max_force_n, hold_s, time_limit_s)`: the band is from
/// `min_force_n` to the shared `max_force_n`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceControl {
    pub min_force_n: Newtons,
    pub hold_s: Seconds,
}

impl TaskType for ForceControl {
    const NAME: &'static str = "ForceControl";
    const LABEL: &'static str = "force control";
    type Run = ForceControlRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "hold {} to {} N on the {} for {} s",
            self.min_force_n,
            shared.max_force_n,
            shared.organ.as_deref().unwrap_or_default(),
            self.hold_s.0
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        let min = BandEnd {
            field: "min_force_n",
            anchors: &["tasks", "min_force_n"],
            value_n: self.min_force_n.0,
        };
        let max = BandEnd {
            field: "max_force_n",
            anchors: &["tasks", "max_force_n"],
            value_n: check.shared.max_force_n.0,
        };
        check.force_band(min, max);
        check.hold_fits(self.hold_s.0);
    }

    fn run(&self, shared: &TaskShared, setup: RunSetup) -> ForceControlRun {
        ForceControlRun {
            organ: setup.organ,
            band_n: (self.min_force_n.0, shared.max_force_n.0),
            hold_s: self.hold_s.0,
            hold: Hold::default(),
            within_band_s: 0.0,
        }
    }
}

#[derive(Clone, Debug)]
pub struct ForceControlRun {
    organ: Option<usize>,
    band_n: (f64, f64),
    hold_s: f64,
    hold: Hold,
    within_band_s: f64,
}

impl TaskRun for ForceControlRun {
    type Result = ForceControlResult;

    fn step(&mut self, tick: &mut Tick<'_>) {
        let sample = tick.sample;
        let on_organ = self.organ.is_some_and(|k| sample.touches(k));
        let in_band = on_organ && (self.band_n.0..=self.band_n.1).contains(&sample.force_n);
        if in_band {
            self.within_band_s += tick.dt;
        }
        if self.hold.step(in_band, sample.time_s) >= self.hold_s && in_band {
            tick.metrics.completed = true;
        }
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(TaskProgress {
            what: "held",
            done: self.hold.longest_s,
            of: self.hold_s,
            unit: "s",
        })
    }

    fn result(&self) -> ForceControlResult {
        ForceControlResult {
            band_min_n: self.band_n.0,
            hold_s: self.hold_s,
            longest_hold_s: self.hold.longest_s,
            within_band_s: self.within_band_s,
        }
    }
}

/// Force control's measures: the band's bottom, the hold asked and the longest, and the time
/// in contact within the band.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ForceControlResult {
    pub band_min_n: f64,
    pub hold_s: f64,
    pub longest_hold_s: f64,
    pub within_band_s: f64,
}

impl TaskResult for ForceControlResult {
    /// Off target is the time in contact outside the band.
    fn off_target_s(&self, metrics: &crate::scenario::TaskMetrics) -> f64 {
        metrics.contact_s - self.within_band_s
    }

    fn unfinished(&self) -> Option<String> {
        Some(held(self.longest_hold_s, self.hold_s))
    }

    fn lower_force_n(&self) -> Option<f64> {
        Some(self.band_min_n)
    }
}

/// " (held 1.0 s of 3.0 s)": how long a task's hold lasted, of how long it asks.
pub(super) fn held(longest_s: f64, hold_s: f64) -> String {
    format!(" (held {longest_s:.1} s of {hold_s:.1} s)")
}
