//! The scenario as a Bevy asset, reloaded when the educator saves its file: `trainer run FILE`
//! loads FILE through [`ScenarioLoader`] (the same reading and checks as `trainer validate`)
//! from its folder, which Bevy watches. An edit that keeps the scene (organs,
//! nodules, tool, device) replaces the scenario: on the briefing at once, during an exercise from the next
//! attempt. An edit that changes the scene, or that does not read, is reported at the bottom
//! of the window and changes nothing.

use std::path::{Path, PathBuf};

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoadFailedEvent, AssetLoader, AssetPlugin, LoadContext};
use bevy::prelude::*;

use super::FrameSet;
use super::lesson::{Lesson, Stage};
use crate::scenario::{Scenario, ScenarioError, parse};

/// A scenario file, read and checked.
#[derive(Asset, TypePath, Debug)]
pub struct ScenarioAsset(pub Scenario);

/// Reads `*.scenario.ron` files; `dir` is the folder the asset server reads from, so that
/// errors name the file as the educator knows it.
#[derive(TypePath)]
pub struct ScenarioLoader {
    dir: PathBuf,
}

impl AssetLoader for ScenarioLoader {
    type Asset = ScenarioAsset;
    type Settings = ();
    type Error = ScenarioError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        context: &mut LoadContext<'_>,
    ) -> Result<ScenarioAsset, ScenarioError> {
        let file = self.dir.join(context.path().path());
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|e| ScenarioError::unreadable(&file, e))?;
        let text = String::from_utf8(bytes).map_err(|e| ScenarioError::unreadable(&file, e))?;
        parse(&file, &text).map(ScenarioAsset)
    }

    fn extensions(&self) -> &[&str] {
        &["scenario.ron"]
    }
}

/// The asset server for the scenarios in `folder`: reading from it and watching it. Without a
/// folder, nothing is watched.
pub(super) fn asset_plugin(folder: Option<&Path>) -> AssetPlugin {
    let folder = folder.map(|f| absolute(f).to_string_lossy().into_owned());
    AssetPlugin {
        watch_for_changes_override: Some(folder.is_some()),
        file_path: folder.unwrap_or_else(|| AssetPlugin::default().file_path),
        meta_check: bevy::asset::AssetMetaCheck::Never,
        ..default()
    }
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_owned())
}

/// The lesson's scenario file as loaded from the watched folder.
#[derive(Resource)]
struct Watched {
    folder: PathBuf,
    file: PathBuf,
    handle: Option<Handle<ScenarioAsset>>,
}

/// The last word about the file (reloaded, refused), shown at the bottom of the window.
#[derive(Component)]
struct Notice;

/// Watches the scenarios in `folder`, if there is one (the asset plugin must come from
/// [`asset_plugin`] with the same folder): the lesson's file, whichever it is.
/// Watches the scenarios folder: an edit of the lesson's file reloads it.
pub(super) struct ReloadPlugin {
    pub folder: Option<PathBuf>,
}

impl Plugin for ReloadPlugin {
    fn build(&self, app: &mut App) {
        let Some(folder) = self.folder.as_deref().map(absolute) else {
            return;
        };
        app.init_asset::<ScenarioAsset>()
            .register_asset_loader(ScenarioLoader {
                dir: folder.clone(),
            })
            .insert_resource(Watched {
                folder,
                file: PathBuf::new(),
                handle: None,
            })
            .add_systems(Startup, spawn_notice)
            .add_systems(
                Update,
                (
                    follow_lesson.run_if(resource_exists_and_changed::<Lesson>),
                    apply_edits,
                    report_failures,
                )
                    .chain()
                    .in_set(FrameSet::Input),
            );
    }
}

/// Watches the lesson's file when it lies in the watched folder (the built-in scenario run
/// away from its folder does not).
fn follow_lesson(lesson: Res<Lesson>, assets: Res<AssetServer>, mut watched: ResMut<Watched>) {
    if watched.file == lesson.file {
        return;
    }
    watched.file = lesson.file.clone();
    let in_folder = lesson
        .file
        .parent()
        .is_some_and(|parent| absolute(parent) == watched.folder);
    watched.handle = match (in_folder, lesson.file.file_name()) {
        (true, Some(name)) => Some(assets.load(PathBuf::from(name))),
        _ => None,
    };
}

fn spawn_notice(mut commands: Commands) {
    commands.spawn((
        Notice,
        Text::default(),
        TextFont {
            font_size: FontSize::Px(15.0),
            ..default()
        },
        TextColor(Color::srgb(1.0, 0.85, 0.4)),
        Node {
            position_type: PositionType::Absolute,
            left: px(10),
            bottom: px(10),
            ..default()
        },
    ));
}

