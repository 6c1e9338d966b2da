//! What the trainee reads: the task and its clock, the force the device renders against its
//! limit, what the tool touches, faults (in a bimanual exercise a line a hand: its
//! instrument, what it holds or touches, its force, and which hand the mouse drives), how to drive the virtual tool and steer the
//! laparoscope, and a warning while the instrument is out of the laparoscope's view. The
//! device's name, the loop's timing and the tissue's laws are behind F3: a trainee has no use
//! for them, a developer does.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use super::FrameSet;
use super::bridge::{HapticLink, Snapshot};
use super::input::MouseHand;
use super::laparoscope::CameraMode;
use super::lesson::{Lesson, Stage};
use crate::app::haptic::{HandIndex, HapticSnapshot, organ_with_law};
use crate::devices::Action;
use crate::dissection::CauteryMode;
use crate::scenario::{Progress, Scenario};

#[derive(Component)]
struct Hud;

/// Whether the HUD shows the device, the loop's timing and the tissue (F3 toggles it).
#[derive(Resource, Clone, Copy, Debug, Default)]
struct Details(bool);

/// The key that shows and hides the details.
const DETAILS_KEY: KeyCode = KeyCode::F3;

/// The HUD.
pub(super) struct HudPlugin;

impl Plugin for HudPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Details>()
            .add_systems(Startup, spawn_hud)
            .add_systems(
                Update,
                (toggle_details, update_hud, hide_under_panels)
                    .chain()
                    .in_set(FrameSet::Draw),
            );
    }
}

/// The HUD is for the exercise and free play: under the menu's, the briefing's and the
/// debrief's panels it is hidden, so that no text is drawn over theirs at any window size.
fn hide_under_panels(stage: Option<Res<State<Stage>>>, mut hud: Query<&mut Visibility, With<Hud>>) {
    let shown = stage.is_none_or(|stage| matches!(stage.get(), Stage::FreePlay | Stage::Exercise));
    for mut visibility in &mut hud {
        visibility.set_if_neq(match shown {
            true => Visibility::Inherited,
            false => Visibility::Hidden,
        });
    }
}

fn toggle_details(keys: Res<ButtonInput<KeyCode>>, mut details: ResMut<Details>) {
    if keys.just_pressed(DETAILS_KEY) {
        details.0 = !details.0;
    }
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

/// How the trainee has set the view and the controls: the camera, whether the details show,
/// and which hand the mouse drives.
#[derive(SystemParam)]
struct ViewChoices<'w> {
    mode: Res<'w, CameraMode>,
    details: Res<'w, Details>,
    mouse: Option<Res<'w, MouseHand>>,
}

fn update_hud(
    link: Res<HapticLink>,
    snapshot: Res<Snapshot>,
    time: Res<Time<Real>>,
    lesson: Option<Res<Lesson>>,
    view: ViewChoices,
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
    let force_n = snapshot.0.first_hand().force_n.norm();
    let mouse = (view.mouse.as_deref()).filter(|_| link.mouse_drives());
    let (force, status) = match snapshot.0.hands.len() {
        1 => (
            format!(
                "force {force_n:.3} N {} limit {limit_n:.1} N",
                gauge(force_n, limit_n)
            ),
            status_line(&link, &snapshot.0),
        ),
        _ => two_hands_lines(&link, &snapshot.0, mouse.map(|m| m.0)),
    };
    let help = if link.mouse_drives() {
        "\nmouse: move the tool | wheel or W/S: push in / pull out | Q/E: turn the handle\n\
         right-drag: orbit | middle-drag: pan | Ctrl+wheel or +/-: zoom"
    } else {
        ""
    };
    let timing = &snapshot.0.timing;
    let lines = HudLines {
        task: lesson.map_or_else(String::new, |lesson| {
            task_line(&lesson.scenario, snapshot.0.exercise)
        }),
        force,
        status,
        guidance: format!(
            "{}{help}{}{}{}",
            building_line(),
            instrument_line(&link, &snapshot.0),
            camera_line(&link, &snapshot.0, *view.mode),
            critical_view_line(&link, &snapshot.0)
        ),
        details: format!(
            "device: {}\nhaptic {:.0} Hz | tick p99 {:.0} us, late p99 {:.0} us, {} skipped | \
             frame {:.1} ms\n{}",
            link.device_name,
            rate.hz,
            timing.compute_p99_us,
            timing.lateness_p99_us,
            timing.skipped,
            dt * 1e3,
            tissue_line(&link)
        ),
    };
    text.0 = lines.compose(view.details.0);
}

