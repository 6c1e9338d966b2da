//! A scenario in the window, in stages: the briefing (what to do, Space to begin), the
//! exercise (scored in the haptic thread; the HUD shows the task and its clock), and the
//! debrief (the score and what went wrong; R tries again from the briefing, M goes to the
//! menu of scenarios, Esc closes the window and writes a report per attempt).
//! Without a scenario the window stays in free play; with a scripted device the exercise
//! begins at once.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use bevy::prelude::*;

use super::FrameSet;
use super::bridge::Snapshot;
use super::doublet::{DOUBLET_WIDTH_PX, doublet_image, doublet_node};
use crate::app::attempt::{outcome_of, prepare, sites_on};
use crate::app::haptic::{ExerciseLink, HapticLoop, HapticScene};
use crate::report;
use crate::scenario::{Exercise, Scenario};

/// Where the trainee is.
#[derive(States, Default, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Stage {
    /// No scenario: the organs and the tool only.
    #[default]
    FreePlay,
    /// Choosing a scenario.
    Menu,
    /// The chosen scenario's scene being read (or built) away from the window.
    Loading,
    Briefing,
    Exercise,
    Debrief,
}

/// The scenario the window runs, and its link to the exercise in the haptic thread.
#[derive(Resource, Clone)]
pub struct Lesson {
    pub scenario: Scenario,
    /// The file it was read from (the built-in scenario's shipped name): its reports are
    /// named after it, and an edit of it reloads it.
    pub file: PathBuf,
    /// The scene it runs on, to find its nodules and regions for each fresh exercise.
    pub scene: HapticScene,
    pub link: Arc<ExerciseLink>,
}

impl Lesson {
    /// `scenario` (read from `file`) on `scene`, its exercise prepared in `haptic`'s world.
    pub fn prepare(
        haptic: &mut HapticLoop,
        scenario: Scenario,
        file: PathBuf,
        scene: HapticScene,
    ) -> Self {
        let exercise = Exercise::new(scenario.clone(), sites_on(&scene, &scenario));
        Self {
            link: prepare(haptic, exercise),
            scenario,
            file,
            scene,
        }
    }

    /// A fresh exercise of the scenario, for another attempt.
    pub(super) fn fresh_exercise(&self) -> Exercise {
        Exercise::new(self.scenario.clone(), sites_on(&self.scene, &self.scenario))
    }
}

/// Every lesson the window has run, in order, with its scenario's file: the attempts at each
/// are collected from its link when the window closes.
#[derive(Resource, Clone, Default)]
pub struct Lessons(Arc<Mutex<Vec<LessonRun>>>);

/// A lesson's scenario file and its link to the exercise.
pub type LessonRun = (PathBuf, Arc<ExerciseLink>);

impl Lessons {
    pub fn add(&self, lesson: &Lesson) {
        if let Ok(mut lessons) = self.0.lock() {
            lessons.push((lesson.file.clone(), lesson.link.clone()));
        }
    }

    /// The lessons run, once (after that, none).
    pub fn take(&self) -> Vec<LessonRun> {
        self.0
            .lock()
            .map(|mut l| std::mem::take(&mut *l))
            .unwrap_or_default()
    }
}

/// Where the window opens a lesson.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Opening {
    /// On the menu of scenarios, the lesson's own chosen.
    Menu,
    /// On the lesson's briefing (or its exercise, if begun already).
    Lesson,
}

/// The lesson's stages (menu, briefing, exercise, debrief) and the keys between them; the
/// lesson to open, if any, and where.
pub(super) struct LessonPlugin {
    pub lesson: Option<(Lesson, Opening)>,
    pub lessons: Lessons,
}

impl Plugin for LessonPlugin {
    fn build(&self, app: &mut App) {
        app.init_state::<Stage>()
            .add_systems(OnEnter(Stage::Briefing), show_briefing)
            .add_systems(OnEnter(Stage::Debrief), show_debrief)
            .add_systems(
                Update,
                (
                    begin_on_space.run_if(in_state(Stage::Briefing)),
                    debrief_when_done.run_if(in_state(Stage::Exercise)),
                    retry_on_r.run_if(in_state(Stage::Debrief)),
                    close_on_escape.run_if(in_state(Stage::Debrief).or_else(in_state(Stage::Menu))),
                    menu_on_m.run_if(in_state(Stage::Briefing).or_else(in_state(Stage::Debrief))),
                )
                    .in_set(FrameSet::Input),
            );
        let Some((lesson, opening)) = self.lesson.clone() else {
            return;
        };
        // An exercise begun already (a scripted device has no one to press Space) skips the
        // briefing.
        let first = match (lesson.link.started(), opening) {
            (true, _) => Stage::Exercise,
            (false, Opening::Menu) => Stage::Menu,
            (false, Opening::Lesson) => Stage::Briefing,
        };
        self.lessons.add(&lesson);
        app.insert_resource(lesson)
            .insert_resource(self.lessons.clone())
            .add_systems(Startup, move |mut next: ResMut<NextState<Stage>>| {
                next.set(first)
            });
    }
}

