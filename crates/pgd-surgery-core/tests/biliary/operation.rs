//! A clip-and-cut scored by an operation rubric (steps and errors with their points, after
//! Eubanks et al. 1999), through the task's exercise: the competent run earns every step and
//! makes no error; the careless run's errors each cost their points every time, listed in
//! the order made; a bile duct injury, a major error, fails the attempt. And a rubric that
//! cannot be scored refused at its line.

use std::path::Path;

use pgd_surgery_core::biliary::Structure;
use pgd_surgery_core::scenario::{OperationScore, Scenario, parse, score};

use super::task::{ARTERY, DUCT, Event, INSTRUMENTS, careless, competent, run_on, scenario_text};

const OPERATION: &str = r#"operation: Operation(
        steps: [
            Step(name: "cystic duct and artery clipped and divided", points: 10.0, done: Finished(1)),
            Step(name: "critical view of safety before any clip", points: 20.0, done: CriticalView),
            Step(name: "cystic duct divided between clips", points: 15.0, done: DividedBetweenClips(CysticDuct)),
            Step(name: "cystic artery divided between clips", points: 15.0, done: DividedBetweenClips(CysticArtery)),
        ],
        errors: [
            Error(name: "clip or division before the critical view", points: 5.0, made: BeforeCriticalView),
            Error(name: "a stump left open", points: 5.0, made: OpenStump),
            Error(name: "bleeding from the cystic artery", points: 10.0, made: BloodLost(1.0)),
            Error(name: "bile duct injury", points: 50.0, major: true, made: BileDuctInjury),
        ],
    ),"#;

fn operation_scenario(
    operation: &str,
) -> Result<Scenario, pgd_surgery_core::scenario::ScenarioError> {
    let text = scenario_text("biliary: Biliary(),", INSTRUMENTS, "").replace(
        "\n)",
        &format!("\n    rubric: Rubric(pass_mark: 70.0),\n    {operation}\n)"),
    );
    parse(Path::new("operation.scenario.ron"), &text)
}

fn scored(events: &[(f64, Event)]) -> (OperationScore, bool, f64, Vec<String>) {
    let (scenario, metrics) = run_on(operation_scenario(OPERATION).unwrap(), events);
    let card = score(&scenario, metrics);
    let operation = card.operation.unwrap();
    (operation, card.passed, card.score, card.feedback)
}

fn done(operation: &OperationScore) -> Vec<Option<f64>> {
    operation.steps.iter().map(|s| s.done_s).collect()
}

fn made(operation: &OperationScore) -> Vec<Vec<f64>> {
    (operation.errors.iter())
        .map(|e| e.made.iter().map(|o| o.time_s).collect())
        .collect()
}

#[test]
fn the_competent_run_earns_every_step_and_makes_no_error() {
    let (operation, passed, card_score, _) = scored(&competent());
    assert_eq!(
        done(&operation),
        [Some(19.0), Some(5.0), Some(12.0), Some(19.0)]
    );
    assert!(made(&operation).iter().all(Vec::is_empty), "{operation:?}");
    assert_eq!((operation.points, operation.possible), (60.0, 60.0));
    assert_eq!((card_score, passed), (100.0, true));
}

/// A clip and a cut on the duct before the view, the artery cut with one clip on the
/// gallbladder's side only: two errors before the view, two open stumps, the bleeding; the
/// view itself reached after a clip, so that step not earned; the divisions not between
/// clips.
#[test]
fn the_careless_run_pays_for_each_error_each_time_in_the_order_made() {
    let (operation, passed, card_score, feedback) = scored(&careless());
    let steps = done(&operation);
    assert_eq!(steps[1..], [None, None, None], "{operation:?}");
    let errors = made(&operation);
    assert_eq!(errors[0], [3.0, 4.0]);
    assert_eq!(errors[1], [4.0, 9.0]);
    assert_eq!(errors[2].len(), 1, "bleeding once");
    assert!(errors[3].is_empty());
    let finished = if steps[0].is_some() { 10.0 } else { 0.0 };
    assert_eq!(operation.points, finished - 2.0 * 5.0 - 2.0 * 5.0 - 10.0);
    assert_eq!(card_score, 0.0, "the score floors at 0");
    assert!(!passed);
    let lines: Vec<&String> = feedback.iter().filter(|l| l.contains("points")).collect();
    let first = |what: &str| lines.iter().position(|l| l.contains(what)).unwrap();
    assert!(
        lines[0].starts_with(
            "3.0 s: clip or division before the critical view, the cystic duct (−5 points"
        ),
        "{lines:?}"
    );
    assert!(
        first("4.0 s: a stump left open, the cystic duct")
            < first("9.0 s: a stump left open, the cystic artery")
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("not done: critical view of safety"))
    );
}

