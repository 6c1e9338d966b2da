//! Five simulated minutes of `trainer soak` (the hour is a benchmark): every attempt scored and
//! kept, no force that is not finite, no step of the force the safety filter does not allow,
//! and no leak of a scene's worth of memory an attempt once every scene has been loaded.

use std::process::Command;

use pgd_surgery::devices::SafetySettings;

use crate::{TRAINER, root, vademecums};

#[test]
fn five_minutes_of_use_lose_nothing_and_leak_nothing() {
    let dir = std::env::temp_dir().join(format!("pgd-soak-{}", std::process::id()));
    let history = dir.join("soak.sqlite");
    let out = Command::new(TRAINER)
        .args([
            "soak",
            "--duration-s",
            "300",
            "--coarse",
            "--no-rebuild",
            "--json",
        ])
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
    assert_eq!(number("ticks"), 300_000.0);
    assert_eq!(number("nan_count"), 0.0);
    let scored = number("attempts_scored");
    assert!(
        scored >= 24.0,
        "{scored} attempts: every scenario twice at least"
    );
    assert_eq!(number("attempts_kept"), scored);
    // The 1 % target is the hour's (docs/safety.md); over five minutes the same run measures
    // 0.3 % alone and 4.9 % beside the rest of the suite. What this catches is a leak of
    // 5 MB an attempt, a scene's worth, which over the attempts after the first round passes
    // 10 % of the resident memory.
    let growth = number("rss_end_bytes") / number("rss_start_bytes") - 1.0;
    eprintln!("resident memory grew {:.2} %", growth * 100.0);
    assert!(
        growth < 0.10,
        "resident memory grew {:.2} %",
        growth * 100.0
    );
    // The filter moves the force by its rate limit a tick, or fades it from the device's peak
    // over its fade ticks: no step between ticks can be larger.
    let safety = SafetySettings::default();
    let largest_allowed =
        (safety.max_force_n / safety.fade_ticks as f64).max(safety.max_change_n_per_tick);
    assert!(number("max_force_step_n") <= largest_allowed * (1.0 + 1e-9));
    std::fs::remove_dir_all(&dir).ok();
}
