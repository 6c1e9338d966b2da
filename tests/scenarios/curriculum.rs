//! The shipped curriculum and where trainees stand in it: modules open as the proficiency
//! rules are met on the attempts kept in the history, a failed attempt (a complication) never
//! counts; bad curriculum files are refused with their line, field and hint.

use std::path::{Path, PathBuf};
use std::process::Command;

use pgd_surgery::history::{AttemptRecord, History};
use pgd_surgery::scenario::curriculum::load_curriculum;

use crate::{TRAINER, assert_refused, root};

const SHIPPED: &str = "curricula/cholecystectomy.curriculum.ron";

fn attempt(trainee: &str, name: &str, score: f64, passed: bool, at_unix_s: i64) -> AttemptRecord {
    AttemptRecord {
        id: 0,
        uid: String::new(),
        station: String::new(),
        trainee: trainee.into(),
        scenario: format!("scenarios/{name}.scenario.ron"),
        title: name.into(),
        at_unix_s,
        score,
        passed,
        time_s: 10.0,
        path_mm: 100.0,
        peak_force_n: 0.3,
        errors: 0,
        report: String::new(),
        proficient: None,
    }
}

/// `trainer curriculum` on the shipped curriculum for `trainee`, from `db`.
fn standing(db: &Path, trainee: &str) -> String {
    let output = Command::new(TRAINER)
        .current_dir(root())
        .args(["curriculum", SHIPPED, "--trainee", trainee, "--history"])
        .arg(db)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    String::from_utf8(output.stdout).unwrap()
}

/// Ada passes every basic skill at 85 twice in a row but the palpation, where a failed
/// attempt at 90 (a complication) breaks her run: the basics stay open, the tasks locked.
/// One more passed palpation and the basics are done, the tasks open; Bob, with no attempt,
/// has the basics open and the tasks locked. The cohort's view has a row each, the exercises
/// each has had, and their learning curves as a plot and CSV.
#[test]
fn the_curriculum_opens_its_modules_as_the_benchmarks_are_met() {
    let curriculum = load_curriculum(&root().join(SHIPPED)).unwrap();
    let basics: Vec<String> = (curriculum.modules[0].exercises.iter())
        .map(|e| {
            e.scenario
                .file_name()
                .unwrap()
                .to_string_lossy()
                .replace(".scenario.ron", "")
        })
        .collect();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("curriculum-standing");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let db = dir.join("history.sqlite");
    let history = History::open(&db).unwrap();
    let mut at = 1_700_000_000;
    let mut keep = |name: &str, score: f64, passed: bool| {
        at += 60;
        history
            .record(&attempt("ada", name, score, passed, at))
            .unwrap();
    };
    for name in &basics {
        keep(name, 85.0, true);
        if name == "pancreas-palpation" {
            keep(name, 90.0, false);
        }
        keep(name, 85.0, true);
    }
    let text = standing(&db, "ada");
    assert!(text.contains("1. Basic skills: open"), "{text}");
    assert!(text.contains("pancreas-palpation: 1 of 2"), "{text}");
    assert!(text.contains("liver-steady-press: had"), "{text}");
    assert!(
        text.contains("2. Cholecystectomy tasks: locked (opens after Basic skills)"),
        "{text}"
    );
    keep("pancreas-palpation", 76.0, true);
    let text = standing(&db, "ada");
    assert!(text.contains("1. Basic skills: done"), "{text}");
    assert!(text.contains("2. Cholecystectomy tasks: open"), "{text}");
    assert!(
        text.contains("3. The operation: locked (opens after Cholecystectomy tasks)"),
        "{text}"
    );
    assert!(
        text.contains("pancreas-palpation: had (75 on 2 attempts in a row; 4 attempts, best 90)"),
        "{text}"
    );
    let text = standing(&db, "bob");
    assert!(
        text.contains("1. Basic skills: open") && text.contains("tasks: locked"),
        "{text}"
    );
    assert!(
        text.contains("liver-steady-press: 0 of 2 (80 on 2 attempts in a row; no attempt yet)"),
        "{text}"
    );
    // The programme's view: both trainees, a row each, and their curves as PNG and CSV.
    history
        .record(&attempt("bob", "liver-steady-press", 55.0, false, at + 60))
        .unwrap();
    let plot = dir.join("cohort.png");
    let output = Command::new(TRAINER)
        .current_dir(root())
        .args(["history", "--cohort", "--curriculum", SHIPPED, "--history"])
        .arg(&db)
        .arg("--plot")
        .arg(&plot)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let table = String::from_utf8(output.stdout).unwrap();
    let row = |name: &str| {
        table
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_default()
            .to_owned()
    };
    let (ada, bob) = (row("ada"), row("bob"));
    let made = 2 * basics.len() + 2;
    let exercises: usize = curriculum.modules.iter().map(|m| m.exercises.len()).sum();
    let had = format!("{}/{exercises}  {made:>8}", basics.len());
    assert!(
        ada.contains("done") && ada.contains("open") && ada.contains(&had),
        "{table}"
    );
    assert!(
        bob.contains("open") && bob.contains("locked") && bob.contains(&format!("0/{exercises}")),
        "{table}"
    );
    assert!(std::fs::metadata(&plot).unwrap().len() > 1000);
    let csv = std::fs::read_to_string(dir.join("cohort.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + made + 1, "{csv}");
    // A group of one.
    let output = Command::new(TRAINER)
        .current_dir(root())
        .args([
            "history",
            "--cohort",
            "--curriculum",
            SHIPPED,
            "--group",
            "bob",
            "--history",
        ])
        .arg(&db)
        .arg("--plot")
        .arg(dir.join("bob.png"))
        .output()
        .unwrap();
    let table = String::from_utf8(output.stdout).unwrap();
    assert!(
        table.contains(": 1 trainee\n") && table.contains("\nbob ") && !table.contains("\nada "),
        "{table}"
    );
}

/// Broken curricula: a module opening after one not listed before it, a scenario that is not
/// there, a score out of range; each refused by `trainer validate` with its line, field and
/// hint, the shipped one accepted.
#[test]
fn bad_curricula_are_refused_with_file_line_field_and_hint() {
    let cases = [
        (
            "opens-after-unknown",
            9,
            "modules[0].opens_after[0]",
            "not a module listed before",
        ),
        (
            "scenario-missing",
            8,
            "modules[0].exercises[0].scenario",
            "the scenario does not load",
        ),
        (
            "proficient-without-benchmark",
            9,
            "modules[0].exercises[0].proficiency",
            "asks for the scenario's benchmark, and it sets none",
        ),
        (
            "score-out-of-range",
            10,
            "modules[0].exercises[0].proficiency.Benchmark.score",
            "not a score",
        ),
    ];
    for (name, line, field, message) in cases {
        let file = root().join(format!("tests/scenarios/broken/{name}.curriculum.ron"));
        assert_refused(
            &file,
            &load_curriculum(&file).unwrap_err(),
            (line, field, message),
        );
        let output = Command::new(TRAINER)
            .current_dir(root())
            .arg("validate")
            .arg(&file)
            .output()
            .unwrap();
        assert!(!output.status.success());
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains(&format!("{name}.curriculum.ron:{line}:")),
            "{stderr}"
        );
    }
    let output = Command::new(TRAINER)
        .current_dir(root())
        .args(["validate", SHIPPED])
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
}
