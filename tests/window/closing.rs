//! Closing the window with a hardware device in hand, against the fake HD library: the window
//! closing at the end of its run, and SIGINT (Ctrl-C) closing it as its close button would,
//! each leave the device at zero force with its servo stopped and the device disabled, after
//! the trainer had been pushing back on a stylus held in the liver. The trainer runs as a user
//! runs it, offscreen; the fake, which the test cannot reach inside the trainer's process,
//! takes its stylus from `FAKE_HD_STYLUS` and writes what the device was left in to
//! `FAKE_HD_REPORT` when the process lets the library go.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use nalgebra::Vector3;
use pgd_surgery::app::scene::Detail;
use serde::Deserialize;

use crate::vendor_fake::VendorFake;
use crate::{TRAINER, assert_ran, liver_target, vademecums};

/// What the fake device was left in.
#[derive(Debug, Deserialize)]
struct Left {
    last_force: [f64; 3],
    largest_force: f64,
    running: i32,
    disabled: i32,
}

/// The trainer offscreen on the coarse organs with an OpenHaptics device (the fake's copy for
/// `name`) whose stylus is held 4 mm into the liver, `args` added; and where its report goes.
fn trainer_on_the_fake(name: &str, args: &[&str]) -> (Command, PathBuf) {
    let fake = VendorFake::new("fake_hd", name);
    let (point, normal) = liver_target();
    let tip_m = point + normal * (Detail::Coarse.tip_radius_m() - 0.004);
    // The scene's (x, y, z) m is the device's (x, z, −y) mm.
    let stylus_mm = Vector3::new(tip_m.x, tip_m.z, -tip_m.y) * 1e3;
    let report = fake.path.with_extension("json");
    let _ = std::fs::remove_file(&report);
    let _ = std::fs::remove_file(started(&report));
    let mut command = Command::new(TRAINER);
    command
        .args([
            "--device",
            "openhaptics",
            "--coarse",
            "--no-rebuild",
            "--offscreen",
        ])
        .arg("--vademecums")
        .arg(vademecums())
        .args(args)
        .env("PGD_OPENHAPTICS_LIB", &fake.path)
        .env(
            "FAKE_HD_STYLUS",
            format!("{},{},{}", stylus_mm.x, stylus_mm.y, stylus_mm.z),
        )
        .env("FAKE_HD_REPORT", &report)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY");
    (command, report)
}

/// The file the fake writes once its servo runs.
fn started(report: &Path) -> PathBuf {
    report.with_extension("json.started")
}

/// The run pushed back on the stylus, and left the device at zero force, its servo stopped and
/// the device disabled.
fn assert_released_after_pushing(output: &Output, report: &Path) {
    assert_ran(output);
    let text = std::fs::read_to_string(report)
        .unwrap_or_else(|e| panic!("the fake wrote no report to {} ({e})", report.display()));
    let left: Left = serde_json::from_str(&text).unwrap();
    eprintln!("{left:?}");
    assert!(
        left.largest_force > 0.05,
        "the trainer never pushed back: {left:?}"
    );
    assert_eq!(left.last_force, [0.0; 3], "left pushing: {left:?}");
    assert_eq!(
        (left.running, left.disabled),
        (0, 1),
        "not released: {left:?}"
    );
}

/// The window closes at the end of its run (`--exit-after-s`), as when the trainee closes it.
#[test]
fn closing_the_window_leaves_the_device_released_at_zero_force() {
    let (mut command, report) = trainer_on_the_fake("window-closes", &["--exit-after-s", "3"]);
    let output = command.output().unwrap();
    assert_released_after_pushing(&output, &report);
}

/// SIGINT while the window is open: the devices are released at once, the window closes as its
/// close button would, and the trainer ends without an error.
#[test]
fn an_interrupt_closes_the_window_and_leaves_the_device_released() {
    let (mut command, report) = trainer_on_the_fake("interrupted", &["--exit-after-s", "120"]);
    let child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&started(&report), Duration::from_secs(60));
    std::thread::sleep(Duration::from_secs(2));
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let output = within(child, Duration::from_secs(60));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("signal received"), "{stderr}");
    assert_released_after_pushing(&output, &report);
}

/// Waits until `file` exists (`limit` at most).
fn wait_for(file: &Path, limit: Duration) {
    let give_up = Instant::now() + limit;
    while !file.exists() {
        assert!(Instant::now() < give_up, "{} never came", file.display());
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The child's output once it has ended, killing it after `limit`.
fn within(mut child: Child, limit: Duration) -> Output {
    let give_up = Instant::now() + limit;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > give_up {
            let _ = child.kill();
            panic!("the trainer did not end within {limit:?} of the signal");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}
