//! The rubric applied to what the tasks measured: a score per task, an overall score 0–100,
//! pass or fail, and in words what went wrong.

use serde::Serialize;

use super::exercise::{COVERED_TO_FINISH, TaskMetrics};
use super::format::{Rubric, Scenario, TaskKind};
use super::incision::IncisionMetrics;
use super::keratotomy::KeratotomyMetrics;
use super::units::Newtons;

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

/// Scores `tasks` (in the scenario's order) by the scenario's rubric.
pub fn score(scenario: &Scenario, tasks: Vec<TaskMetrics>) -> Scorecard {
    let rubric = &scenario.rubric;
    let tasks: Vec<TaskScore> = tasks
        .into_iter()
        .map(|metrics| TaskScore {
            score: task_score(rubric, &metrics),
            metrics,
        })
        .collect();
    let score = tasks.iter().map(|t| t.score).sum::<f64>() / tasks.len().max(1) as f64;
    let all_done = tasks.iter().all(|t| t.metrics.completed);
    let complication = tasks.iter().any(|t| t.metrics.complication.is_some());
    let passed =
        score >= rubric.pass_mark && (all_done || !rubric.all_tasks_required) && !complication;
    let mut feedback: Vec<String> = tasks.iter().flat_map(task_feedback).collect();
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
    }
}

/// Completion, speed, force control and (palpation) accuracy weighted by the rubric, less the
/// error penalties.
fn task_score(rubric: &Rubric, m: &TaskMetrics) -> f64 {
    let completion = f64::from(u8::from(m.completed));
    let speed = match m.completed {
        true => (1.0 - m.time_s / m.time_limit_s).clamp(0.0, 1.0),
        false => 0.0,
    };
    // Accuracy weighs only where there is a mark to be accurate about.
    let accuracy_weight = match m.kind {
        TaskKind::Palpation | TaskKind::Incision | TaskKind::RadialKeratotomy => rubric.accuracy,
        TaskKind::ForceControl
        | TaskKind::SafeNavigation
        | TaskKind::Retraction
        | TaskKind::Grasp => 0.0,
    };
    let terms = [
        (rubric.completion, completion),
        (rubric.speed, speed),
        (rubric.force, force_control(m)),
        (accuracy_weight, accuracy(m)),
        (rubric.motion, economy(m)),
        (rubric.view, in_view(m)),
    ];
    let weights: f64 = terms.iter().map(|(w, _)| w).sum();
    let weighted = terms.iter().map(|(w, v)| w * v).sum::<f64>() / weights.max(f64::MIN_POSITIVE);
    (100.0 * weighted - rubric.error_penalty * m.error_count() as f64).clamp(0.0, 100.0)
}

/// Economy of motion as a share: the shortest path needed over the path taken (1 when the tip
/// never left its start: nothing was wasted).
fn economy(m: &TaskMetrics) -> f64 {
    m.motion.economy.map_or(1.0, |e| (1.0 / e).clamp(0.0, 1.0))
}

/// The share of the task's time in the camera's view: the mean over the tip and the point to
/// keep in view (those measured; 1 with neither).
fn in_view(m: &TaskMetrics) -> f64 {
    let shares: Vec<f64> = [m.motion.out_of_view_s, m.target_out_of_view_s]
        .into_iter()
        .flatten()
        .map(|out_s| 1.0 - out_s / m.time_s.max(f64::MIN_POSITIVE))
        .collect();
    match shares.len() {
        0 => 1.0,
        n => (shares.iter().sum::<f64>() / n as f64).clamp(0.0, 1.0),
    }
}

/// Palpation: 1 for a mark on the nodule, falling linearly to 0 at twice the distance that
/// counts as found; 0 without a mark. Incision: the mean of the line's accuracy (1 on it,
/// falling to 0 at twice the tolerance off it on average) and the depth's (1 at the target,
/// falling to 0 at half or twice as deep); 0 with nothing cut.
///
/// Radial keratotomy: the mean of the symmetry (1 evenly spaced, 0 when a gap is off by half
/// the even spacing), the optical zone (1 clear, 0 cut to the axis), the depth's accuracy (as
/// an incision's) and the correction's (1 on the target, 0 at twice the tolerance off it, or
/// when it could not be predicted); 0 with no incision.
fn accuracy(m: &TaskMetrics) -> f64 {
    if let Some(cut) = &m.incision {
        if cut.covered_mm <= 0.0 {
            return 0.0;
        }
        let line = 1.0 - cut.mean_deviation_mm / (2.0 * cut.tolerance_mm);
        let depth = depth_accuracy(cut.mean_depth_mm / cut.target_depth_mm);
        return 0.5 * (line.clamp(0.0, 1.0) + depth);
    }
    if let Some(rk) = &m.keratotomy {
        return keratotomy_accuracy(rk);
    }
    match (m.localization_error_mm, m.found_within_mm) {
        (Some(error), Some(within)) => (1.0 - error / (2.0 * within)).clamp(0.0, 1.0),
        _ => 0.0,
    }
}

