//! What the trainee reads: the force the device renders against its limit, the haptic rate,
//! the frame time, faults, how to drive the virtual tool and steer the laparoscope, and a
//! warning while the instrument is out of the laparoscope's view.

use bevy::prelude::*;

use super::FrameSet;
use super::bridge::{HapticLink, Snapshot};
use super::laparoscope::CameraMode;
use super::lesson::Lesson;
use crate::app::haptic::{HapticSnapshot, organ_with_law};
use crate::devices::Action;

#[derive(Component)]
struct Hud;

pub(super) fn setup(app: &mut App) {
    app.add_systems(Startup, spawn_hud)
        .add_systems(Update, update_hud.in_set(FrameSet::Draw));
}

fn spawn_hud(mut commands: Commands) {
    commands.spawn((
        Hud,
        Text::new(""),
        TextFont {
            font_size: FontSize::Px(15.0),
            ..default()
        },
        Node {
            position_type: PositionType::Absolute,
            top: px(10),
            left: px(10),
            ..default()
        },
    ));
}

/// The haptic rate measured from the snapshots' tick counter against wall-clock time (not the
/// virtual time, which caps a slow frame's step), smoothed over about a second.
#[derive(Default)]
struct Rate {
    last_tick: u64,
    hz: f64,
}

fn update_hud(
    link: Res<HapticLink>,
    snapshot: Res<Snapshot>,
    time: Res<Time<Real>>,
    lesson: Option<Res<Lesson>>,
    mode: Res<CameraMode>,
    mut rate: Local<Rate>,
    mut hud: Query<&mut Text, With<Hud>>,
) {
    let Ok(mut text) = hud.single_mut() else {
        return;
    };
    let dt = time.delta_secs_f64();
    let ticks = snapshot.0.tick.saturating_sub(rate.last_tick);
    let first = rate.last_tick == 0;
    rate.last_tick = snapshot.0.tick;
    if dt > 0.0 && !first {
        let k = dt.min(1.0);
        rate.hz = rate.hz * (1.0 - k) + k * ticks as f64 / dt;
    }
    let limit_n = link.scene.safety.max_force_n;
    let force_n = snapshot.0.force_n.norm();
    let filled = ((force_n / limit_n).clamp(0.0, 1.0) * 20.0).round() as usize;
    let gauge = format!("[{}{}]", "#".repeat(filled), "-".repeat(20 - filled));
    let touching: Vec<&str> = snapshot
        .0
        .organs
        .iter()
        .zip(&link.scene.organs)
        .filter(|(o, _)| o.contact.is_some())
        .map(|(_, (name, _))| name.as_str())
        .collect();
    let grasped = snapshot
        .0
        .organs
        .iter()
        .zip(&link.scene.organs)
        .find(|(o, _)| o.grasped)
        .map(|(_, (name, _))| name.as_str());
    let status = if snapshot.0.faulted {
        "FAULT: force faded to zero (see the log)".to_owned()
    } else if let Some(name) = grasped {
        format!("grasping {name}: release the button to let go")
    } else if touching.is_empty() {
        "no contact".to_owned()
    } else {
        format!(
            "touching {}{}",
            touching.join(", "),
            beyond_range(&snapshot.0)
        )
    };
    let help = if link.virtual_device.is_some() {
        "\nmouse: move the tool | wheel or W/S: push in / pull out | Q/E: turn the handle\n\
         right-drag: orbit | middle-drag: pan | Ctrl+wheel or +/-: zoom"
    } else {
        ""
    };
    let task = lesson.map_or_else(String::new, |lesson| task_line(&lesson, &snapshot));
    let camera = camera_line(&link, &snapshot.0, *mode);
    let instruments = instrument_line(&link, &snapshot.0);
    let tissue = tissue_line(&link);
    let timing = &snapshot.0.timing;
    text.0 = format!(
        "{task}device: {}\nforce {force_n:.3} N {gauge} limit {limit_n:.1} N\n{status}\n\
         haptic {:.0} Hz | tick p99 {:.0} us, late p99 {:.0} us, {} skipped | frame {:.1} ms\n{tissue}{help}{instruments}{camera}",
        link.device_name,
        rate.hz,
        timing.compute_p99_us,
        timing.lateness_p99_us,
        timing.skipped,
        dt * 1e3
    );
}

