//! A scaled workspace: the tool moves `scale` times as far as the device's handle.

use pgd_surgery::app::haptic::HapticLoop;
use pgd_surgery::devices::{PressMotion, SafetySettings, Trajectory, TrajectoryRow, Workspace};

use crate::common::{press, run, scene, scripted, tick_at};

/// The force sent, tick by tick, for `trajectory` on a device whose workspace is scaled.
fn sent_n(trajectory: Trajectory, scale: f64, ticks: u64) -> Vec<f64> {
    let mut scene = scene(SafetySettings::default());
    scene.right_hand_mut().workspace = Workspace { scale };
    let mut haptic = HapticLoop::new(&scene, scripted(trajectory)).unwrap();
    haptic.keep_trace();
    run(&mut haptic, ticks)
        .sent_n
        .iter()
        .map(|f| f.norm())
        .collect()
}

/// The press scripted at half size, on a workspace scaled by 2, is the full-size press: the
/// same force on every tick (to 1e-12 N), for half the handle's travel (so the tissue feels
/// twice as stiff under the hand).
#[test]
fn a_scaled_workspace_moves_the_tool_scale_times_as_far() {
    let motion = PressMotion {
        slide_m: 0.0,
        ..PressMotion::default()
    };
    let full = press(&motion);
    let half = Trajectory {
        rows: full
            .rows
            .iter()
            .map(|row| TrajectoryRow {
                x_m: row.x_m / 2.0,
                y_m: row.y_m / 2.0,
                z_m: row.z_m / 2.0,
                ..*row
            })
            .collect(),
    };
    let ticks = tick_at(motion.approach_s + motion.press_s + 0.5 * motion.slide_s);
    let unscaled = sent_n(full, 1.0, ticks);
    let scaled_half = sent_n(half, 2.0, ticks);
    assert!(unscaled.last().unwrap() > &0.1, "{:?}", unscaled.last());
    for (tick, (a, b)) in unscaled.iter().zip(&scaled_half).enumerate() {
        assert!((a - b).abs() < 1e-12, "tick {tick}: {a} N against {b} N");
    }
}