/// A panel of text in the middle of the window, gone when the stage ends; returns the text's
/// entity.
pub(super) fn spawn_panel(commands: &mut Commands, stage: Stage, text: String) -> Entity {
    spawn_panel_with(commands, stage, text, None)
}

/// [`spawn_panel`] with a picture beside the text (the debrief's critical view).
fn spawn_panel_with(
    commands: &mut Commands,
    stage: Stage,
    text: String,
    picture: Option<Handle<Image>>,
) -> Entity {
    let text = commands
        .spawn((
            Text::new(text),
            TextFont {
                font_size: FontSize::Px(17.0),
                ..default()
            },
        ))
        .id();
    commands
        .spawn((
            DespawnOnExit(stage),
            Node {
                position_type: PositionType::Absolute,
                width: percent(100),
                height: percent(100),
                align_items: AlignItems::Center,
                justify_content: JustifyContent::Center,
                ..default()
            },
        ))
        .with_children(|parent| {
            let mut panel = parent.spawn((
                Node {
                    max_width: px(720.0 + picture.as_ref().map_or(0.0, |_| DOUBLET_WIDTH_PX)),
                    max_height: percent(96),
                    padding: UiRect::all(px(24)),
                    overflow: Overflow::clip(),
                    align_items: AlignItems::Center,
                    ..default()
                },
                BackgroundColor(Color::srgba(0.02, 0.03, 0.05, 0.88)),
            ));
            panel.add_child(text);
            if let Some(picture) = picture {
                panel.with_child(doublet_node(picture));
            }
        });
    text
}

fn show_briefing(mut commands: Commands, lesson: Res<Lesson>) {
    spawn_panel(
        &mut commands,
        Stage::Briefing,
        briefing_text(&lesson.scenario),
    );
}

/// The briefing: title, difficulty, what to do, the tasks in order, how to begin.
fn briefing_text(scenario: &Scenario) -> String {
    let difficulty = scenario.difficulty.name();
    let tasks: Vec<String> = scenario
        .tasks
        .iter()
        .enumerate()
        .map(|(k, task)| {
            format!(
                "  {}. {} ({:.0} s)",
                k + 1,
                task.description(),
                task.time_limit_s()
            )
        })
        .collect();
    format!(
        "{} ({difficulty})\n\n{}\n\n{}\n\nPress Space to begin (M: the menu of scenarios).",
        scenario.title,
        scenario.briefing,
        tasks.join("\n")
    )
}

fn begin_on_space(
    keys: Res<ButtonInput<KeyCode>>,
    lesson: Res<Lesson>,
    mut next: ResMut<NextState<Stage>>,
) {
    if keys.just_pressed(KeyCode::Space) {
        lesson.link.start();
        next.set(Stage::Exercise);
    }
}

fn debrief_when_done(snapshot: Res<Snapshot>, mut next: ResMut<NextState<Stage>>) {
    if snapshot.0.exercise.is_some_and(|p| p.finished()) {
        next.set(Stage::Debrief);
    }
}

/// What the debrief's keys do. A web page has no reports to write, and nothing to close.
#[cfg(not(target_arch = "wasm32"))]
const DEBRIEF_KEYS: &str = "Press R to try again, M for the menu of scenarios, or Esc to close; the reports are written then.";
#[cfg(target_arch = "wasm32")]
const DEBRIEF_KEYS: &str = "Press R to try again, or M for the menu of scenarios.";

/// The scorecard the debrief shows, for the web page around the window.
#[cfg(target_arch = "wasm32")]
#[derive(Resource, Clone, Debug)]
pub(super) struct Debriefed(pub crate::scenario::Scorecard);