/// A force against the limit as a bar of 20.
fn gauge(force_n: f64, limit_n: f64) -> String {
    let filled = ((force_n / limit_n).clamp(0.0, 1.0) * 20.0).round() as usize;
    format!("[{}{}]", "#".repeat(filled), "-".repeat(20 - filled))
}

/// Two hands: a line each (its instrument, what it holds or touches, its force against the
/// limit, and whether the mouse drives it), then the faults, or how to hand the mouse over.
fn two_hands_lines(
    link: &HapticLink,
    snapshot: &HapticSnapshot,
    mouse: Option<usize>,
) -> (String, String) {
    let limit_n = link.scene.safety.max_force_n;
    let name = |k: usize| {
        link.scene
            .organs
            .get(k)
            .map_or("?", |(name, _)| name.as_str())
    };
    let lines: Vec<String> = (snapshot.hands.iter().zip(&link.scene.hands).enumerate())
        .map(|(index, (hand, scene))| {
            let instrument = scene.instruments.get(hand.instruments.in_hand);
            let tool = instrument.map_or("tool".to_owned(), |i| action_name(i.action));
            let energy = match hand.cautery {
                Some(true) => " ENERGY ON",
                _ => "",
            };
            let touching: Vec<&str> = (0..link.scene.organs.len())
                .filter(|&k| k < 64 && hand.touching & (1 << k) != 0)
                .map(name)
                .collect();
            let doing = match (hand.holding, touching.is_empty()) {
                (Some(k), _) => format!("holding the {}", name(k)),
                (None, false) => format!("touching {}", touching.join(", ")),
                (None, true) => "free".to_owned(),
            };
            let driven = match mouse == Some(index) {
                true => " (mouse)",
                false => "",
            };
            let force_n = hand.force_n.norm();
            format!(
                "{}{driven}: {tool}{energy}, {doing} | {force_n:.3} N {}",
                HandIndex(index).name(),
                gauge(force_n, limit_n)
            )
        })
        .collect();
    let faulted: Vec<&str> = (snapshot.hands.iter().enumerate())
        .filter(|(_, hand)| hand.faulted)
        .map(|(index, _)| HandIndex(index).name())
        .collect();
    let status = match (faulted.is_empty(), mouse) {
        (false, _) => format!(
            "FAULT: the {}'s force faded to zero (see the log)",
            faulted.join(" and the ")
        ),
        (true, Some(_)) => {
            format!("limit {limit_n:.1} N a hand | H: the mouse takes the other hand")
        }
        (true, None) => format!("limit {limit_n:.1} N a hand"),
    };
    (lines.join("\n"), status)
}

/// What an instrument is called on the HUD (a hook with its power and mode).
fn action_name(action: Action) -> String {
    match action {
        Action::Press => "probe".to_owned(),
        Action::Grasp => "grasper".to_owned(),
        Action::Cut => "scalpel".to_owned(),
        Action::Cauterize(hook) => {
            let mode = match hook.mode {
                CauteryMode::Cut => "cut",
                CauteryMode::Coagulate => "coagulation",
            };
            format!("hook ({:.0} W, {mode})", hook.power_w)
        }
        Action::Clip { .. } => "clip applier".to_owned(),
        Action::Divide { .. } => "scissors".to_owned(),
    }
}

