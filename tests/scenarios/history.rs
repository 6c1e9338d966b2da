//! The history of attempts: a record reads back as written, filters select, a corrupt
//! database is refused untouched and the attempt kept beside it, and the trainer keeps every
//! scored attempt and lists them as a table, a plot and CSV.

use std::path::{Path, PathBuf};
use std::process::Command;

use pgd_surgery::history::{
    AttemptRecord, History, HistoryError, HistoryFilter, Store, keep_attempt,
};

use crate::{TRAINER, run_steady_press};

/// A fresh folder of this test's own.
fn folder(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("history-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn record(trainee: &str, scenario: &str, score: f64, at_unix_s: i64) -> AttemptRecord {
    AttemptRecord {
        id: 0,
        uid: String::new(),
        station: String::new(),
        trainee: trainee.into(),
        scenario: scenario.into(),
        title: format!("{scenario} title"),
        at_unix_s,
        score,
        passed: score >= 70.0,
        time_s: 12.25,
        path_mm: 431.5,
        peak_force_n: 0.3125,
        errors: 2,
        report: "reports/x.json".into(),
        // Held to a benchmark of 80 where it scored 50 or more; not held to one below.
        proficient: (score >= 50.0).then_some(score >= 80.0),
    }
}

/// Written, then read back: the same record, numbered; oldest first; filters by trainee and
/// by scenario select exactly theirs.
#[test]
fn attempts_read_back_as_written_and_filter() {
    let db = folder("roundtrip").join("history.sqlite");
    let written = [
        record("ann", "a.ron", 81.5, 200),
        record("bob", "a.ron", 40.0, 100),
        record("ann", "b.ron", 66.0, 300),
    ];
    let history = History::open(&db).unwrap();
    for r in &written {
        history.record(r).unwrap();
    }
    drop(history);
    let history = History::open(&db).unwrap();
    let all = history.attempts(&HistoryFilter::default()).unwrap();
    let by_time: Vec<_> = [1, 0, 2].map(|k| written[k].clone()).into();
    let ids: Vec<i64> = all.iter().map(|a| a.id).collect();
    assert_eq!(ids, [2, 1, 3]);
    for (read, wrote) in all.iter().zip(&by_time) {
        assert_eq!(
            AttemptRecord {
                id: 0,
                ..read.clone()
            },
            *wrote
        );
    }
    let ann = HistoryFilter {
        trainee: Some("ann".into()),
        ..HistoryFilter::default()
    };
    assert_eq!(history.attempts(&ann).unwrap().len(), 2);
    let a_by_ann = HistoryFilter {
        scenario: Some("a.ron".into()),
        ..ann
    };
    let found = history.attempts(&a_by_ann).unwrap();
    assert_eq!((found.len(), found[0].score), (1, 81.5));
    assert_eq!(all[0].when(), "1970-01-01T00:01:40Z");
}

/// A history an older trainer wrote (schema 1: no attempt ids) is brought to the current
/// schema when opened, its attempts kept (held to no benchmark); a new attempt with an id is kept once however often
/// it is recorded, and those without ids each time.
#[test]
fn an_older_history_is_migrated_and_an_attempt_kept_once() {
    let db = folder("migrated").join("history.sqlite");
    let old = rusqlite::Connection::open(&db).unwrap();
    old.execute_batch(
        "CREATE TABLE attempts (id INTEGER PRIMARY KEY, trainee TEXT NOT NULL, \
         scenario TEXT NOT NULL, title TEXT NOT NULL, at_unix_s INTEGER NOT NULL, \
         score REAL NOT NULL, passed INTEGER NOT NULL, time_s REAL NOT NULL, \
         path_mm REAL NOT NULL, peak_force_n REAL NOT NULL, errors INTEGER NOT NULL, \
         report TEXT NOT NULL);
         INSERT INTO attempts VALUES (1, 'ann', 'a.ron', 'A', 100, 81.5, 1, 30.0, 120.0, \
         0.4, 0, '');
         PRAGMA user_version = 1;",
    )
    .unwrap();
    drop(old);
    let history = History::open(&db).unwrap();
    let all = HistoryFilter::default();
    let kept = history.attempts(&all).unwrap();
    assert_eq!(
        (
            kept.len(),
            kept[0].score,
            kept[0].uid.as_str(),
            kept[0].proficient
        ),
        (1, 81.5, "", None)
    );
    let with_id = AttemptRecord {
        uid: "64-0123".into(),
        ..record("bob", "b.ron", 60.0, 200)
    };
    let first = history.record(&with_id).unwrap();
    assert_eq!(history.record(&with_id).unwrap(), first);
    let without = record("cy", "c.ron", 50.0, 300);
    assert_ne!(
        history.record(&without).unwrap(),
        history.record(&without).unwrap()
    );
    assert_eq!(history.attempts(&all).unwrap().len(), 4);
    let version: i64 = rusqlite::Connection::open(&db)
        .unwrap()
        .query_row("PRAGMA user_version", [], |r| r.get(0))
        .unwrap();
    assert_eq!(
        version, 3,
        "migrated through attempt ids (2) and benchmarks (3)"
    );
}

/// A file that is not a history database: refused with its path, left as it was, and the
/// attempt written beside it, where the error says, reading back as the attempt.
#[test]
fn a_corrupt_database_is_refused_and_the_attempt_kept_aside() {
    let db = folder("corrupt").join("history.sqlite");
    let junk = b"this is not a database, and it must not be overwritten".repeat(100);
    std::fs::write(&db, &junk).unwrap();
    let attempt = record("ann", "a.ron", 75.0, 1234);
    let error = keep_attempt(&Store::Local(db.clone()), &attempt).unwrap_err();
    eprintln!("{error}");
    let HistoryError::SetAside { path, aside, .. } = &error else {
        panic!("{error}");
    };
    assert_eq!(path, &db);
    assert!(
        error.to_string().contains(&*db.to_string_lossy()),
        "{error}"
    );
    assert_eq!(std::fs::read(&db).unwrap(), junk);
    let kept: AttemptRecord =
        serde_json::from_str(&std::fs::read_to_string(aside).unwrap()).unwrap();
    assert_eq!(kept, attempt);
}

/// Two scored runs of the steady-press scenario through the trainer land in its history
/// under the trainee; `trainer history` lists them as CSV (their scores as the runs printed
/// them) and as a table with a learning-curve plot; another trainee's filter lists none.
#[test]
fn the_trainer_keeps_each_scored_attempt_and_lists_them() {
    let dir = folder("trainer");
    let db = dir.join("history.sqlite");
    let run = |script: &str| {
        let output = run_steady_press(script, &dir, &["--trainee", "ann"]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "{stderr}");
        assert!(stderr.contains("history: attempt"), "{stderr}");
        let card: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        card["score"].as_f64().unwrap()
    };
    let scores = [run("competent"), run("careless")];
    let history = |args: &[&str]| {
        Command::new(TRAINER)
            .arg("history")
            .args(args)
            .arg("--history")
            .arg(&db)
            .output()
            .unwrap()
    };
    let csv = history(&["--csv", "--trainee", "ann"]);
    assert!(csv.status.success());
    let text = String::from_utf8(csv.stdout).unwrap();
    let mut rows = csv::Reader::from_reader(text.as_bytes());
    let listed: Vec<f64> = rows
        .records()
        .map(|r| r.unwrap()[5].parse().unwrap())
        .collect();
    eprintln!("{text}");
    assert_eq!(listed.len(), 2);
    for (listed, scored) in listed.iter().zip(scores) {
        assert!((listed - scored).abs() < 0.051, "{listed} vs {scored}");
    }
    let plot = dir.join("curve.png");
    let table = history(&["--plot", plot.to_str().unwrap()]);
    assert!(table.status.success());
    let table = String::from_utf8(table.stdout).unwrap();
    assert!(
        table.contains("passed") && table.contains("failed"),
        "{table}"
    );
    assert_eq!(&std::fs::read(&plot).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
    let none = history(&["--csv", "--trainee", "bob"]);
    assert_eq!(String::from_utf8(none.stdout).unwrap().lines().count(), 1);
}