/// A saved edit that reads: taken if it keeps the scene, reported if not.
fn apply_edits(
    mut events: MessageReader<AssetEvent<ScenarioAsset>>,
    scenarios: Res<Assets<ScenarioAsset>>,
    watched: Res<Watched>,
    mut lesson: ResMut<Lesson>,
    stage: Res<State<Stage>>,
    mut next: ResMut<NextState<Stage>>,
    mut notice: Single<&mut Text, With<Notice>>,
) {
    for event in events.read() {
        let AssetEvent::Modified { id } = event else {
            continue;
        };
        let ours = watched.handle.as_ref().is_some_and(|h| h.id() == *id);
        let Some(edited) = scenarios.get(*id).filter(|_| ours) else {
            continue;
        };
        let file = watched.file.display();
        notice.0 = if !same_scene(&lesson.scenario, &edited.0) {
            format!(
                "{file}: the organs, nodules, contact, tool or device changed: choose it again on the menu (M) to use them"
            )
        } else {
            lesson.scenario = edited.0.clone();
            if *stage.get() == Stage::Briefing {
                lesson.link.offer(lesson.fresh_exercise());
                // Entered again, the briefing is drawn from the edited scenario.
                next.set(Stage::Briefing);
                format!("{file} reloaded")
            } else {
                format!("{file} reloaded: the next attempt (R on the debrief) uses it")
            }
        };
    }
}

/// Whether two scenarios run on the same haptic scene.
pub(super) fn same_scene(a: &Scenario, b: &Scenario) -> bool {
    a.organs == b.organs
        && a.nodules == b.nodules
        && a.instruments_in_hand() == b.instruments_in_hand()
        && a.device == b.device
}

/// A saved edit that does not read: its error, with file, line and field, on screen.
fn report_failures(
    mut failures: MessageReader<AssetLoadFailedEvent<ScenarioAsset>>,
    mut notice: Single<&mut Text, With<Notice>>,
) {
    for failure in failures.read() {
        notice.0 = format!("{}\n(the exercise is unchanged)", failure.error);
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::time::{Duration, Instant};

    use bevy::state::app::StatesPlugin;

    use super::super::testing::{scene_without_organs, texts};
    use super::*;
    use crate::app::haptic::{ExerciseLink, ExerciseRun};
    use crate::app::window::bridge::Snapshot;
    use crate::scenario::load;

    fn scenario_text(briefing: &str, organ: &str, max_force_n: f64) -> String {
        format!(
            r#"Scenario(title: "Press", briefing: "{briefing}", organs: ["{organ}"],
                tasks: [ForceControl(organ: "{organ}", min_force_n: 0.1,
                                     max_force_n: {max_force_n}, hold_s: 1.0, time_limit_s: 5.0)])"#
        )
    }

    /// The window's stages and the file watch, in a headless app over `file`.
    fn app(file: &Path) -> (App, Arc<ExerciseLink>) {
        let link = Arc::new(ExerciseLink::default());
        let lesson = Lesson {
            scenario: load(file).unwrap(),
            file: file.to_owned(),
            scene: scene_without_organs(),
            link: link.clone(),
        };
        let mut app = App::new();
        let folder = file.parent();
        app.add_plugins((MinimalPlugins, StatesPlugin, asset_plugin(folder)))
            .init_resource::<ButtonInput<KeyCode>>()
            .init_resource::<Snapshot>()
            .add_message::<AppExit>();
        let opening = super::super::lesson::Opening::Lesson;
        app.add_plugins((
            ReloadPlugin {
                folder: folder.map(Path::to_path_buf),
            },
            super::super::lesson::LessonPlugin {
                lesson: Some((lesson, opening)),
                lessons: Default::default(),
            },
        ));
        (app, link)
    }

    /// Updates the app until `done` (the file watcher takes a moment), for at most 20 s.
    fn update_until(app: &mut App, what: &str, done: impl Fn(&mut App) -> bool) {
        let start = Instant::now();
        while !done(app) {
            assert!(start.elapsed() < Duration::from_secs(20), "never: {what}");
            std::thread::sleep(Duration::from_millis(20));
            app.update();
        }
    }

    /// Saved on the briefing, an edit is shown at once and is what the exercise runs; an edit
    /// that changes the organs, and one that does not validate, are reported on screen and
    /// change nothing.
    #[test]
    fn an_edit_reloads_on_the_briefing_and_a_bad_one_changes_nothing() {
        let dir = std::env::temp_dir().join(format!("pgd-reload-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("press.scenario.ron");
        std::fs::write(&file, scenario_text("Press the liver.", "liver", 0.3)).unwrap();
        let (mut app, link) = app(&file);
        update_until(&mut app, "the first load", |app| {
            app.world().resource::<Assets<ScenarioAsset>>().len() == 1
        });
        assert!(texts(&mut app).contains("Press the liver."));

        std::fs::write(&file, scenario_text("Press it gently.", "liver", 0.3)).unwrap();
        update_until(&mut app, "the briefing redrawn", |app| {
            texts(app).contains("Press it gently.")
        });
        assert!(texts(&mut app).contains("reloaded"));
        link.start();
        let taken = ExerciseRun::new(link.clone()).into_exercise().unwrap();
        assert_eq!(taken.finish().scenario.briefing, "Press it gently.");

        std::fs::write(&file, scenario_text("Press the spleen.", "pancreas", 0.3)).unwrap();
        update_until(&mut app, "the scene change refused", |app| {
            texts(app).contains("choose it again on the menu")
        });
        std::fs::write(&file, scenario_text("Too hard.", "liver", 30.0)).unwrap();
        update_until(&mut app, "the bad value shown", |app| {
            texts(app).contains("forces here are in newtons")
        });
        let notice = texts(&mut app);
        assert!(notice.contains("press.scenario.ron:3:"), "{notice}");
        let lesson = app.world().resource::<Lesson>();
        assert_eq!(lesson.scenario.briefing, "Press it gently.");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
