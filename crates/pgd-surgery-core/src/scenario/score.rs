//! The rubric applied to what the tasks measured: a score per task, an overall score 0–100,
//! pass or fail, and in words what went wrong.

use serde::Serialize;

use super::format::{Rubric, Scenario};
use super::global::{BenchmarkLine, GlobalMeasures};
use super::operation::OperationScore;
use super::phases::{PhaseTime, phase_times};
use super::task::TaskMetrics;
use super::units::Newtons;
use crate::biliary::ViewRecord;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TaskScore {
    pub metrics: TaskMetrics,
    /// 0–100.
    pub score: f64,
}

/// An attempt's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scorecard {
    pub title: String,
    pub tasks: Vec<TaskScore>,
    /// The mean of the task scores, 0–100.
    pub score: f64,
    pub pass_mark: f64,
    pub passed: bool,
    /// What went wrong, in words, for the debrief.
    pub feedback: Vec<String>,
    /// The scalpel's strokes, on every organ, in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub cuts: Vec<CutMade>,
    /// The operation's steps and errors, scored by the scenario's operation rubric.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operation: Option<OperationScore>,
    /// The operation's phases, in order, with their times (where the tasks name phases).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<PhaseTime>,
    /// The attempt's global measures, where the scenario scores an operation or holds the
    /// attempt to a benchmark...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global: Option<GlobalMeasures>,
    /// ...each benchmark value against the attempt's, and whether all were met.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub benchmark: Vec<BenchmarkLine>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub proficient: Option<bool>,
    /// What the critical view of safety was judged on when it was reached (or last, when it
    /// never was), for the report's doublet pictures; in a scene with a biliary tree.
    #[serde(skip)]
    pub critical_view: Option<ViewRecord>,
}

/// One stroke of the scalpel, as the report lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CutMade {
    pub organ: String,
    /// Where the tissue parted and where the cut reached (mm, the scene's frame).
    pub start_mm: [f64; 3],
    pub end_mm: [f64; 3],
    pub length_mm: f64,
    pub max_depth_mm: f64,
}

/// Scores `tasks` (in the scenario's order) by the scenario's rubric: the mean of the tasks'
/// scores, or the operation's score where the scenario has an operation rubric (a major
/// error then fails the attempt too).
pub fn score(scenario: &Scenario, tasks: Vec<TaskMetrics>) -> Scorecard {
    let rubric = &scenario.rubric;
    let operation = (scenario.operation.as_ref()).map(|operation| operation.score(&tasks));
    let global =
        (operation.is_some() || scenario.benchmark.is_some()).then(|| GlobalMeasures::of(&tasks));
    let phases = phase_times(scenario, &tasks);
    let tasks: Vec<TaskScore> = tasks
        .into_iter()
        .map(|metrics| TaskScore {
            score: task_score(rubric, &metrics),
            metrics,
        })
        .collect();
    let mean = tasks.iter().map(|t| t.score).sum::<f64>() / tasks.len().max(1) as f64;
    let score = operation.as_ref().map_or(mean, |o| o.score);
    let all_done = tasks.iter().all(|t| t.metrics.completed);
    let complication = tasks.iter().any(|t| t.metrics.complication.is_some());
    let major_error = operation.as_ref().is_some_and(|o| o.major_error);
    let passed = score >= rubric.pass_mark
        && (all_done || !rubric.all_tasks_required)
        && !complication
        && !major_error;
    let mut feedback: Vec<String> = tasks.iter().flat_map(task_feedback).collect();
    feedback.extend(operation.iter().flat_map(OperationScore::feedback));
    let benchmark = match (&scenario.benchmark, &global) {
        (Some(benchmark), Some(measures)) => benchmark.compare(measures, score),
        _ => Vec::new(),
    };
    feedback.extend(benchmark.iter().map(BenchmarkLine::describe));
    let proficient = scenario
        .benchmark
        .as_ref()
        .map(|_| benchmark.iter().all(|l| l.met));
    if score < rubric.pass_mark {
        feedback.push(format!(
            "the score {score:.0} is below the pass mark {:.0}",
            rubric.pass_mark
        ));
    }
    Scorecard {
        title: scenario.title.clone(),
        tasks,
        score,
        pass_mark: rubric.pass_mark,
        passed,
        feedback,
        cuts: Vec::new(),
        operation,
        phases,
        global,
        benchmark,
        proficient,
        critical_view: None,
    }
}