/// The common bile duct divided: a major error fails the attempt whatever the points.
#[test]
fn a_bile_duct_injury_fails_the_operation() {
    let scenario = operation_scenario(OPERATION).unwrap();
    let tree = scenario.biliary.as_ref().unwrap().tree().unwrap();
    let share = (tree.junction_arc_m() + 6e-3) / tree.tube(Structure::CommonDuct).length_m();
    let (scenario, metrics) = run_on(
        scenario,
        &[
            (5.0, Event::View),
            (6.0, Event::Cut(Structure::CommonDuct, share)),
        ],
    );
    let card = score(&scenario, metrics);
    let operation = card.operation.as_ref().unwrap();
    assert_eq!(made(operation)[3], [6.0]);
    assert!(operation.major_error && !card.passed);
    assert!(
        card.feedback
            .iter()
            .any(|l| l
                == "6.0 s: bile duct injury, the common bile duct (−50 points, a major error)"),
        "{:?}",
        card.feedback
    );
}

#[test]
fn an_operation_rubric_that_cannot_be_scored_is_refused_at_its_line() {
    let error = |operation: &str| operation_scenario(operation).unwrap_err();
    let late = error(
        r#"operation: Operation(steps: [
        Step(name: "done", points: 5.0, done: Finished(2)),
    ]),"#,
    );
    assert_eq!(late.field, "operation.steps[0]");
    assert!(late.message.contains("there is no task 2"), "{late}");
    assert_eq!((late.line, late.column), (15, 20), "{late}");
    let unread = error(
        r#"operation: Operation(steps: [
        Step(name: "freed", points: 5.0, done: Released(0.9)),
    ]),"#,
    );
    assert!(
        unread.message.contains("read from a Dissection task"),
        "{unread}"
    );
    let free = error(
        r#"operation: Operation(steps: [
        Step(name: "view", points: 0.0, done: CriticalView),
    ]),"#,
    );
    assert_eq!(free.field, "operation.steps[0].points");
    let none = error("operation: Operation(steps: []),");
    assert!(none.message.contains("no steps"), "{none}");
}

const BENCHMARK: &str = "benchmark: Benchmark(score: 90.0, time_s: 30.0, blood_lost_ml: 0.5),";

/// Held to a benchmark, the competent run is proficient and the careless one not, each value
/// said in the debrief; a benchmark value out of range is refused at its line.
#[test]
fn the_benchmark_says_which_run_is_proficient() {
    let scenario = || operation_scenario(&format!("{OPERATION}\n    {BENCHMARK}")).unwrap();
    let (scenario_run, metrics) = run_on(scenario(), &competent());
    let card = score(&scenario_run, metrics);
    assert_eq!(card.proficient, Some(true), "{:?}", card.benchmark);
    assert_eq!(card.benchmark.len(), 3);
    let global = card.global.as_ref().unwrap();
    assert!(
        global.time_s <= 30.0 && global.blood_lost_ml == 0.0,
        "{global:?}"
    );
    assert!(
        card.feedback
            .iter()
            .any(|l| l.starts_with("benchmark time (s): ") && l.ends_with("met")),
        "{:?}",
        card.feedback
    );
    let careless = [
        (3.0, Event::Clip(DUCT, 0.2)),
        (4.0, Event::Cut(DUCT, 0.6)),
        (8.0, Event::Cut(ARTERY, 0.5)),
    ];
    let (scenario_run, metrics) = run_on(scenario(), &careless);
    let card = score(&scenario_run, metrics);
    assert_eq!(card.proficient, Some(false));
    let debrief = pgd_surgery_core::report::summary(&card);
    let missing = pgd_surgery_core::report::without_glyph(&debrief);
    assert!(missing.is_empty(), "no glyph for {missing:?} in {debrief}");
    let unmet: Vec<&str> = (card.benchmark.iter().filter(|l| !l.met))
        .map(|l| l.measure)
        .collect();
    assert!(
        unmet.contains(&"score") && unmet.contains(&"blood lost (ml)"),
        "{unmet:?}"
    );

    let wrong = operation_scenario(&format!(
        "{OPERATION}\n    benchmark: Benchmark(both_hands_share: 1.5),"
    ))
    .unwrap_err();
    assert_eq!(wrong.field, "benchmark.both_hands_share");
    assert!(wrong.hint.contains("from 0 to 1"), "{wrong}");
}