/// 1 at the target depth (`ratio` of it 1), falling to 0 at half or twice as deep.
fn depth_accuracy(ratio: f64) -> f64 {
    (1.0 - ratio.ln().abs() / 2f64.ln()).clamp(0.0, 1.0)
}

fn keratotomy_accuracy(rk: &KeratotomyMetrics) -> f64 {
    let made = rk.incisions.len();
    if made == 0 {
        return 0.0;
    }
    let symmetry = 1.0 - rk.spacing_error_deg / (180.0 / made as f64);
    let zone = 1.0 - rk.zone_intrusion_mm / (rk.optical_zone_mm / 2.0);
    let depth = depth_accuracy(rk.mean_depth_fraction / rk.target_depth_fraction);
    let correction = rk.predicted_correction_d.map_or(0.0, |d| {
        1.0 - (d - rk.target_correction_d).abs() / (2.0 * rk.correction_tolerance_d)
    });
    let terms = [symmetry, zone, depth, correction];
    terms.iter().map(|t| t.clamp(0.0, 1.0)).sum::<f64>() / terms.len() as f64
}

/// The share of the time in contact spent as the task wants: within the band (force control),
/// under the limit (safe navigation and palpation; retraction, under the limits on the tool
/// and on the organs around; full marks if the tool never touched in safe navigation, none in
/// the others, where touching is the task).
fn force_control(m: &TaskMetrics) -> f64 {
    if m.contact_s <= 0.0 {
        return match m.kind {
            TaskKind::ForceControl
            | TaskKind::Palpation
            | TaskKind::Retraction
            | TaskKind::Grasp
            | TaskKind::Incision
            | TaskKind::RadialKeratotomy => 0.0,
            TaskKind::SafeNavigation => 1.0,
        };
    }
    let over_s = match m.kind {
        TaskKind::ForceControl => m.contact_s - m.within_band_s,
        TaskKind::SafeNavigation
        | TaskKind::Palpation
        | TaskKind::Grasp
        | TaskKind::Incision
        | TaskKind::RadialKeratotomy => m.time_over_limit_s,
        TaskKind::Retraction => m.time_over_limit_s + m.surrounding_over_limit_s,
    };
    (1.0 - over_s / m.contact_s).clamp(0.0, 1.0)
}

/// Time out of the camera's view the debrief mentions (s): a glance aside is not worth a line.
const NOTED_OUT_OF_VIEW_S: f64 = 0.5;

