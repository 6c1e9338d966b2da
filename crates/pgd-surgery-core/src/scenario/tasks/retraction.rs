//! Move the organ with the tool to expose what lies behind it, without loading the organs
//! around.

use serde::{Deserialize, Serialize};

use super::region::{RegionMove, RegionResult, check_towards, watched};
use crate::scenario::task::{
    LimitWatch, RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
    Watched,
};
use crate::scenario::units::{Millimetres, Newtons, Seconds};

/// `Retraction(organ, region, at_mm, towards, move_mm, hold_s, max_force_n,
/// max_surrounding_force_n, time_limit_s)`: push the organ's `region` (the surface nearest
/// `at_mm`) at least `move_mm` along `towards` and keep it there for `hold_s`, loading the
/// surrounding organs (through the retracted organ or by touching them) no more than
/// `max_surrounding_force_n`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Retraction {
    /// What the trainee is told the region is (e.g. "the fundus").
    pub region: String,
    pub at_mm: (f64, f64, f64),
    /// The direction to move the region in (any length; the scene's frame).
    pub towards: (f64, f64, f64),
    pub move_mm: Millimetres,
    pub hold_s: Seconds,
    pub max_surrounding_force_n: Newtons,
}

/// The mistake of loading the organs around over their limit (the limit the amount).
const OVER_SURROUNDING: u16 = 0;

impl TaskType for Retraction {
    const NAME: &'static str = "Retraction";
    const LABEL: &'static str = "retraction";
    type Run = RetractionRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "move {} of the {} {:.0} mm and hold it {} s, under {} N, loading the organs \
             around under {} N",
            self.region,
            shared.organ.as_deref().unwrap_or_default(),
            self.move_mm.0,
            self.hold_s.0,
            shared.max_force_n,
            self.max_surrounding_force_n
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        check_towards(check, self.towards);
        check.hold_fits(self.hold_s.0);
    }

    fn watched<'a>(&'a self, shared: &'a TaskShared) -> Option<Watched<'a>> {
        watched(shared, self.at_mm, self.towards)
    }

    fn run(&self, _: &TaskShared, _: RunSetup) -> RetractionRun {
        RetractionRun {
            region: RegionMove::new(self.move_mm.0, self.hold_s.0),
            surrounding_limit_n: self.max_surrounding_force_n.0,
            surrounding_peak_n: 0.0,
            surrounding_over_limit_s: 0.0,
            over_surrounding: LimitWatch::default(),
        }
    }

    fn describe_mistake(&self, _: &TaskShared, code: u16, amount: f64) -> String {
        debug_assert_eq!(code, OVER_SURROUNDING);
        format!("loaded the organs around harder than {} N", Newtons(amount))
    }
}

#[derive(Clone, Debug)]
pub struct RetractionRun {
    region: RegionMove,
    surrounding_limit_n: f64,
    surrounding_peak_n: f64,
    surrounding_over_limit_s: f64,
    over_surrounding: LimitWatch,
}

impl TaskRun for RetractionRun {
    type Result = RetractionResult;

    fn step(&mut self, tick: &mut Tick<'_>) {
        let sample = tick.sample;
        let load_n = sample.surrounding_force_n;
        self.surrounding_peak_n = self.surrounding_peak_n.max(load_n);
        let limit_n = self.surrounding_limit_n;
        if (self.over_surrounding).crossed(
            load_n,
            limit_n,
            tick.dt,
            &mut self.surrounding_over_limit_s,
        ) {
            tick.mistake(OVER_SURROUNDING, limit_n);
        }
        let moved_mm = self.region.moved(sample.region_moved_m);
        if self
            .region
            .hold(moved_mm >= self.region.move_mm, sample.time_s)
        {
            tick.metrics.completed = true;
        }
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(self.region.progress())
    }

    fn result(&self) -> RetractionResult {
        RetractionResult {
            region: self.region.result(),
            surrounding_limit_n: self.surrounding_limit_n,
            surrounding_peak_n: self.surrounding_peak_n,
            surrounding_over_limit_s: self.surrounding_over_limit_s,
        }
    }
}

/// Retraction's measures: the region's move and hold, and the load on the organs around —
/// its limit, its peak and the time above it.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RetractionResult {
    #[serde(flatten)]
    pub region: RegionResult,
    pub surrounding_limit_n: f64,
    pub surrounding_peak_n: f64,
    pub surrounding_over_limit_s: f64,
}

impl TaskResult for RetractionResult {
    /// Off target is the time above either limit, the tool's or the organs around's.
    fn off_target_s(&self, metrics: &crate::scenario::TaskMetrics) -> f64 {
        metrics.time_over_limit_s + self.surrounding_over_limit_s
    }

    fn unfinished(&self) -> Option<String> {
        Some(self.region.unfinished())
    }

    fn feedback(&self) -> Vec<String> {
        (self.surrounding_over_limit_s > 0.0)
            .then(|| {
                format!(
                    "{:.1} s loading the organs around above {} N (peak {} N)",
                    self.surrounding_over_limit_s,
                    Newtons(self.surrounding_limit_n),
                    Newtons(self.surrounding_peak_n)
                )
            })
            .into_iter()
            .collect()
    }

    fn summary(&self) -> Vec<String> {
        let region = &self.region;
        vec![format!(
            "region moved up to {:.1} mm (of {:.0}), held {:.1} s; organs around: peak {:.2} N, {:.1} s above {:.2} N",
            region.moved_mm.unwrap_or(0.0),
            region.move_target_mm,
            region.longest_hold_s,
            self.surrounding_peak_n,
            self.surrounding_over_limit_s,
            self.surrounding_limit_n
        )]
    }
}