/// Scores a copy of the ended exercise for the screen, with the critical view's doublet
/// beside it where the scene has a biliary tree (off the web, whose plots have no font); the
/// attempt scores the exercise itself for the report when the window closes.
pub(super) fn show_debrief(
    mut commands: Commands,
    lesson: Res<Lesson>,
    images: Option<ResMut<Assets<Image>>>,
) {
    let (text, picture) = match lesson.link.ended_copy() {
        Some(exercise) => {
            let card = outcome_of(exercise).card;
            let text = report::summary(&card);
            let picture = (card.critical_view.as_ref())
                .filter(|_| cfg!(not(target_arch = "wasm32")))
                .and_then(doublet_image)
                .zip(images)
                .map(|(image, mut images)| images.add(image));
            #[cfg(target_arch = "wasm32")]
            commands.insert_resource(Debriefed(card));
            (text, picture)
        }
        None => ("The exercise has ended.".to_owned(), None),
    };
    spawn_panel_with(
        &mut commands,
        Stage::Debrief,
        format!("{text}\n{DEBRIEF_KEYS}"),
        picture,
    );
}

/// Another attempt at the same exercise: back to the briefing, scored from Space as before.
/// The ended attempt is kept for its report.
fn retry_on_r(
    keys: Res<ButtonInput<KeyCode>>,
    lesson: Res<Lesson>,
    mut next: ResMut<NextState<Stage>>,
) {
    if keys.just_pressed(KeyCode::KeyR) && lesson.link.retry(lesson.fresh_exercise()) {
        next.set(Stage::Briefing);
    }
}

/// To the menu, once the haptic thread has handed over an ended attempt (as for a retry).
fn menu_on_m(
    keys: Res<ButtonInput<KeyCode>>,
    lesson: Res<Lesson>,
    stage: Res<State<Stage>>,
    mut next: ResMut<NextState<Stage>>,
) {
    if keys.just_pressed(KeyCode::KeyM)
        && (*stage.get() == Stage::Briefing || lesson.link.ended_copy().is_some())
    {
        next.set(Stage::Menu);
    }
}

