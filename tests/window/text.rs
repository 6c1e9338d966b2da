//! The trainee's screen reads at a small and a large size: on the menu and during an
//! exercise, at 1024 × 600 and at 1280 × 720, no text overlaps another and every one lies on
//! the screen. The rectangles are those the trainer's layout gave its texts, written in the
//! screenshot's legend.

use std::path::Path;
use std::process::Command;

use pgd_surgery::app::window::{Legend, TextLegend};

use super::{Surface, TRAINER, assert_ran, held_at, liver_target, shot_of, vademecums};

/// The smallest screen the trainer is laid out for, and the usual one.
const SIZES: [(u32, u32); 2] = [(1024, 600), (1280, 720)];

fn size_arg((width, height): (u32, u32)) -> String {
    format!("{width}x{height}")
}

/// The menu, opened on the built-in scenario with the mouse as the device (a scripted device
/// begins the exercise at once).
fn menu_legend(size: (u32, u32)) -> Legend {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join(format!("menu-{}.png", size_arg(size)));
    let output = Command::new(TRAINER)
        .args(["--offscreen", "--size", &size_arg(size), "--frames", "12"])
        .args(["--coarse", "--no-rebuild", "--device", "virtual"])
        .arg("--vademecums")
        .arg(vademecums())
        .arg("--screenshot")
        .arg(&png)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_ran(&output);
    let legend = std::fs::read_to_string(png.with_extension("json")).unwrap();
    serde_json::from_str(&legend).unwrap()
}

/// The built-in exercise under way, the scripted tool held above the liver.
fn exercise_legend(size: (u32, u32)) -> Legend {
    let (point, normal) = liver_target();
    let rows = held_at(point + normal * 0.04);
    let args = ["--size", &size_arg(size), "--frames", "12"];
    let name = format!("exercise-{}", size_arg(size));
    shot_of(&name, rows, &args, Surface::Offscreen).legend
}

/// Every text within the screen of `size`, and no two overlapping.
fn assert_apart(texts: &[TextLegend], (width, height): (u32, u32), what: &str) {
    assert!(!texts.is_empty(), "{what}: no text shown");
    let (width, height) = (width as f32 + 0.5, height as f32 + 0.5);
    for text in texts {
        let [x0, y0] = text.min_px;
        let [x1, y1] = text.max_px;
        assert!(
            x0 >= -0.5 && y0 >= -0.5 && x1 <= width && y1 <= height,
            "{what}: \"{}\" runs off the screen: {text:?}",
            text.words
        );
    }
    for (k, a) in texts.iter().enumerate() {
        for b in &texts[k + 1..] {
            let apart = (0..2)
                .any(|axis| a.max_px[axis] <= b.min_px[axis] || b.max_px[axis] <= a.min_px[axis]);
            assert!(apart, "{what}: \"{}\" overlaps \"{}\"", a.words, b.words);
        }
    }
}

#[test]
fn texts_neither_overlap_nor_leave_a_small_or_a_large_screen() {
    for size in SIZES {
        let menu = menu_legend(size);
        assert_apart(
            &menu.texts,
            size,
            &format!("the menu at {}", size_arg(size)),
        );
        assert!(
            menu.texts
                .iter()
                .any(|t| t.words.starts_with("Choose a scenario")),
            "the menu is shown: {:?}",
            menu.texts
        );
        let exercise = exercise_legend(size);
        let what = format!("the exercise at {}", size_arg(size));
        assert_apart(&exercise.texts, size, &what);
        assert!(
            exercise
                .texts
                .iter()
                .any(|t| t.words.starts_with("task 1 of")),
            "{what}: the HUD leads with the task: {:?}",
            exercise.texts
        );
    }
}

/// The check itself: two rectangles that share a corner are seen to overlap.
#[test]
#[should_panic(expected = "overlaps")]
fn the_overlap_check_sees_text_on_text() {
    let text = |words: &str, min_px, max_px| TextLegend {
        words: words.into(),
        min_px,
        max_px,
    };
    let texts = [
        text("task 1 of 1", [10.0, 10.0], [400.0, 120.0]),
        text("menu", [300.0, 100.0], [700.0, 500.0]),
    ];
    assert_apart(&texts, (1024, 600), "made up");
}