fn task_feedback(task: &TaskScore) -> Vec<String> {
    let m = &task.metrics;
    let mut lines = Vec::new();
    if !m.completed && m.localization_error_mm.is_none() {
        let what = match (m.targets, m.moved_mm, m.move_target_mm) {
            (0, Some(moved), Some(target)) if moved < target => {
                format!(" (moved at most {moved:.0} of {target:.0} mm)")
            }
            (0, _, _) => match m.hold_s {
                Some(hold) => format!(" (held {:.1} s of {hold:.1} s)", m.longest_hold_s),
                None => String::new(),
            },
            (n, _, _) => format!(" ({} of {n} targets reached)", m.targets_reached),
        };
        lines.push(format!(
            "{}: not finished after {:.1} s of {:.0} s{what}",
            m.kind, m.time_s, m.time_limit_s
        ));
    }
    if let (Some(error), Some(within)) = (m.localization_error_mm, m.found_within_mm)
        && error > within
    {
        lines.push(format!(
            "{}: marked {error:.0} mm from the nodule; within {within:.0} mm counts as found",
            m.kind
        ));
    }
    if m.time_over_limit_s > 0.0 {
        lines.push(format!(
            "{}: {:.1} s above {} N (peak {} N)",
            m.kind,
            m.time_over_limit_s,
            Newtons(m.force_limit_n),
            Newtons(m.peak_force_n)
        ));
    }
    if let Some(out_s) = m.motion.out_of_view_s.filter(|&s| s >= NOTED_OUT_OF_VIEW_S) {
        lines.push(format!(
            "{}: the instrument was out of the camera's view for {out_s:.1} s",
            m.kind
        ));
    }
    if let Some(out_s) = m.target_out_of_view_s.filter(|&s| s >= NOTED_OUT_OF_VIEW_S) {
        lines.push(format!(
            "{}: the point to keep in view left the camera's view for {out_s:.1} s",
            m.kind
        ));
    }
    if let Some(limit) = m.surrounding_limit_n
        && m.surrounding_over_limit_s > 0.0
    {
        lines.push(format!(
            "{}: {:.1} s loading the organs around above {} N (peak {} N)",
            m.kind,
            m.surrounding_over_limit_s,
            Newtons(limit),
            Newtons(m.surrounding_peak_n)
        ));
    }
    if m.beyond_range_s > 0.0 {
        lines.push(format!(
            "{}: pressed up to {:.1} mm deeper than the tissue model covers, for {:.1} s: the \
             tissue stopped stiffening there, its force extrapolated from the range's edge",
            m.kind, m.max_beyond_range_mm, m.beyond_range_s
        ));
    }
    if let Some(cut) = &m.incision {
        lines.extend(incision_feedback(m.kind, cut));
    }
    if let Some(rk) = &m.keratotomy {
        lines.extend(keratotomy_feedback(m.kind, rk));
    }
    if let Some(complication) = &m.complication {
        lines.push(format!(
            "{}: complication: {complication}; the attempt fails",
            m.kind
        ));
    }
    lines.extend(m.errors.iter().map(|e| format!("{}: {e}", m.kind)));
    if m.more_errors > 0 {
        lines.push(format!("{}: {} more errors", m.kind, m.more_errors));
    }
    lines
}

/// What an incision's cut missed: the line, its depth.
fn incision_feedback(kind: TaskKind, cut: &IncisionMetrics) -> Vec<String> {
    let mut lines = Vec::new();
    if cut.covered_mm < COVERED_TO_FINISH * cut.line_length_mm {
        lines.push(format!(
            "{kind}: cut {:.0} of the line's {:.0} mm (strokes: {})",
            cut.covered_mm, cut.line_length_mm, cut.strokes
        ));
    }
    if cut.mean_deviation_mm > cut.tolerance_mm {
        lines.push(format!(
            "{kind}: {:.1} mm off the line on average (within {:.0} mm counts)",
            cut.mean_deviation_mm, cut.tolerance_mm
        ));
    }
    let (depth, target) = (cut.mean_depth_mm, cut.target_depth_mm);
    if cut.covered_mm > 0.0 && !(0.75 * target..=1.25 * target).contains(&depth) {
        lines.push(format!(
            "{kind}: cut {depth:.1} mm deep on average for {target:.0} mm"
        ));
    }
    lines
}

/// What a keratotomy got wrong, and always the correction it is predicted to give.
fn keratotomy_feedback(kind: TaskKind, rk: &KeratotomyMetrics) -> Vec<String> {
    let mut lines = Vec::new();
    let made = rk.incisions.len();
    if made != rk.planned {
        lines.push(format!("{kind}: {made} incisions made of {}", rk.planned));
    }
    if made > 1 && rk.spacing_error_deg > 90.0 / made as f64 {
        lines.push(format!(
            "{kind}: unevenly spaced: a gap {:.0}° off the even {:.0}°",
            rk.spacing_error_deg,
            360.0 / made as f64
        ));
    }
    if rk.zone_intrusion_mm > 0.0 {
        lines.push(format!(
            "{kind}: cut {:.1} mm into the {:.1} mm optical zone",
            rk.zone_intrusion_mm, rk.optical_zone_mm
        ));
    }
    let (depth, target) = (rk.mean_depth_fraction, rk.target_depth_fraction);
    if made > 0 && (depth - target).abs() > 0.1 {
        lines.push(format!(
            "{kind}: {:.0} % deep on average for {:.0} %",
            100.0 * depth,
            100.0 * target
        ));
    }
    let target = rk.target_correction_d;
    lines.push(match rk.predicted_correction_d {
        Some(d) => format!(
            "{kind}: predicted correction {d:.1} D for {target:.1} D (within {:.1} D counts)",
            rk.correction_tolerance_d
        ),
        None if made == 0 => format!("{kind}: no incision, no correction"),
        None => format!("{kind}: the correction could not be predicted"),
    });
    lines
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
        let metrics = TaskMetrics {
            completed: true,
            time_s: 2.0,
            time_limit_s: 10.0,
            contact_s: 2.0,
            within_band_s: 2.0,
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
