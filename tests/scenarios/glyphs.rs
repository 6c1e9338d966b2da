//! The shipped font (DejaVu Sans, in `assets/fonts`) has a glyph for the signs the trainer
//! prints beyond ASCII; a missing one shows as a box in the window and the web page.

use std::process::Command;

use pgd_surgery::report::without_glyph;

use crate::{TRAINER, root};

/// The signs the debrief and the HUD print beyond ASCII have glyphs; a character no font
/// here has (a private-use one) has none, so that the check can fail.
#[test]
fn the_font_has_the_signs_the_trainer_prints() {
    let printed = without_glyph("1.00× the shortest, 23.6 m/s³ rms, 12 µs, ±0.5 N, 4 °, ↑ ↓");
    assert!(printed.is_empty(), "{printed:?}");
    assert_eq!(without_glyph("a\u{e000}b\u{e000}"), vec!['\u{e000}']);
}

/// `trainer validate` warns of a title the font cannot draw, and still passes the file; the
/// shipped scenarios draw whole.
#[test]
fn validate_warns_of_words_the_font_cannot_draw() {
    let dir = std::env::temp_dir().join(format!("pgd-glyphs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("cjk.scenario.ron");
    let text = r#"Scenario(title: "肝臓を押す", briefing: "Press the liver.", organs: ["liver"],
        tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3, hold_s: 1.0,
                             time_limit_s: 5.0)])"#;
    std::fs::write(&file, text).unwrap();
    let (passed, stderr) = validate(std::slice::from_ref(&file));
    assert!(passed, "{stderr}");
    assert!(stderr.contains("no glyph for '肝'"), "{stderr}");
    let shipped: Vec<_> = std::fs::read_dir(root().join("scenarios"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.to_string_lossy().ends_with(".scenario.ron"))
        .collect();
    let (passed, stderr) = validate(&shipped);
    assert!(passed && !stderr.contains("no glyph"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `trainer validate FILES`: whether it passed them, and its error stream.
fn validate(files: &[std::path::PathBuf]) -> (bool, String) {
    let out = Command::new(TRAINER)
        .arg("validate")
        .args(files)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
