//! An incision on screen: the liver cut by the scalpel along the capsule-incision scenario's
//! line, then pressed beside the cut, seen from above, shows its lips apart and the picture
//! along the cut changed from the same presses on the uncut liver.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use super::{Shot, distance, row, scenario_shot_after};

/// The blade set down at the line's start, pressed to a tip height of `stroke_y_mm` and
/// drawn along it (the stroke of `tests/scenarios/cutting.rs`: 57.8 mm cuts; 62 mm peaks at
/// 0.49 N of the 0.56 N that parts the liver, so the uncut run stays higher still), lifted,
/// then pressed 14 mm beside the line's middle, lightly enough not to cut, and held.
fn stroke_then_press_beside(stroke_y_mm: f64) -> Vec<super::TrajectoryRow> {
    let at = |t: f64, x: f64, y: f64, z: f64| row(t, Vector3::new(x, y, z) * 1e-3);
    vec![
        at(0.0, 22.0, 85.0, 0.3),
        at(1.0, 22.0, 60.0, 0.3),
        at(1.5, 22.0, stroke_y_mm, 0.3),
        at(5.5, 48.0, stroke_y_mm - 1.8, 0.3),
        at(6.0, 48.0, stroke_y_mm - 1.8, 0.3),
        at(7.0, 48.0, 85.0, 0.3),
        at(7.5, 35.0, 85.0, 14.3),
        at(8.5, 35.0, 63.0, 14.3),
        at(600.0, 35.0, 63.0, 14.3),
    ]
}

/// The shipped scenario seen through a laparoscope straight above the line's middle, 60 mm
/// away, with a second task that keeps the exercise going (so that no debrief covers the view).
fn scenario_over_the_line(dir: &Path) -> PathBuf {
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/liver-capsule-incision.scenario.ron");
    let text = std::fs::read_to_string(shipped).unwrap();
    let tool = "    tool: Scalpel(tip_radius_mm: 6.0, edge_mm: 3.0),\n";
    let end_of_tasks = "        ),\n    ],\n";
    assert!(text.contains(tool) && text.contains(end_of_tasks));
    let laparoscope = "    laparoscope: Laparoscope(port_mm: (35.0, 150.0, 0.3), \
                       look_at_mm: (35.0, 59.0, 0.3), distance_mm: 60.0),\n";
    let hold = "        ),\n        ForceControl(organ: \"liver\", min_force_n: 0.1, \
                max_force_n: 0.3, hold_s: 500.0, time_limit_s: 600.0),\n    ],\n";
    let text = text
        .replace(tool, &format!("{tool}{laparoscope}"))
        .replace(end_of_tasks, hold);
    let file = dir.join("incision-seen-from-above.scenario.ron");
    std::fs::write(&file, text).unwrap();
    file
}

fn shot(name: &str, stroke_y_mm: f64) -> Shot {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
    std::fs::create_dir_all(&dir).unwrap();
    let file = scenario_over_the_line(&dir);
    let script = stroke_then_press_beside(stroke_y_mm);
    scenario_shot_after(name, &file, (3, 9.5), script)
}

/// Cut and pressed beside, the liver's lips are drawn apart by at least 3 pixels somewhere,
/// and along the cut (between its lips) the colour differs from the uncut liver's under the
/// same presses by more than 10 on average (of 0–255 per channel).
#[test]
fn an_incision_opens_on_screen() {
    let cut = shot("incision-cut", 57.8);
    let uncut = shot("incision-uncut", 63.5);
    assert!(uncut.legend.lips.is_empty(), "the light stroke cut");
    let lips: Vec<_> = cut
        .legend
        .lips
        .iter()
        .filter(|l| l.organ == "liver")
        .collect();
    assert!(!lips.is_empty(), "the liver is not split");
    let apart = |l: &&pgd_surgery::app::window::LipLegend| {
        (l.own_px[0] - l.across_px[0]).hypot(l.own_px[1] - l.across_px[1])
    };
    let widest = lips.iter().map(apart).fold(0.0, f32::max);
    eprintln!(
        "{} split vertices, lips up to {widest:.1} px apart",
        lips.len()
    );
    assert!(widest >= 3.0, "the lips are {widest:.1} px apart at most");
    let along: Vec<[f32; 2]> = lips
        .iter()
        .map(|l| {
            [
                (l.own_px[0] + l.across_px[0]) / 2.0,
                (l.own_px[1] + l.across_px[1]) / 2.0,
            ]
        })
        .collect();
    let change = along
        .iter()
        .map(|&px| distance(cut.colour_at(px), uncut.colour_at(px)))
        .sum::<f32>()
        / along.len() as f32;
    eprintln!("along the cut the colour moved by {change:.1}");
    assert!(
        change > 10.0,
        "along the cut the colour moved by only {change:.1}"
    );
}