/// Esc closes the window; a web page's trainer stays (the page is closed as any other).
fn close_on_escape(keys: Res<ButtonInput<KeyCode>>, mut exit: MessageWriter<AppExit>) {
    if !cfg!(target_arch = "wasm32") && keys.just_pressed(KeyCode::Escape) {
        exit.write(AppExit::Success);
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use bevy::state::app::StatesPlugin;

    use super::super::testing::{scene_without_organs, stage, tap, texts};
    use super::*;
    use crate::biliary::{
        Anatomy, BiliaryTree, CriticalView, CriticalViewRule, Judging, Segment, ViewRecord,
    };
    use crate::mesh::organs::{Abdomen, OrganSettings};
    use crate::scenario::{Progress, Sample, Sites, parse};
    use nalgebra::Vector3;

    const SCENARIO: &str = r#"Scenario(
        title: "Quick press",
        briefing: "Press the liver.",
        organs: ["liver"],
        tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                             hold_s: 0.005, time_limit_s: 0.01)],
    )"#;

    fn app() -> (App, Arc<ExerciseLink>) {
        let scenario = parse(Path::new("quick.scenario.ron"), SCENARIO).unwrap();
        let link = Arc::new(ExerciseLink::default());
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, StatesPlugin))
            .init_resource::<ButtonInput<KeyCode>>()
            .init_resource::<Snapshot>()
            .add_message::<AppExit>();
        let lesson = Lesson {
            scenario,
            file: PathBuf::from("quick.scenario.ron"),
            scene: scene_without_organs(),
            link: link.clone(),
        };
        app.add_plugins(LessonPlugin {
            lesson: Some((lesson, Opening::Lesson)),
            lessons: Lessons::default(),
        });
        (app, link)
    }

    /// The exercise ended without the trainee touching the organ: a failed force control.
    fn ended_exercise(scenario: &Scenario, sites: Sites) -> Exercise {
        let mut exercise = Exercise::new(scenario.clone(), sites);
        for tick in 0..20 {
            exercise.step(&Sample {
                time_s: tick as f64 * 1e-3,
                ..Sample::default()
            });
        }
        assert!(exercise.finished());
        exercise
    }

    /// The haptic side ends the exercise, unscored, and says so in its snapshot.
    fn end_exercise(app: &mut App, link: &ExerciseLink) {
        end_exercise_at(app, link, Sites::default());
    }

    /// [`end_exercise`] of an exercise at `sites`.
    fn end_exercise_at(app: &mut App, link: &ExerciseLink, sites: Sites) {
        let scenario = app.world().resource::<Lesson>().scenario.clone();
        let mut ended = Some(ended_exercise(&scenario, sites));
        link.hand_over(&mut ended);
        assert!(ended.is_none());
        app.world_mut().resource_mut::<Snapshot>().0.exercise = Some(Progress {
            task: 1,
            tasks: 1,
            task_elapsed_s: 0.0,
            step: None,
        });
        app.update();
        app.update();
    }

    #[test]
    fn briefing_then_exercise_on_space_then_debrief_with_the_score() {
        let (mut app, link) = app();
        app.update();
        app.update();
        assert_eq!(stage(&app), Stage::Briefing);
        assert!(texts(&mut app).contains("Press the liver."));
        assert!(
            !link.started(),
            "the exercise began before the trainee was ready"
        );

        tap(&mut app, KeyCode::Space);
        assert_eq!(stage(&app), Stage::Exercise);
        assert!(link.started());
        assert!(!texts(&mut app).contains("Press the liver."));

        end_exercise(&mut app, &link);
        assert_eq!(stage(&app), Stage::Debrief);
        let debrief = texts(&mut app);
        assert!(
            debrief.contains("FAILED") && debrief.contains("Esc"),
            "{debrief}"
        );
        assert!(
            link.take_ended().is_some(),
            "the debrief must leave the exercise for the report"
        );
    }

    /// What the critical view was judged on in a generated tree, its fat intact.
    fn judged_record() -> ViewRecord {
        let abdomen = Abdomen::new(&OrganSettings::default());
        let tree = BiliaryTree::generate(&Anatomy::default(), &abdomen).unwrap();
        let optic = Vector3::new(0.0, 0.123, -0.2);
        let rule = CriticalViewRule::default();
        let view = CriticalView::judge(&tree, 1.0, optic, |_: &Segment| false, rule);
        let mut record = ViewRecord::new(&tree, 4, Vec::new(), Vec::new());
        record.keep(&Judging {
            time_s: 0.005,
            optic_m: optic,
            view: &view,
            tree: &tree,
            clips: &[],
            bed: None,
            organ_shifts_m: &[],
        });
        record
    }

    /// Where the critical view was judged, the debrief shows its doublet beside the score:
    /// the report's picture, at its size.
    #[test]
    fn the_debrief_shows_the_critical_view_beside_the_score() {
        let (mut app, link) = app();
        app.insert_resource(Assets::<Image>::default());
        app.update();
        tap(&mut app, KeyCode::Space);
        let sites = Sites {
            critical_view: Some(judged_record()),
            ..Sites::default()
        };
        end_exercise_at(&mut app, &link, sites);
        assert_eq!(stage(&app), Stage::Debrief);
        assert!(texts(&mut app).contains("FAILED"));
        let world = app.world_mut();
        let shown: Vec<AssetId<Image>> = (world.query::<&ImageNode>().iter(world))
            .map(|node| node.image.id())
            .collect();
        let images = world.resource::<Assets<Image>>();
        let [picture] = shown[..] else {
            panic!("{} pictures", shown.len());
        };
        assert_eq!(images.get(picture).unwrap().size(), UVec2::new(1200, 760));
    }

    /// R on the debrief goes back to the briefing for another attempt: the exercise is not
    /// scored until Space again, and the ended attempt is kept for its report.
    #[test]
    fn r_on_the_debrief_tries_again() {
        let (mut app, link) = app();
        app.update();
        tap(&mut app, KeyCode::Space);
        end_exercise(&mut app, &link);
        assert_eq!(stage(&app), Stage::Debrief);
        assert!(texts(&mut app).contains("R to try again"));

        tap(&mut app, KeyCode::KeyR);
        assert_eq!(stage(&app), Stage::Briefing);
        assert!(texts(&mut app).contains("Press the liver."));
        assert!(!link.started());
        app.world_mut().resource_mut::<Snapshot>().0.exercise = None;
        tap(&mut app, KeyCode::Space);
        assert_eq!(stage(&app), Stage::Exercise);
        assert!(link.started());
        assert_eq!(link.take_earlier().len(), 1, "the first attempt is kept");
        assert!(link.take_ended().is_none());
    }
}
