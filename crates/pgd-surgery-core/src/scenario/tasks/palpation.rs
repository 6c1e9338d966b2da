//! Find the organ's hidden nodule by feel and mark it with the device's button.

use serde::{Deserialize, Serialize};

use crate::scenario::sample::NoduleSite;
use crate::scenario::task::{RunSetup, TaskCheck, TaskResult, TaskRun, TaskShared, TaskType, Tick};
use crate::scenario::units::Millimetres;

/// `Palpation(organ, found_within_mm, max_force_n, time_limit_s)`: one mark, which ends the
/// task; found when it is within `found_within_mm` of the nodule across the surface (depth
/// does not count).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Palpation {
    pub found_within_mm: Millimetres,
}

impl TaskType for Palpation {
    const NAME: &'static str = "Palpation";
    const LABEL: &'static str = "palpation";
    type Run = PalpationRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "find the nodule in the {} by feel and mark it, under {} N",
            shared.organ.as_deref().unwrap_or_default(),
            shared.max_force_n
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        let organ = check.organ_name();
        if !check.scene.nodules.iter().any(|n| n.organ == organ) {
            let quoted = format!("\"{organ}\"");
            check.problem_at(
                "organ",
                &["tasks", "Palpation", &quoted],
                format!("the {organ} has no nodule to find"),
                format!(
                    "add `nodules: [Nodule(organ: \"{organ}\", at_mm: (x, y, z), radius_mm: …, stiffness_ratio: …)]` (docs/scenarios.md)"
                ),
            );
        }
    }

    fn run(&self, _: &TaskShared, setup: RunSetup) -> PalpationRun {
        PalpationRun {
            organ: setup.organ,
            nodules: setup.nodules,
            found_within_mm: self.found_within_mm.0,
            button_held: false,
            error_mm: None,
        }
    }
}

#[derive(Clone, Debug)]
pub struct PalpationRun {
    organ: Option<usize>,
    nodules: Vec<NoduleSite>,
    found_within_mm: f64,
    /// Whether the button was held on the last tick.
    button_held: bool,
    /// How far across the surface the mark was from the nearest nodule, once made (mm).
    error_mm: Option<f64>,
}

impl TaskRun for PalpationRun {
    type Result = PalpationResult;

    /// A press of the button while on the organ is the mark: the task ends with it, found if
    /// the mark is near enough a nodule. A press off the organ marks nothing.
    fn step(&mut self, tick: &mut Tick<'_>) {
        let sample = tick.sample;
        let pressed = sample.button && !self.button_held;
        self.button_held = sample.button;
        let on_organ = self.organ.is_some_and(|k| sample.touches(k));
        let (true, true, Some(tip)) = (pressed, on_organ, sample.tip_m) else {
            return;
        };
        let Some(error_m) = (self.nodules.iter())
            .map(|site| site.lateral_distance_m(&tip))
            .min_by(f64::total_cmp)
        else {
            return;
        };
        self.error_mm = Some(error_m * 1e3);
        tick.metrics.completed = error_m <= self.found_within_mm * 1e-3;
    }

    /// Marked, right or wrong.
    fn over(&self) -> bool {
        self.error_mm.is_some()
    }

    fn result(&self) -> PalpationResult {
        PalpationResult {
            localization_error_mm: self.error_mm,
            found_within_mm: self.found_within_mm,
        }
    }
}

/// Palpation's measures: how far across the surface the mark was from the nodule (mm), if
/// made, and how near counts as found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PalpationResult {
    pub localization_error_mm: Option<f64>,
    pub found_within_mm: f64,
}

impl TaskResult for PalpationResult {
    /// 1 for a mark on the nodule, falling linearly to 0 at twice the distance that counts as
    /// found; 0 without a mark.
    fn accuracy(&self) -> Option<f64> {
        Some(self.localization_error_mm.map_or(0.0, |error| {
            (1.0 - error / (2.0 * self.found_within_mm)).clamp(0.0, 1.0)
        }))
    }

    /// A mark in the wrong place says so itself.
    fn unfinished(&self) -> Option<String> {
        self.localization_error_mm.is_none().then(String::new)
    }

    fn feedback(&self) -> Vec<String> {
        let within = self.found_within_mm;
        (self.localization_error_mm.filter(|&error| error > within))
            .map(|error| {
                format!(
                    "marked {error:.0} mm from the nodule; within {within:.0} mm counts as found"
                )
            })
            .into_iter()
            .collect()
    }

    fn summary(&self) -> Vec<String> {
        (self.localization_error_mm)
            .map(|error| {
                format!(
                    "mark: {error:.1} mm from the nodule across the surface (found within {:.0} mm)",
                    self.found_within_mm
                )
            })
            .into_iter()
            .collect()
    }
}