/// What the tool is doing: a fault, a grasp, the organs it touches, or nothing.
fn status_line(link: &HapticLink, snapshot: &HapticSnapshot) -> String {
    // A snapshot of the scene before a change may name organs the new one lacks.
    let name = |k: usize| link.scene.organs.get(k).map(|(name, _)| name.as_str());
    let organs = || snapshot.organs.iter().enumerate();
    let touching: Vec<&str> = organs()
        .filter(|(_, o)| o.contact.is_some())
        .filter_map(|(k, _)| name(k))
        .collect();
    let grasped = organs().find(|(_, o)| o.grasped).and_then(|(k, _)| name(k));
    if snapshot.first_hand().faulted {
        "FAULT: force faded to zero (see the log)".to_owned()
    } else if let Some(name) = grasped {
        format!("grasping {name}: release the button to let go")
    } else if touching.is_empty() {
        "no contact".to_owned()
    } else {
        format!("touching {}{}", touching.join(", "), beyond_range(snapshot))
    }
}

/// With a biliary tree, the critical view of safety as last judged: each criterion against
/// what the scenario asks.
fn critical_view_line(link: &HapticLink, snapshot: &HapticSnapshot) -> String {
    let (Some(tree), Some(biliary)) = (&snapshot.biliary, &link.scene.biliary) else {
        return String::new();
    };
    let (view, rule) = (tree.view, biliary.rule);
    format!(
        "\ncritical view of safety{}: triangle cleared {:.0} % (of {:.0}) | lower third off its \
         bed {:.0} % (of {:.0}) | structures seen entering the gallbladder {} of {}",
        if view.reached { " REACHED" } else { "" },
        100.0 * view.triangle_cleared,
        100.0 * rule.triangle_cleared,
        100.0 * view.lower_third_released,
        100.0 * rule.lower_third_released,
        view.seen,
        view.entering
    )
}

/// The HUD's parts: what the trainee reads first, then the details behind F3.
struct HudLines {
    /// The task and its clock (with a blank line after it), or nothing.
    task: String,
    force: String,
    status: String,
    /// Each line beginning with a line break: builds, keys, instruments, the laparoscope.
    guidance: String,
    /// The device, the loop's timing, the tissue.
    details: String,
}

impl HudLines {
    /// The HUD's text, with the details or the key that shows them.
    fn compose(&self, details: bool) -> String {
        let HudLines {
            task,
            force,
            status,
            guidance,
            ..
        } = self;
        let last = match details {
            true => format!("{}\nF3: hide these", self.details),
            false => "F3: the device, the loop's timing, the tissue".to_owned(),
        };
        format!("{task}{force}\n{status}{guidance}\n\n{last}")
    }
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
    format!("tissue: {}", laws.join(", "))
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
    let instruments = &link.scene.hands[0].instruments;
    if instruments.len() < 2 {
        return String::new();
    }
    let in_hand = snapshot.first_hand().instruments.in_hand;
    let name = action_name(instruments[in_hand].action);
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
        .first_hand()
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

/// The task under way, its clock and how far it has come, above the rest of the HUD (nothing
/// before the exercise begins or after it ends).
fn task_line(scenario: &Scenario, progress: Option<Progress>) -> String {
    let Some(progress) = progress.filter(|p| !p.finished()) else {
        return String::new();
    };
    let Some(task) = scenario.tasks.get(progress.task) else {
        return String::new();
    };
    let step = progress
        .step
        .map_or(String::new(), |step| format!(" | {step}"));
    let phase = (task.shared.phase.as_ref()).map_or(String::new(), |p| format!(" ({p})"));
    format!(
        "task {} of {}{phase}: {}\n{:.1} s of {:.0} s{step}\n\n",
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lines() -> HudLines {
        HudLines {
            task: "task 1 of 1: hold the force\n2.0 s of 20 s\n\n".into(),
            force: "force 0.210 N [#---] limit 3.3 N".into(),
            status: "touching liver".into(),
            guidance: "\nmouse: move the tool".into(),
            details: "device: mouse\nhaptic 1000 Hz | tick p99 77 us\ntissue: liver (linear)"
                .into(),
        }
    }

    /// Under the menu's, the briefing's and the debrief's panels the HUD is hidden; during the
    /// exercise and in free play (and with no lesson at all) it shows.
    #[test]
    fn the_hud_hides_under_the_panels() {
        use bevy::state::app::StatesPlugin;
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, StatesPlugin))
            .add_systems(Update, hide_under_panels);
        let hud = app.world_mut().spawn((Hud, Visibility::Inherited)).id();
        app.update();
        let visibility = |app: &App| *app.world().get::<Visibility>(hud).unwrap();
        assert_eq!(visibility(&app), Visibility::Inherited, "no lesson");
        app.init_state::<Stage>();
        for (stage, shown) in [
            (Stage::Menu, false),
            (Stage::Briefing, false),
            (Stage::Exercise, true),
            (Stage::Debrief, false),
            (Stage::FreePlay, true),
        ] {
            app.world_mut()
                .resource_mut::<NextState<Stage>>()
                .set(stage);
            app.update();
            app.update();
            let expected = match shown {
                true => Visibility::Inherited,
                false => Visibility::Hidden,
            };
            assert_eq!(visibility(&app), expected, "{stage:?}");
        }
    }

