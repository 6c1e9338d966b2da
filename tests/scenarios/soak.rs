//! `trainer soak` on the simulated clock (the hour is a benchmark): every attempt scored and
//! kept, no force that is not finite, no fault, no step of the force outside a lowered limit's
//! clamp larger than the safety filter's rate limit, though the device passes from attempt
//! to attempt; and no leak of an attempt's world, shown against a soak that plants that leak:
//! over a minute of one scene played over and over, and (the slow tier) over five minutes of
//! every scene.

use std::process::Command;

use pgd_surgery::devices::SafetySettings;

use crate::{TRAINER, root, vademecums};

/// A minute of use, the fast tier's soak: every attempt scored is kept, and the force is
/// finite and within the filter's step throughout. The leak check is the five minutes' alone
/// (below): it measures growth after a first round through every scene, which takes longer
/// than a minute of scripted attempts.
#[test]
fn a_minute_of_use_loses_nothing() {
    let report = soak(60, false, None);
    assert!(report.scored >= 2.0, "{} attempts", report.scored);
}

/// The growth per attempt after the first round that the soak must stay under: a haptic
/// world leaked each attempt (the planted defect) grows it by 36 MB an attempt on the coarse
/// scenes; the scenes' own sizes, which differ from attempt to attempt, move an honest fit by
/// about 5 MB either way over five minutes.
const LEAK_BOUND_BYTES: f64 = 10e6;

/// The growth per attempt one scene played over and over may not reach: an honest minute of
/// the liver's steady press grows 36 kB an attempt (its history, the allocator), one leaking
/// each attempt's world 3.6 MB.
const ONE_SCENE_LEAK_BOUND_BYTES: f64 = 1e6;

/// The fast tier's leak check: a minute of one scene over and over (nine attempts) grows less
/// than [`ONE_SCENE_LEAK_BOUND_BYTES`] an attempt, and the same minute with each attempt's
/// world leaked grows more.
#[test]
fn one_scene_over_and_over_leaks_nothing_and_a_planted_leak_shows() {
    let only = Some("scenarios/liver-steady-press.scenario.ron");
    let honest = soak(60, false, only);
    let leaking = soak(60, true, only);
    eprintln!(
        "memory grew {:.0} kB an attempt, {:.0} kB leaking a world each",
        honest.growth_per_attempt / 1e3,
        leaking.growth_per_attempt / 1e3
    );
    assert!(honest.scored >= 5.0, "{} attempts", honest.scored);
    assert!(honest.growth_per_attempt < ONE_SCENE_LEAK_BOUND_BYTES);
    assert!(leaking.growth_per_attempt > ONE_SCENE_LEAK_BOUND_BYTES);
}

#[test]
#[ignore = "slow tier: five simulated minutes of the soak (docs/development.md)"]
fn five_minutes_of_use_lose_nothing_and_leak_nothing() {
    let report = soak(300, false, None);
    assert!(
        report.scored >= 24.0,
        "{} attempts: every scenario twice at least",
        report.scored
    );
    eprintln!(
        "memory grew {:.0} kB an attempt",
        report.growth_per_attempt / 1e3
    );
    assert!(
        report.growth_per_attempt < LEAK_BOUND_BYTES,
        "resident memory grew {:.0} kB an attempt",
        report.growth_per_attempt / 1e3
    );
}

/// The same soak with a haptic world leaked each attempt fails the bound above: the check
/// catches a leak of one attempt's worth.
#[test]
#[ignore = "slow tier: five simulated minutes of the soak with a planted leak"]
fn a_leaked_world_an_attempt_fails_the_growth_bound() {
    let report = soak(300, true, None);
    eprintln!(
        "memory grew {:.0} kB an attempt",
        report.growth_per_attempt / 1e3
    );
    assert!(report.growth_per_attempt > LEAK_BOUND_BYTES);
}

/// What both tiers read of a soak's report.
struct Soaked {
    scored: f64,
    growth_per_attempt: f64,
}

/// `trainer soak` for `duration_s` simulated seconds on the tests' coarse organs (each
/// attempt's world leaked when `leak`; `only` that scenario, when given), with the checks
/// every length of soak must pass: every
/// tick run, every attempt scored and kept, no NaN, no fault, and no step between ticks
/// larger than the filter's rate limit outside a lowered limit's clamp.
fn soak(duration_s: u32, leak: bool, only: Option<&str>) -> Soaked {
    let dir = std::env::temp_dir().join(format!(
        "pgd-soak-{}-{duration_s}-{leak}-{}",
        std::process::id(),
        only.is_some()
    ));
    let history = dir.join("soak.sqlite");
    let mut command = Command::new(TRAINER);
    if leak {
        command.env("PGD_SOAK_PLANT_LEAK", "1");
    }
    let out = command
        .args(["soak", "--duration-s", &duration_s.to_string()])
        .args(["--coarse", "--no-rebuild", "--json"])
        .arg("--vademecums")
        .arg(vademecums())
        .arg("--keep-in")
        .arg(&history)
        .args(only.map(|only| ["--scenario", only]).into_iter().flatten())
        .current_dir(root())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stderr}");
    assert!(out.status.success(), "{stderr}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    eprintln!("{report:#}");
    let number = |key: &str| report[key].as_f64().unwrap_or_else(|| panic!("{key}"));
    assert_eq!(number("ticks"), f64::from(duration_s) * 1000.0);
    assert_eq!(number("nan_count"), 0.0);
    let scored = number("attempts_scored");
    assert_eq!(number("attempts_kept"), scored);
    // No scripted attempt, careless or not, trips a fault; then every step the device sees,
    // across attempts and scenes too, is the filter's rate limit at most, but where a scene's
    // lower limit clamps the force at once.
    assert_eq!(
        report["faults"],
        serde_json::json!({}),
        "faults in scripted attempts"
    );
    let slew_n = SafetySettings::default().max_change_n_per_tick;
    let plain = &report["largest_plain_step"];
    assert!(
        plain["step_n"].as_f64().unwrap() <= slew_n * (1.0 + 1e-9),
        "a step past the rate limit: {plain}"
    );
    if number("lowered_limit_steps") == 0.0 {
        assert_eq!(
            number("max_force_step_n"),
            plain["step_n"].as_f64().unwrap()
        );
    }
    let samples = report["memory"].as_array().unwrap().len();
    let every_minute = duration_s as usize / 60 + 1;
    assert_eq!(
        samples, every_minute,
        "a memory sample at the start and every minute"
    );
    std::fs::remove_dir_all(&dir).ok();
    Soaked {
        scored,
        growth_per_attempt: report["growth"]["per_attempt_bytes"].as_f64().unwrap(),
    }
}
