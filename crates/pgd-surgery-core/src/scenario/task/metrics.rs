//! What every task measures, whatever its type, and its type's own result beside it.

use serde::Serialize;

use super::{TaskOutcome, TaskResult};
use crate::scenario::motion::MotionMetrics;

/// What a task measured: what every task measures here, its type's own in `outcome`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TaskMetrics {
    /// The task type's label ("force control").
    pub kind: &'static str,
    pub description: String,
    pub started_s: f64,
    pub time_limit_s: f64,
    pub completed: bool,
    /// Time spent on the task (to completion, or the whole limit).
    pub time_s: f64,
    pub contact_s: f64,
    pub peak_force_n: f64,
    /// Mean force while in contact.
    pub mean_force_n: f64,
    /// The force limit the task sets (the band's top for force control).
    pub force_limit_n: f64,
    pub time_over_limit_s: f64,
    /// Each error, with the time it was made (the first [`super::MISTAKES_LISTED`])...
    pub errors: Vec<String>,
    /// ...and how many more were made, counted but not listed.
    #[serde(skip_serializing_if = "is_zero")]
    pub more_errors: usize,
    /// The tool tip's motion over the task (the task's hand's): path, economy, movements,
    /// idle time, jerk.
    pub motion: MotionMetrics,
    /// In a bimanual exercise, both hands: each one's motion, their work together, the idle
    /// hand's drift.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hands: Option<crate::scenario::BimanualMetrics>,
    /// The other hand's counter-traction, when the task asks for one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub countertraction: Option<crate::scenario::CountertractionMetrics>,
    /// Laparoscopy: the time the point to keep in view was out of the camera's view (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_out_of_view_s: Option<f64>,
    /// How long the tool pressed beyond the depth the tissue model covers (s), and how far
    /// at most (mm): there the tissue stops stiffening and the force is extrapolated.
    pub beyond_range_s: f64,
    pub max_beyond_range_mm: f64,
    /// A complication (a perforated eye): the attempt fails whatever its score.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub complication: Option<String>,
    /// What the task's type measured of its own, once the attempt is scored (written beside
    /// the fields above in the report).
    #[serde(flatten)]
    pub outcome: Option<TaskOutcome>,
}

fn is_zero(count: &usize) -> bool {
    *count == 0
}

impl TaskMetrics {
    /// Every error made, listed or not.
    pub fn error_count(&self) -> usize {
        self.errors.len() + self.more_errors
    }

    /// What the task's type measured of its own, if it is an `R`.
    pub fn result<R: TaskResult>(&self) -> Option<&R> {
        self.outcome.as_ref()?.get()
    }
}

/// The results of type `R` among `tasks`', in order.
pub fn results_of<R: TaskResult>(tasks: &[TaskMetrics]) -> impl Iterator<Item = &R> {
    tasks.iter().filter_map(TaskMetrics::result::<R>)
}