    /// The task's line says how far the task has come, in the type's own words, under its
    /// description and clock; before the start and after the end there is none.
    #[test]
    fn the_task_line_says_how_far_the_task_has_come() {
        let scenario = crate::scenario::parse(
            std::path::Path::new("t.scenario.ron"),
            r#"Scenario(title: "t", briefing: "b", organs: ["liver"],
                tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                                     hold_s: 3.0, time_limit_s: 20.0)])"#,
        )
        .unwrap();
        let step = crate::scenario::task::TaskProgress {
            what: "held",
            done: 1.24,
            of: 3.0,
            unit: "s",
        };
        let progress = Progress {
            task: 0,
            tasks: 1,
            task_elapsed_s: 2.0,
            step: Some(step),
        };
        let line = task_line(&scenario, Some(progress));
        assert!(
            line.starts_with("task 1 of 1: hold 0.10 to 0.30 N"),
            "{line}"
        );
        assert!(line.contains("2.0 s of 20 s | held 1.2 of 3.0 s"), "{line}");
        assert!(crate::report::without_glyph(&line).is_empty());
        let ended = Progress {
            task: 1,
            ..progress
        };
        assert_eq!(task_line(&scenario, Some(ended)), "");
        assert_eq!(task_line(&scenario, None), "");
        let mut phased = scenario.clone();
        phased.tasks[0].shared.phase = Some("exposure".into());
        let line = task_line(&phased, Some(progress));
        assert!(line.starts_with("task 1 of 1 (exposure): hold"), "{line}");
    }

    /// The trainee reads the task, the force and what the tool touches first, and the loop's
    /// figures only after pressing F3, which hides them again.
    #[test]
    fn the_loop_figures_wait_behind_f3() {
        let plain = lines().compose(false);
        assert!(plain.starts_with("task 1 of 1"), "{plain}");
        assert!(plain.contains("force 0.210 N") && plain.contains("touching liver"));
        assert!(
            !plain.contains("tick p99") && !plain.contains("device:"),
            "{plain}"
        );
        assert!(plain.ends_with("F3: the device, the loop's timing, the tissue"));
        let detailed = lines().compose(true);
        assert!(detailed.contains("tick p99 77 us") && detailed.contains("tissue: liver"));
        assert!(detailed.ends_with("F3: hide these"), "{detailed}");
        let drawn = crate::report::without_glyph(&format!("{plain}{detailed}"));
        assert!(drawn.is_empty(), "{drawn:?}");
    }
}
