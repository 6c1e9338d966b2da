//! A task type made up here, registered here, and run here: adding a task touches its own
//! module and the registry, nothing else. `Tap(organ, taps, max_force_n, time_limit_s)`
//! asks for so many separate touches of the organ, none held longer than a second.

use std::path::Path;

use pgd_surgery_core::scenario::task::{
    RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
};
use pgd_surgery_core::scenario::{Exercise, Sample, Sites, parse, register, score};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct Tap {
    taps: usize,
}

/// The mistake of staying on the organ too long (the time held, s, the amount).
const LINGERED: u16 = 0;
const LINGER_S: f64 = 1.0;

impl TaskType for Tap {
    const NAME: &'static str = "Tap";
    const LABEL: &'static str = "tap";
    type Run = TapRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "tap the {} {} times",
            shared.organ.as_deref().unwrap_or_default(),
            self.taps
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        if self.taps == 0 {
            check.problem("taps", "no taps to make", "ask for at least one");
        }
    }

    fn run(&self, _: &TaskShared, setup: RunSetup) -> TapRun {
        TapRun {
            organ: setup.organ.expect("the organ is in the scene"),
            taps: self.taps,
            made: 0,
            touching_since_s: None,
        }
    }

    fn describe_mistake(&self, shared: &TaskShared, code: u16, held_s: f64) -> String {
        assert_eq!(code, LINGERED);
        let organ = shared.organ.as_deref().unwrap_or_default();
        format!("stayed on the {organ} for {held_s:.1} s")
    }
}

#[derive(Clone, Debug)]
struct TapRun {
    organ: usize,
    taps: usize,
    made: usize,
    touching_since_s: Option<f64>,
}

impl TaskRun for TapRun {
    type Result = TapResult;

    fn step(&mut self, tick: &mut Tick<'_>) {
        let (touching, now_s) = (tick.sample.touches(self.organ), tick.sample.time_s);
        match (touching, self.touching_since_s) {
            (true, None) => {
                self.touching_since_s = Some(now_s);
                self.made += 1;
            }
            (false, Some(since_s)) => {
                self.touching_since_s = None;
                if now_s - since_s > LINGER_S {
                    tick.mistake(LINGERED, now_s - since_s);
                }
            }
            _ => {}
        }
        tick.metrics.completed = self.made >= self.taps && !touching;
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(TaskProgress {
            what: "taps",
            done: self.made as f64,
            of: self.taps as f64,
            unit: "",
        })
    }

    fn result(&self) -> TapResult {
        TapResult {
            taps_made: self.made,
            taps: self.taps,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
struct TapResult {
    taps_made: usize,
    taps: usize,
}

impl TaskResult for TapResult {
    fn accuracy(&self) -> Option<f64> {
        Some((self.taps_made as f64 / self.taps as f64).min(1.0))
    }

    fn unfinished(&self) -> Option<String> {
        Some(format!(" ({} of {} taps)", self.taps_made, self.taps))
    }
}

fn scenario_with(task: &str) -> String {
    format!(
        r#"Scenario(title: "taps", briefing: "tap", organs: ["liver"],
               tasks: [{task}])"#
    )
}

const TAPS: &str = r#"Tap(organ: "liver", taps: 3, max_force_n: 2.0, time_limit_s: 10.0)"#;

/// Registered, the type reads from a scenario with its own and the shared fields, checks its
/// own, runs tick by tick with its progress and mistakes, and scores: three taps, one held too
/// long.
#[test]
fn a_task_type_registered_in_a_test_module_reads_runs_and_scores() {
    register::<Tap>();
    let file = Path::new("taps.scenario.ron");
    let scenario = parse(file, &scenario_with(TAPS)).unwrap();
    let task = &scenario.tasks[0];
    assert_eq!(task.get::<Tap>(), Some(&Tap { taps: 3 }));
    assert_eq!(
        (task.organ(), task.max_force_n(), task.time_limit_s()),
        (Some("liver"), 2.0, 10.0)
    );
    assert_eq!(task.description(), "tap the liver 3 times");

    let mut exercise = Exercise::new(scenario, Sites::default());
    // Touch at 0.1–0.3 s, 0.5–2.0 s (too long) and 2.2–2.4 s, then lift.
    let touches = [(0.1, 0.3), (0.5, 2.0), (2.2, 2.4)];
    let mut progress = Vec::new();
    for tick in 0..3000 {
        let time_s = f64::from(tick) * 1e-3;
        let touching = touches.iter().any(|&(a, b)| (a..b).contains(&time_s));
        exercise.step(&Sample {
            time_s,
            touching: u64::from(touching),
            force_n: if touching { 0.5 } else { 0.0 },
            ..Sample::default()
        });
        progress.extend(exercise.progress().step.map(|p| p.to_string()));
    }
    assert!(exercise.finished());
    assert!(progress.contains(&"taps 2 of 3".to_owned()), "{progress:?}");
    let finished = exercise.finish();
    let (scenario, metrics) = (finished.scenario, finished.tasks);
    let m = &metrics[0];
    assert!(m.completed, "{m:#?}");
    assert_eq!((m.kind, m.time_s.round()), ("tap", 2.0));
    assert_eq!(
        m.result::<TapResult>(),
        Some(&TapResult {
            taps_made: 3,
            taps: 3
        })
    );
    assert_eq!(m.errors, ["2.00 s: stayed on the liver for 1.5 s"]);
    let card = score(&scenario, metrics);
    assert!(card.feedback.iter().any(|l| l.starts_with("tap: ")));
    let json = serde_json::to_value(&card).unwrap();
    assert_eq!(json["tasks"][0]["metrics"]["taps_made"], 3);
}

/// Its fields are checked as the built-in types' are: its own check, an unknown field (the
/// hint lists its own and the shared ones), a shared field missing, and a misspelt type
/// name (the hint lists the registered ones).
#[test]
fn a_registered_task_types_errors_name_the_field_and_the_place() {
    register::<Tap>();
    let file = Path::new("taps.scenario.ron");
    let error = |task: &str| parse(file, &scenario_with(task)).unwrap_err();

    let none = error(r#"Tap(organ: "liver", taps: 0, max_force_n: 2.0, time_limit_s: 10.0)"#);
    assert_eq!(none.field, "tasks[0].taps");
    assert!(none.message.contains("no taps"), "{none}");

    let typo = error(r#"Tap(organ: "liver", tops: 3, max_force_n: 2.0, time_limit_s: 10.0)"#);
    assert!(typo.message.contains("tops"), "{typo}");
    for field in ["taps", "organ", "max_force_n", "time_limit_s"] {
        assert!(typo.hint.contains(field), "{typo}");
    }
    assert_eq!((typo.line, typo.column > 20), (2, true), "{typo}");

    let missing = error(r#"Tap(organ: "liver", taps: 3, max_force_n: 2.0)"#);
    assert!(missing.message.contains("time_limit_s"), "{missing}");

    let misspelt = error(r#"Tapp(organ: "liver", taps: 3, max_force_n: 2.0, time_limit_s: 1.0)"#);
    assert!(misspelt.hint.contains("Tap") && misspelt.hint.contains("ForceControl"));
}