/// Completion, speed, force control and (where the task's type measures one) accuracy
/// weighted by the rubric, less the error penalties.
fn task_score(rubric: &Rubric, m: &TaskMetrics) -> f64 {
    let completion = f64::from(u8::from(m.completed));
    let speed = match m.completed {
        true => (1.0 - m.time_s / m.time_limit_s).clamp(0.0, 1.0),
        false => 0.0,
    };
    // Accuracy weighs only where there is a mark to be accurate about.
    let accuracy = m.outcome.as_ref().and_then(|o| o.accuracy());
    let terms = [
        (rubric.completion, completion),
        (rubric.speed, speed),
        (rubric.force, force_control(m)),
        (
            accuracy.map_or(0.0, |_| rubric.accuracy),
            accuracy.unwrap_or(0.0),
        ),
        (rubric.motion, economy(m)),
        (rubric.view, in_view(m)),
        (rubric.both_hands, both_hands(m)),
    ];
    let weights: f64 = terms.iter().map(|(w, _)| w).sum();
    let weighted = terms.iter().map(|(w, v)| w * v).sum::<f64>() / weights.max(f64::MIN_POSITIVE);
    (100.0 * weighted - rubric.error_penalty * m.error_count() as f64).clamp(0.0, 100.0)
}

/// How the hands worked together, as a share: with counter-traction, the share of the task's
/// time the other hand held its organ within its band; otherwise the share of the time on
/// tissue both hands worked at once (1 with one hand).
fn both_hands(m: &TaskMetrics) -> f64 {
    match (&m.countertraction, &m.hands) {
        (Some(countertraction), _) => countertraction.in_band_share(),
        (None, Some(hands)) => hands.together(),
        (None, None) => 1.0,
    }
}

/// Economy of motion as a share: the shortest path needed over the path taken (1 when the tip
/// never left its start: nothing was wasted).
fn economy(m: &TaskMetrics) -> f64 {
    m.motion.economy.map_or(1.0, |e| (1.0 / e).clamp(0.0, 1.0))
}

/// The share of the task's time in the camera's view: the mean over the tip (each hand's, in
/// a bimanual exercise) and the point to keep in view (those measured; 1 with none).
fn in_view(m: &TaskMetrics) -> f64 {
    // Both hands' tips, in a bimanual exercise.
    let tips = match &m.hands {
        Some(h) => [h.right.out_of_view_s, h.left.out_of_view_s],
        None => [m.motion.out_of_view_s, None],
    };
    let shares: Vec<f64> = tips
        .into_iter()
        .chain([m.target_out_of_view_s])
        .flatten()
        .map(|out_s| 1.0 - out_s / m.time_s.max(f64::MIN_POSITIVE))
        .collect();
    match shares.len() {
        0 => 1.0,
        n => (shares.iter().sum::<f64>() / n as f64).clamp(0.0, 1.0),
    }
}

/// The share of the time in contact spent as the task wants: under the limit, unless its
/// type says otherwise (force control: within the band; retraction: under the limits on the
/// tool and on the organs around). Without contact, what its type says (none for most, where
/// touching is the task; full marks in navigation).
fn force_control(m: &TaskMetrics) -> f64 {
    let outcome = m.outcome.as_ref();
    if m.contact_s <= 0.0 {
        return outcome.map_or(0.0, |o| o.untouched_force_share());
    }
    let off_s = outcome.map_or(m.time_over_limit_s, |o| o.off_target_s(m));
    (1.0 - off_s / m.contact_s).clamp(0.0, 1.0)
}

