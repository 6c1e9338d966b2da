//! `trainer soak` on the simulated clock (the hour is a benchmark): every attempt scored and
//! kept, no force that is not finite, no step of the force the safety filter does not allow;
//! and over five minutes (the slow tier) no leak of a scene's worth of memory an attempt once
//! every scene has been loaded.

use std::process::Command;

use pgd_surgery::devices::SafetySettings;

use crate::{TRAINER, root, vademecums};

/// A minute of use, the fast tier's soak: every attempt scored is kept, and the force is
/// finite and within the filter's step throughout. The leak check is the five minutes' alone
/// (below): it measures growth after a first round through every scene, which takes longer
/// than a minute of scripted attempts.
#[test]
fn a_minute_of_use_loses_nothing() {
    let report = soak(60);
    assert!(report.scored >= 2.0, "{} attempts", report.scored);
}

#[test]
#[ignore = "slow tier: five simulated minutes of the soak (docs/development.md)"]
fn five_minutes_of_use_lose_nothing_and_leak_nothing() {
    let report = soak(300);
    assert!(
        report.scored >= 24.0,
        "{} attempts: every scenario twice at least",
        report.scored
    );
    // The 1 % target is the hour's (docs/safety.md); over five minutes the same run measures
    // 0.3 % alone and 4.9 % beside the rest of the suite. What this catches is a leak of
    // 5 MB an attempt, a scene's worth, which over the attempts after the first round passes
    // 10 % of the resident memory.
    eprintln!("resident memory grew {:.2} %", report.rss_growth * 100.0);
    assert!(
        report.rss_growth < 0.10,
        "resident memory grew {:.2} %",
        report.rss_growth * 100.0
    );
}

/// What both tiers read of a soak's report.
struct Soaked {
    scored: f64,
    rss_growth: f64,
}

/// `trainer soak` for `duration_s` simulated seconds on the tests' coarse organs, with the
/// checks every length of soak must pass: every tick run, every attempt scored and kept, no
/// NaN, and no step between ticks larger than the filter allows.
fn soak(duration_s: u32) -> Soaked {
    let dir = std::env::temp_dir().join(format!("pgd-soak-{}-{duration_s}", std::process::id()));
    let history = dir.join("soak.sqlite");
    let out = Command::new(TRAINER)
        .args(["soak", "--duration-s", &duration_s.to_string()])
        .args(["--coarse", "--no-rebuild", "--json"])
        .arg("--vademecums")
        .arg(vademecums())
        .arg("--keep-in")
        .arg(&history)
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
    // The filter moves the force by its rate limit a tick, or fades it from the device's peak
    // over its fade ticks: no step between ticks can be larger.
    let safety = SafetySettings::default();
    let largest_allowed =
        (safety.max_force_n / safety.fade_ticks as f64).max(safety.max_change_n_per_tick);
    assert!(number("max_force_step_n") <= largest_allowed * (1.0 + 1e-9));
    std::fs::remove_dir_all(&dir).ok();
    Soaked {
        scored,
        rss_growth: number("rss_end_bytes") / number("rss_start_bytes") - 1.0,
    }
}
