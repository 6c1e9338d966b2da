//! The phases of an operation: consecutive tasks given the same `phase` ("exposure",
//! "Calot's triangle", "the bed"), timed together for the debrief, as a surgeon reads an
//! operation by its phases.

use serde::Serialize;

use super::format::Scenario;
use super::task::TaskMetrics;

/// A phase as the attempt went through it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PhaseTime {
    pub name: String,
    /// When its first task started and its last ended (s from the attempt's start).
    pub started_s: f64,
    pub ended_s: f64,
    pub tasks: usize,
    /// Whether every one of its tasks was finished.
    pub completed: bool,
}

/// The named phases of `scenario`'s tasks, in order, timed from the attempt's `tasks` (one
/// per scenario task, as scored); none when no task names one.
pub fn phase_times(scenario: &Scenario, tasks: &[TaskMetrics]) -> Vec<PhaseTime> {
    let mut phases: Vec<PhaseTime> = Vec::new();
    let mut previous: Option<&str> = None;
    for (task, metrics) in scenario.tasks.iter().zip(tasks) {
        let name = task.shared.phase.as_deref();
        let ended_s = metrics.started_s + metrics.time_s;
        match (name, phases.last_mut()) {
            (Some(name), Some(last)) if previous == Some(name) => {
                last.ended_s = ended_s;
                last.tasks += 1;
                last.completed &= metrics.completed;
            }
            (Some(name), _) => phases.push(PhaseTime {
                name: name.to_owned(),
                started_s: metrics.started_s,
                ended_s,
                tasks: 1,
                completed: metrics.completed,
            }),
            (None, _) => {}
        }
        previous = name;
    }
    phases
}

/// A phase named again after another began: the task (from 0) that names it again, its name,
/// and the phase between.
pub fn phase_out_of_order(scenario: &Scenario) -> Option<(usize, String, String)> {
    let names: Vec<Option<&str>> = (scenario.tasks.iter())
        .map(|t| t.shared.phase.as_deref())
        .collect();
    (1..names.len()).find_map(|k| {
        let name = names[k]?;
        let between = names[k - 1].filter(|&before| before != name)?;
        names[..k - 1]
            .contains(&Some(name))
            .then(|| (k, name.to_owned(), between.to_owned()))
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::scenario::{parse, score};

    /// Three presses on the liver, in the phases `phases`.
    fn text(phases: [&str; 3]) -> String {
        let task = |phase: &str| {
            format!(
                "ForceControl(organ: \"liver\", min_force_n: 0.15, max_force_n: 0.35, \
                 hold_s: 3.0, time_limit_s: 20.0, phase: \"{phase}\"),"
            )
        };
        format!(
            "Scenario(\n    title: \"Phases\",\n    briefing: \"Press.\",\n    organs: [\"liver\"],\n    \
             tasks: [\n        {}\n        {}\n        {}\n    ],\n)",
            task(phases[0]),
            task(phases[1]),
            task(phases[2])
        )
    }

    fn metrics(started_s: f64, time_s: f64, completed: bool) -> TaskMetrics {
        TaskMetrics {
            started_s,
            time_s,
            completed,
            ..TaskMetrics::default()
        }
    }

    /// Two tasks of one phase, then one of another: two phases, in order, each from its
    /// first task's start to its last's end, done only if all its tasks were; the summary
    /// says them.
    #[test]
    fn the_phases_follow_the_scenarios_order_with_their_times() {
        let file = Path::new("phases.scenario.ron");
        let scenario = parse(file, &text(["exposure", "exposure", "palpation"])).unwrap();
        let tasks = vec![
            metrics(0.0, 8.0, true),
            metrics(8.0, 12.0, true),
            metrics(20.0, 20.0, false),
        ];
        let card = score(&scenario, tasks);
        let phases: Vec<_> = (card.phases.iter())
            .map(|p| {
                (
                    p.name.as_str(),
                    p.started_s,
                    p.ended_s,
                    p.tasks,
                    p.completed,
                )
            })
            .collect();
        assert_eq!(
            phases,
            [
                ("exposure", 0.0, 20.0, 2, true),
                ("palpation", 20.0, 40.0, 1, false)
            ]
        );
        let summary = crate::report::summary(&card);
        assert!(
            summary.contains("phase 1, exposure: 0.0 to 20.0 s (20.0 s), done"),
            "{summary}"
        );
        assert!(summary.contains("phase 2, palpation: 20.0 to 40.0 s (20.0 s), not done"));
    }

    /// A phase named again after another began is refused at the task that names it again.
    #[test]
    fn a_phase_named_again_after_another_is_refused_at_its_line() {
        let file = Path::new("phases.scenario.ron");
        let error = parse(file, &text(["exposure", "palpation", "exposure"])).unwrap_err();
        assert_eq!(error.field, "tasks[2].phase");
        assert_eq!(error.line, 8, "{error}");
        assert!(
            error
                .message
                .contains("`exposure` again, after `palpation`"),
            "{error}"
        );
    }
}
