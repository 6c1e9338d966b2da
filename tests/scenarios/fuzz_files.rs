//! Every file the trainer reads, fuzzed (`tests/support/fuzz.rs`): scenario files, trajectory
//! CSV, vademecums (`.vdm`), distance fields (`.vdf`), their web forms and the history
//! database, each from valid seeds — the shipped scenarios and runs, the coarse scenes' own
//! files. No panic, no read past a person's patience, and no allocation past the stated bound
//! for the file's length. The mesh formats are fuzzed in `tests/geometry`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use pgd_surgery::app::SHIPPED_SCENARIOS;
use pgd_surgery::app::shipped::SHIPPED_RUNS;
use pgd_surgery::contact::DistanceField;
use pgd_surgery::devices::Trajectory;
use pgd_surgery::history::{AttemptRecord, History, HistoryFilter};
use pgd_surgery::pgd::{container, decode, web_form};
use pgd_surgery::scenario::parse;

use crate::fuzz::{Format, assert_refused_within, fuzz, in_proportion, rebuilt};
use crate::vademecums;

/// Cases per format in `cargo test`.
const CASES: u32 = 256;
/// Cases for the formats whose every case reads a multi-megabyte file or a database.
const HEAVY_CASES: u32 = 48;

/// The smallest file with `extension` among the coarse scenes' files.
fn smallest(extension: &str) -> Vec<u8> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(vademecums())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort_by_key(|path| std::fs::metadata(path).unwrap().len());
    std::fs::read(&files[0]).unwrap()
}

#[test]
fn scenario_files_are_fuzzed() {
    let read = |bytes: &[u8]| {
        let _ = parse(
            Path::new("fuzz.scenario.ron"),
            &String::from_utf8_lossy(bytes),
        );
    };
    fuzz(
        &Format {
            name: "scenario (RON)",
            seeds: SHIPPED_SCENARIOS
                .iter()
                .map(|(_, text)| text.as_bytes().to_vec())
                .collect(),
            container: false,
            allocation_bound: in_proportion,
            read: &read,
        },
        CASES,
    );
}

#[test]
fn trajectory_files_are_fuzzed() {
    let read = |bytes: &[u8]| {
        let _ = Trajectory::read(Path::new("fuzz.csv"), bytes);
    };
    fuzz(
        &Format {
            name: "trajectory (CSV)",
            seeds: SHIPPED_RUNS
                .iter()
                .map(|run| run.competent.as_bytes().to_vec())
                .collect(),
            container: false,
            allocation_bound: in_proportion,
            read: &read,
        },
        CASES,
    );
}

#[test]
fn vademecum_files_are_fuzzed() {
    let read = |bytes: &[u8]| {
        let _ = decode(Path::new("fuzz.vdm"), bytes);
    };
    fuzz(
        &Format {
            name: "vademecum (.vdm)",
            seeds: vec![smallest("vdm")],
            container: true,
            allocation_bound: in_proportion,
            read: &read,
        },
        HEAVY_CASES,
    );
}

/// The fuzzed `.vdf` is provided at this path, where the field's loader finds it.
const FIELD: &str = "fuzz/provided.vdf";

#[test]
fn distance_field_files_are_fuzzed() {
    let read = |bytes: &[u8]| {
        container::provide(Path::new(FIELD), Arc::from(bytes));
        let _ = DistanceField::load(Path::new(FIELD));
    };
    fuzz(
        &Format {
            name: "distance field (.vdf)",
            seeds: vec![smallest("vdf")],
            container: true,
            allocation_bound: in_proportion,
            read: &read,
        },
        HEAVY_CASES,
    );
}

/// A web form inflates to at most 1,032 times its length (deflate's largest ratio), within
/// its reader's 1 GiB cap, and the growing buffer may hold twice that while it grows.
fn inflated(len: usize) -> usize {
    2 * 1032 * len + (1 << 20)
}