/// Each organ's tissue law, and the nonlinear vademecum building in the background, if any
/// (its organ runs linear tissue until the briefing after it is built loads the scene again).
fn tissue_line(link: &HapticLink) -> String {
    let laws: Vec<String> = link
        .scene
        .organs
        .iter()
        .map(|(name, vademecum)| organ_with_law(name, vademecum))
        .collect();
    format!("tissue: {}{}", laws.join(", "), building_line())
}

/// What the background builder is doing, on its own line, and which of its builds failed
/// (their organs stay linear; the log says why).
#[cfg(not(target_arch = "wasm32"))]
fn building_line() -> String {
    let status = crate::store::background_status();
    let failed: String = status
        .failed
        .iter()
        .map(|(organ, _)| {
            format!("\n{organ}'s nonlinear vademecum could not be built: see the log")
        })
        .collect();
    let Some(building) = status.building else {
        return failed;
    };
    let share = match building.total {
        0 => String::new(),
        total => format!(" {}/{total}", building.done),
    };
    let waiting = match status.queued.len() {
        0 => String::new(),
        n => format!(", {n} more waiting"),
    };
    format!(
        "\nbuilding the {} {} in the background ({}{share}{waiting}): the next briefing uses \
         it{failed}",
        building.law, building.organ, building.stage
    )
}

#[cfg(target_arch = "wasm32")]
fn building_line() -> String {
    String::new()
}

/// With several instruments: the one in hand, and how to change it.
fn instrument_line(link: &HapticLink, snapshot: &HapticSnapshot) -> String {
    let instruments = &link.scene.instruments;
    if instruments.len() < 2 {
        return String::new();
    }
    let in_hand = snapshot.instruments.in_hand;
    let name = match instruments[in_hand].action {
        Action::Press => "probe",
        Action::Grasp => "grasper",
        Action::Cut => "scalpel",
    };
    format!(
        "\nin hand: {name}, instrument {} of {} | Tab (the device's second button): change it, off the tissue",
        in_hand + 1,
        instruments.len()
    )
}

/// With a laparoscope: a warning while the instrument's tip is out of its view (what the
/// exercise times), and how to steer it.
fn camera_line(link: &HapticLink, snapshot: &HapticSnapshot, mode: CameraMode) -> String {
    let Some(rig) = &link.scene.scope else {
        return String::new();
    };
    let pose = rig.pose.get();
    let out = snapshot
        .tip_m
        .is_some_and(|tip| !rig.scope.sees(&pose, &tip));
    let warning = match out {
        true => "\nINSTRUMENT OUT OF VIEW",
        false => "",
    };
    let keys = match (mode, rig.script.is_some()) {
        (CameraMode::Free, _) => "\nfree camera | C: back to the laparoscope",
        (CameraMode::Laparoscope, true) => "\nlaparoscope (moved by the scenario) | C: free camera",
        (CameraMode::Laparoscope, false) => {
            "\nlaparoscope: I/K, J/L steer | U/O in / out | Z/X roll | C: free camera"
        }
    };
    format!("{keys}{warning}")
}

/// The task under way and its clock, above the rest of the HUD (nothing before the exercise
/// begins or after it ends).
fn task_line(lesson: &Lesson, snapshot: &Snapshot) -> String {
    let Some(progress) = snapshot.0.exercise.filter(|p| !p.finished()) else {
        return String::new();
    };
    let Some(task) = lesson.scenario.tasks.get(progress.task) else {
        return String::new();
    };
    format!(
        "task {} of {}: {}\n{:.1} s of {:.0} s\n\n",
        progress.task + 1,
        progress.tasks,
        task.description(),
        progress.task_elapsed_s,
        task.time_limit_s()
    )
}

/// What the status line adds while the tool presses deeper than a nonlinear vademecum covers:
/// the trainee should know the tissue no longer firms up there.
fn beyond_range(snapshot: &HapticSnapshot) -> String {
    let beyond_m = snapshot
        .organs
        .iter()
        .filter_map(|o| o.contact.map(|c| c.beyond_range_m))
        .fold(0.0, f64::max);
    if beyond_m > 0.0 {
        format!(
            " | {:.1} mm beyond the model's range: stiffening held",
            beyond_m * 1e3
        )
    } else {
        String::new()
    }
}