/// Time out of the camera's view the debrief mentions (s): a glance aside is not worth a line.
const NOTED_OUT_OF_VIEW_S: f64 = 0.5;

/// Counter-traction held in its band less than this share of a task's time gets a line.
const NOTED_IN_BAND: f64 = 0.95;

fn task_feedback(task: &TaskScore) -> Vec<String> {
    let m = &task.metrics;
    let outcome = m.outcome.as_ref();
    let mut lines = Vec::new();
    let unfinished = outcome.map_or(Some(String::new()), |o| o.unfinished());
    if let (false, Some(how_far)) = (m.completed, unfinished) {
        lines.push(format!(
            "not finished after {:.1} s of {:.0} s{how_far}",
            m.time_s, m.time_limit_s
        ));
    }
    if m.time_over_limit_s > 0.0 {
        lines.push(format!(
            "{:.1} s above {} N (peak {} N)",
            m.time_over_limit_s,
            Newtons(m.force_limit_n),
            Newtons(m.peak_force_n)
        ));
    }
    if let Some(out_s) = m.motion.out_of_view_s.filter(|&s| s >= NOTED_OUT_OF_VIEW_S) {
        lines.push(format!(
            "the instrument was out of the camera's view for {out_s:.1} s"
        ));
    }
    if let Some(out_s) = m.target_out_of_view_s.filter(|&s| s >= NOTED_OUT_OF_VIEW_S) {
        lines.push(format!(
            "the point to keep in view left the camera's view for {out_s:.1} s"
        ));
    }
    if m.beyond_range_s > 0.0 {
        lines.push(format!(
            "pressed up to {:.1} mm deeper than the tissue model covers, for {:.1} s: the \
             tissue stopped stiffening there, its force extrapolated from the range's edge",
            m.max_beyond_range_mm, m.beyond_range_s
        ));
    }
    lines.extend(outcome.map(|o| o.feedback()).unwrap_or_default());
    if let Some(c) = (m.countertraction.as_ref()).filter(|c| c.in_band_share() < NOTED_IN_BAND) {
        lines.push(format!(
            "the counter-traction was within its band {:.0} % of the time (slack {:.1} s, \
             too hard {:.1} s, not held {:.1} s)",
            100.0 * c.in_band_share(),
            c.slack_s,
            c.over_s,
            c.not_held_s
        ));
    }
    if let Some(complication) = &m.complication {
        lines.push(format!("complication: {complication}; the attempt fails"));
    }
    lines.extend(m.errors.iter().cloned());
    if m.more_errors > 0 {
        lines.push(format!("{} more errors", m.more_errors));
    }
    lines
        .into_iter()
        .map(|line| format!("{}: {line}", m.kind))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::parse;

    /// A finished task with full marks scores high, and passes; the same with a
    /// complication fails, whatever its score, and the debrief says why.
    #[test]
    fn a_complication_fails_the_attempt_whatever_its_score() {
        let scenario = parse(
            std::path::Path::new("t.scenario.ron"),
            r#"Scenario(title: "t", briefing: "b", organs: ["liver"],
                tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                                     hold_s: 1.0, time_limit_s: 10.0)])"#,
        )
        .unwrap();
        let band = crate::scenario::tasks::ForceControlResult {
            within_band_s: 2.0,
            ..Default::default()
        };
        let metrics = TaskMetrics {
            outcome: Some(crate::scenario::task::TaskOutcome::new(band)),
            completed: true,
            time_s: 2.0,
            time_limit_s: 10.0,
            contact_s: 2.0,
            ..TaskMetrics::default()
        };
        let clean = score(&scenario, vec![metrics.clone()]);
        assert!(clean.passed && clean.score > 80.0, "{clean:?}");
        let complicated = TaskMetrics {
            complication: Some("1.00 s: a perforation".into()),
            ..metrics
        };
        let card = score(&scenario, vec![complicated]);
        assert_eq!(card.score, clean.score);
        assert!(!card.passed);
        assert!(
            card.feedback
                .iter()
                .any(|l| l.contains("the attempt fails"))
        );
    }
}