#[test]
fn web_forms_are_fuzzed() {
    let vademecum = decode(Path::new("seed.vdm"), &smallest("vdm")).unwrap();
    let read = |bytes: &[u8]| {
        if let Ok(file) = web_form::expand(Path::new("fuzz.vdm.web"), bytes) {
            let _ = decode(Path::new("fuzz.vdm"), &file);
        }
    };
    fuzz(
        &Format {
            name: "web form (.vdm.web, .vdf.web)",
            seeds: vec![
                web_form::vademecum(&vademecum),
                web_form::deflated(&smallest("vdf")),
            ],
            container: false,
            allocation_bound: inflated,
            read: &read,
        },
        HEAVY_CASES,
    );
}

#[test]
fn history_databases_are_fuzzed() {
    let dir = std::env::temp_dir().join(format!("pgd-fuzz-history-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let seed = dir.join("seed.sqlite");
    let history = History::open(&seed).unwrap();
    let card = crate::run("liver-steady-press", "competent").card;
    for trainee in ["ana", "ben"] {
        let record = AttemptRecord::of(&card, Path::new("steady.ron"), trainee, None, 1);
        history.record(&record).unwrap();
    }
    drop(history);
    let fuzzed = dir.join("fuzzed.sqlite");
    let read = |bytes: &[u8]| {
        std::fs::write(&fuzzed, bytes).unwrap();
        if let Ok(history) = History::open(&fuzzed) {
            let _ = history.attempts(&HistoryFilter::default());
        }
    };
    fuzz(
        &Format {
            name: "history (SQLite)",
            seeds: vec![std::fs::read(&seed).unwrap()],
            container: false,
            allocation_bound: in_proportion,
            read: &read,
        },
        HEAVY_CASES,
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `file` with its JSON header's `field` set to `value`, past the checksum.
fn claiming(file: &[u8], field: &str, value: serde_json::Value) -> Vec<u8> {
    rebuilt(
        file,
        |header| {
            let mut json: serde_json::Value = serde_json::from_slice(header).unwrap();
            assert!(json.get(field).is_some(), "no field {field} in the header");
            json[field] = value;
            *header = serde_json::to_vec(&json).unwrap();
        },
        |_| {},
    )
}

/// `file` with the length of its payload's first array claiming 10¹² values.
fn first_array_claiming(file: &[u8]) -> Vec<u8> {
    let claim = 1_000_000_000_000u64.to_le_bytes();
    rebuilt(file, |_| {}, |payload| payload[..8].copy_from_slice(&claim))
}

/// Vademecums and distance fields whose header or first array claims 10¹² nodes, modes or
/// values are refused before anything that size is allocated, and without overflowing.
#[test]
fn claimed_sizes_are_not_allocated() {
    let vdm = smallest("vdm");
    let vdf = smallest("vdf");
    let huge = serde_json::json!(1_000_000_000_000u64);
    let read_vdm = |bytes: &[u8]| {
        assert!(
            decode(Path::new("claim.vdm"), bytes).is_err(),
            "read a claim"
        );
    };
    let read_vdf = |bytes: &[u8]| {
        container::provide(Path::new(FIELD), Arc::from(bytes));
        assert!(
            DistanceField::load(Path::new(FIELD)).is_err(),
            "read a claim"
        );
    };
    let vdm_claims = [
        claiming(&vdm, "node_count", huge.clone()),
        claiming(
            &vdm,
            "modes_per_step",
            serde_json::json!([1_000_000_000_000u64]),
        ),
        first_array_claiming(&vdm),
    ];
    for claim in &vdm_claims {
        assert_refused_within("vademecum claim", claim, in_proportion, read_vdm);
    }
    let vdf_claims = [
        claiming(
            &vdf,
            "dims",
            serde_json::json!([1_000_000u64, 1_000_000u64, 1_000_000u64]),
        ),
        claiming(&vdf, "modes", huge),
        first_array_claiming(&vdf),
    ];
    for claim in &vdf_claims {
        assert_refused_within("distance field claim", claim, in_proportion, read_vdf);
    }
}
