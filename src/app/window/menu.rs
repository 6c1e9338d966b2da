//! The menu of scenarios: every `*.scenario.ron` in the scenarios folder (and the built-in
//! one, when the folder lacks it), each with its title, difficulty and organs; a file that
//! does not validate is listed with its error and cannot be chosen. The chosen scenario's
//! scene is read as a task away from the frames (its vademecums loaded, fetched first in a web
//! page, or built when missing), handed to the haptic loop, and the window redrawn on it; then
//! its briefing opens.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, BoxedFuture, Task, block_on, poll_once};

use super::bridge::HapticLink;
use super::lesson::{Lesson, Lessons, Stage, spawn_panel};
use super::offscreen::Offscreen;
use super::{FrameSet, SceneChanged};
use crate::app::haptic::{HapticLoop, HapticScene, HapticSnapshot, SceneSwap};
use crate::app::scene::mouse_device;
use crate::scenario::curriculum::{Curriculum, ModuleStanding, ModuleState};
use crate::scenario::{self, Scenario};

/// Builds a scenario's scene: its organs' vademecums read (in a web page, fetched first), or
/// built when missing or stale.
pub type SceneSource =
    Arc<dyn Fn(&Scenario) -> BoxedFuture<'static, Result<HapticScene, String>> + Send + Sync>;

/// What the menu offers and how it changes the scene.
#[derive(Resource, Clone)]
pub struct MenuPlan {
    /// The folder whose scenarios are offered (none: the built-in ones only).
    pub folder: Option<PathBuf>,
    /// The scenarios built into the program (file names and texts, as
    /// [`SHIPPED_SCENARIOS`](crate::app::SHIPPED_SCENARIOS)), offered where the folder lacks
    /// them.
    pub built_in: &'static [(&'static str, &'static str)],
    pub scenes: SceneSource,
    /// Where the haptic thread takes the chosen scenario's world.
    pub swap: SceneSwap,
    /// The vademecum files built in the background so far ([`HapticScene::meanwhile`]).
    pub built: BuiltFiles,
    /// A programme's curriculum: the menu then offers its exercises in its order, module by
    /// module, the locked ones refused.
    pub curriculum: Option<MenuCurriculum>,
}

/// A curriculum as the menu offers it, and where the trainee stands in it (read afresh each
/// time the menu opens: an attempt just made may have opened a module).
#[derive(Clone)]
pub struct MenuCurriculum {
    pub curriculum: Curriculum,
    pub standing: Arc<dyn Fn() -> Vec<ModuleStanding> + Send + Sync>,
}

/// Where an entry stands in the curriculum: its module, the module's state, whether the
/// exercise is had, and (locked) what the module waits on.
#[derive(Clone, Debug, PartialEq)]
struct Place {
    module: String,
    state: ModuleState,
    had: bool,
    waits_on: String,
}

/// The files the background builder has built (none in a web page, which builds nothing).
pub type BuiltFiles = Arc<dyn Fn() -> Vec<PathBuf> + Send + Sync>;

/// A scenario on offer: read and checked, or why not.
struct Entry {
    file: PathBuf,
    scenario: Result<Scenario, String>,
    /// In a curriculum, where it stands.
    place: Option<Place>,
}

/// The menu on screen: its entries, the one highlighted, and why the last choice failed.
#[derive(Resource, Default)]
struct Menu {
    entries: Vec<Entry>,
    selected: usize,
    problem: Option<String>,
}

/// The menu's text.
#[derive(Component)]
struct MenuText;

/// The chosen scenario on its way: a task reading its scene and building its haptic world.
#[derive(Resource)]
struct Loading {
    title: String,
    task: Task<Result<Prepared, String>>,
}

/// A lesson ready to run: its haptic world (parked, with its exercise offered) and the end of
/// the world's snapshots that the window reads.
struct Prepared {
    lesson: Lesson,
    haptic: HapticLoop,
    snapshots: triple_buffer::Output<HapticSnapshot>,
}

/// The menu of scenarios, when there is one (not in free play).
pub(super) struct MenuPlugin(pub Option<MenuPlan>);

impl Plugin for MenuPlugin {
    fn build(&self, app: &mut App) {
        let Some(plan) = self.0.clone() else {
            return;
        };
        app.insert_resource(plan)
            .init_resource::<Menu>()
            .add_systems(OnEnter(Stage::Menu), show_menu)
            .add_systems(OnEnter(Stage::Loading), show_loading)
            .add_systems(
                Update,
                (
                    (move_selection, refuse_locked, choose_on_enter)
                        .chain()
                        .run_if(in_state(Stage::Menu)),
                    finish_loading.run_if(in_state(Stage::Loading)),
                    reload_when_built.run_if(in_state(Stage::Briefing)),
                )
                    .in_set(FrameSet::Input),
            );
    }
}

/// The scenarios on offer, read afresh (an educator may have edited or added one): the
/// curriculum's in its order, or the folder's and the built-in ones.
fn entries(plan: &MenuPlan) -> Vec<Entry> {
    match &plan.curriculum {
        Some(curriculum) => curriculum_entries(&curriculum.curriculum, &(curriculum.standing)()),
        None => folder_entries(plan),
    }
}

/// The curriculum's exercises, module by module, each with where it stands.
fn curriculum_entries(curriculum: &Curriculum, standing: &[ModuleStanding]) -> Vec<Entry> {
    let modules = curriculum.modules.iter().zip(standing);
    modules
        .flat_map(|(module, stands)| {
            let exercises = module.exercises.iter().zip(&stands.exercises);
            exercises.map(move |(exercise, had)| Entry {
                scenario: scenario::load(&exercise.scenario).map_err(|e| e.to_string()),
                file: exercise.scenario.clone(),
                place: Some(Place {
                    module: module.name.clone(),
                    state: stands.state,
                    had: had.had(),
                    waits_on: module.opens_after.join(", "),
                }),
            })
        })
        .collect()
}

/// The folder's scenarios, and the built-in ones it lacks first.
fn folder_entries(plan: &MenuPlan) -> Vec<Entry> {
    let mut files: Vec<PathBuf> = plan
        .folder
        .as_deref()
        .and_then(|folder| std::fs::read_dir(folder).ok())
        .into_iter()
        .flatten()
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.to_string_lossy().ends_with(".scenario.ron"))
        .collect();
    files.sort();
    let mut entries: Vec<Entry> = files
        .into_iter()
        .map(|file| Entry {
            scenario: scenario::load(&file).map_err(|e| e.to_string()),
            file,
            place: None,
        })
        .collect();
    let missing: Vec<Entry> = plan
        .built_in
        .iter()
        .filter(|(file, _)| {
            !entries
                .iter()
                .any(|e| e.file.file_name() == Path::new(file).file_name())
        })
        .map(|&(file, text)| Entry {
            scenario: scenario::parse(Path::new(file), text).map_err(|e| e.to_string()),
            file: PathBuf::from(file),
            place: None,
        })
        .collect();
    entries.splice(0..0, missing);
    entries
}

fn show_menu(
    mut commands: Commands,
    plan: Res<MenuPlan>,
    lesson: Res<Lesson>,
    screen: ScreenHeight,
    mut menu: ResMut<Menu>,
) {
    menu.entries = entries(&plan);
    let current = lesson.file.file_name();
    menu.selected = menu
        .entries
        .iter()
        .position(|e| e.file.file_name() == current)
        .unwrap_or(0);
    let rows = screen.entry_rows();
    let text = spawn_panel(&mut commands, Stage::Menu, menu_text(&menu, rows));
    commands.entity(text).insert(MenuText);
}

/// The height (pixels) the menu has: the window's, or the offscreen image's.
#[derive(SystemParam)]
struct ScreenHeight<'w, 's> {
    window: Query<'w, 's, &'static Window>,
    offscreen: Option<Res<'w, Offscreen>>,
}

/// A line of the panel's text (pixels): its 17 px font and the line spacing.
const LINE_PX: f32 = 21.0;

/// The lines of the panel that are not entries: its padding and margins, the header, the
/// selected entry's second line, the scroll marks and a failed choice's message.
const OTHER_LINES: usize = 11;

impl ScreenHeight<'_, '_> {
    /// How many entries, a line each, the menu shows at once: what the height leaves, three
    /// at least.
    fn entry_rows(&self) -> usize {
        let height_px = match (self.window.iter().next(), &self.offscreen) {
            (Some(window), _) => window.height(),
            (None, Some(offscreen)) => offscreen.size.y as f32,
            (None, None) => 600.0,
        };
        ((height_px / LINE_PX) as usize)
            .saturating_sub(OTHER_LINES)
            .max(3)
    }
}

/// The menu's text with at most `rows` entries, a line each, scrolled to keep the selected
/// one in sight (with its file on a second line); marks say how many are above and below.
fn menu_text(menu: &Menu, rows: usize) -> String {
    let count = menu.entries.len();
    // A curriculum's module names take rows of their own.
    let headers = (menu.entries.windows(2))
        .filter(|pair| {
            pair[0].place.as_ref().map(|p| &p.module) != pair[1].place.as_ref().map(|p| &p.module)
        })
        .count()
        + usize::from(menu.entries.first().is_some_and(|e| e.place.is_some()));
    let rows = rows.saturating_sub(headers).max(1).min(count.max(1));
    let first = menu
        .selected
        .saturating_sub(rows / 2)
        .min(count.saturating_sub(rows));
    let mut lines: Vec<String> = Vec::new();
    if first > 0 {
        lines.push(format!("  ↑ {first} more"));
    }
    for (k, entry) in menu.entries.iter().enumerate().skip(first).take(rows) {
        let module = entry.place.as_ref().map(|p| &p.module);
        let before = k
            .checked_sub(1)
            .and_then(|j| menu.entries[j].place.as_ref());
        if let Some(place) = entry
            .place
            .as_ref()
            .filter(|_| module != before.map(|p| &p.module))
        {
            lines.push(module_header(place));
        }
        lines.push(entry_text(entry, k == menu.selected));
    }
    let below = count.saturating_sub(first + rows);
    if below > 0 {
        lines.push(format!("  ↓ {below} more"));
    }
    let problem = match &menu.problem {
        Some(problem) => format!("\n\nThe last choice could not be loaded:\n{problem}"),
        None => String::new(),
    };
    // A web page's trainer is not closed by a key.
    let close = if cfg!(target_arch = "wasm32") {
        ""
    } else {
        " (Esc closes the trainer)"
    };
    format!(
        "Choose a scenario: Up and Down, then Enter{close}.\n\n{}{problem}",
        lines.join("\n")
    )
}

/// A curriculum module's line above its exercises: its name and state.
fn module_header(place: &Place) -> String {
    let state = match place.state {
        ModuleState::Done => "done".to_owned(),
        ModuleState::Open => "open".to_owned(),
        ModuleState::Locked => format!("locked: opens after {}", place.waits_on),
    };
    format!("{} ({state})", place.module)
}

/// One entry: its title, difficulty and organs (or why it cannot be run); the selected one
/// marked, with its file below; in a curriculum, whether it is had or locked.
fn entry_text(entry: &Entry, selected: bool) -> String {
    let name = file_name(&entry.file);
    let mark = match &entry.place {
        Some(place) if place.state == ModuleState::Locked => "[locked] ",
        Some(place) if place.had => "[had] ",
        _ => "",
    };
    let line = match &entry.scenario {
        Ok(s) => format!(
            "{}  ({}; {})",
            s.title,
            s.difficulty.name(),
            s.organ_names()
        ),
        Err(e) => format!(
            "{name}: cannot be run: {}",
            e.lines().next().unwrap_or_default()
        ),
    };
    match selected {
        true => format!("> {mark}{line}\n      {name}"),
        false => format!("  {mark}{line}"),
    }
}

fn file_name(file: &Path) -> String {
    file.file_name().map_or_else(
        || file.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

fn move_selection(
    keys: Res<ButtonInput<KeyCode>>,
    screen: ScreenHeight,
    mut menu: ResMut<Menu>,
    mut text: Single<&mut Text, With<MenuText>>,
) {
    let count = menu.entries.len().max(1);
    let step = if keys.just_pressed(KeyCode::ArrowDown) {
        1
    } else if keys.just_pressed(KeyCode::ArrowUp) {
        count - 1
    } else {
        return;
    };
    menu.selected = (menu.selected + step) % count;
    text.0 = menu_text(&menu, screen.entry_rows());
}

/// Enter on a scenario that reads: its scene is loaded as a task.
fn choose_on_enter(
    mut commands: Commands,
    keys: Res<ButtonInput<KeyCode>>,
    menu: Res<Menu>,
    plan: Res<MenuPlan>,
    lesson: Res<Lesson>,
    mut next: ResMut<NextState<Stage>>,
) {
    if !keys.just_pressed(KeyCode::Enter) {
        return;
    }
    let chosen = menu.entries.get(menu.selected);
    if chosen.and_then(locked_problem).is_some() {
        return;
    }
    let Some(Entry {
        file,
        scenario: Ok(scenario),
        ..
    }) = menu.entries.get(menu.selected)
    else {
        return;
    };
    // The same scene needs no vademecum read again.
    let same = super::reload::same_scene(&lesson.scenario, scenario).then(|| lesson.scene.clone());
    let scene: BoxedFuture<'static, _> = match same {
        Some(scene) => Box::pin(std::future::ready(Ok(scene))),
        None => (plan.scenes)(scenario),
    };
    load(
        &mut commands,
        file.clone(),
        scenario.clone(),
        scene,
        &mut next,
    );
}

/// Enter on a locked curriculum exercise: the menu says why it cannot be chosen.
fn refuse_locked(
    keys: Res<ButtonInput<KeyCode>>,
    screen: ScreenHeight,
    mut menu: ResMut<Menu>,
    mut text: Single<&mut Text, With<MenuText>>,
) {
    if !keys.just_pressed(KeyCode::Enter) {
        return;
    }
    if let Some(locked) = menu.entries.get(menu.selected).and_then(locked_problem) {
        menu.problem = Some(locked);
        text.0 = menu_text(&menu, screen.entry_rows());
    }
}

/// Why a locked curriculum exercise cannot be chosen; none for another entry.
fn locked_problem(entry: &Entry) -> Option<String> {
    let place = entry.place.as_ref()?;
    (place.state == ModuleState::Locked).then(|| {
        format!(
            "{} is locked: the module {} opens once {} done",
            file_name(&entry.file),
            place.module,
            place.waits_on
        )
    })
}

/// On the briefing, once a nonlinear vademecum that the lesson's scene runs linear tissue for
/// meanwhile has been built in the background, the scene is loaded again (once per file), so
/// that the attempt about to begin is felt with it. Not during an exercise: its tissue would
/// change under the trainee's hand.
fn reload_when_built(
    mut commands: Commands,
    plan: Res<MenuPlan>,
    lesson: Res<Lesson>,
    mut reloaded: Local<Vec<PathBuf>>,
    mut next: ResMut<NextState<Stage>>,
) {
    let waiting = &lesson.scene.meanwhile;
    if waiting.iter().all(|file| reloaded.contains(file)) {
        return;
    }
    let built = (plan.built)();
    let ready: Vec<PathBuf> = waiting
        .iter()
        .filter(|file| built.contains(file) && !reloaded.contains(file))
        .cloned()
        .collect();
    if ready.is_empty() {
        return;
    }
    reloaded.extend(ready);
    let scene = (plan.scenes)(&lesson.scenario);
    let (file, scenario) = (lesson.file.clone(), lesson.scenario.clone());
    load(&mut commands, file, scenario, scene, &mut next);
}

/// Reads `scene` for the scenario read from `file` as a task away from the frames; the
/// briefing opens when it is ready.
fn load(
    commands: &mut Commands,
    file: PathBuf,
    scenario: Scenario,
    scene: BoxedFuture<'static, Result<HapticScene, String>>,
    next: &mut NextState<Stage>,
) {
    let title = scenario.title.clone();
    let task = AsyncComputeTaskPool::get().spawn(async move {
        let scene = scene.await?;
        prepared(file, scenario, scene)
    });
    commands.insert_resource(Loading { title, task });
    next.set(Stage::Loading);
}

/// The lesson of `scenario` on `scene`, with its parked haptic world.
fn prepared(file: PathBuf, scenario: Scenario, scene: HapticScene) -> Result<Prepared, String> {
    let mut haptic = HapticLoop::parked(&scene).map_err(|e| format!("{}: {e}", file.display()))?;
    let lesson = Lesson::prepare(&mut haptic, scenario, file, scene);
    let snapshots = haptic.publish();
    Ok(Prepared {
        lesson,
        haptic,
        snapshots,
    })
}

fn show_loading(mut commands: Commands, loading: Res<Loading>) {
    spawn_panel(
        &mut commands,
        Stage::Loading,
        format!(
            "Loading {}: reading its organs' vademecums (one that is missing is built first; \
             its progress shows in the terminal or the browser's console).",
            loading.title
        ),
    );
}

/// When the chosen scene is ready: the haptic thread is handed its world, the window redraws
/// on it, and the briefing opens; if it failed, back to the menu with the reason.
#[allow(clippy::too_many_arguments)]
fn finish_loading(
    mut commands: Commands,
    mut loading: ResMut<Loading>,
    plan: Res<MenuPlan>,
    lessons: Res<Lessons>,
    mut link: ResMut<HapticLink>,
    mut menu: ResMut<Menu>,
    mut changed: MessageWriter<SceneChanged>,
    mut next: ResMut<NextState<Stage>>,
) {
    let Some(result) = block_on(poll_once(&mut loading.task)) else {
        return;
    };
    commands.remove_resource::<Loading>();
    match result {
        Ok(mut prepared) => {
            mouse_for_new_hands(&mut link, &mut prepared);
            plan.swap.offer(prepared.haptic);
            // This frame's snapshot is read from the new scene's end, after this stage.
            link.change_scene(prepared.lesson.scene.clone(), prepared.snapshots);
            lessons.add(&prepared.lesson);
            commands.insert_resource(prepared.lesson);
            menu.problem = None;
            changed.write(SceneChanged);
            next.set(Stage::Briefing);
        }
        Err(problem) => {
            menu.problem = Some(problem);
            next.set(Stage::Menu);
        }
    }
}

/// The hands the chosen scene has and the running one lacks (a bimanual exercise after a
/// one-hand one: its left hand) go on the mouse, which H hands them; the mouse no longer
/// drives a hand the chosen scene lacks.
fn mouse_for_new_hands(link: &mut HapticLink, prepared: &mut Prepared) {
    let scene = &prepared.lesson.scene;
    link.mice.truncate(scene.hands.len());
    for hand in link.scene.hands.len()..scene.hands.len() {
        let (device, handle) = mouse_device(scene, hand);
        prepared.haptic.give_device(hand, device);
        if link.mice.len() <= hand {
            link.mice.resize(hand + 1, None);
        }
        link.mice[hand] = Some(handle);
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::{Duration, Instant};

    use bevy::state::app::StatesPlugin;

    use super::super::bridge::Snapshot;
    use super::super::lesson::{self, Opening};
    use super::super::testing::{scene_without_organs, stage, tap, texts};
    use super::*;
    use crate::app::haptic::ExerciseLink;

    fn scenario_text(title: &str, organ: &str) -> String {
        format!(
            r#"Scenario(title: "{title}", briefing: "Brief of {title}.", organs: ["{organ}"],
                tasks: [ForceControl(organ: "{organ}", min_force_n: 0.1, max_force_n: 0.3,
                                     hold_s: 1.0, time_limit_s: 5.0)])"#
        )
    }

    /// A curriculum in the menu: its exercises in its order under their modules' headers,
    /// the had one marked, the locked module's refused with what it waits on.
    #[test]
    fn a_curriculum_orders_the_menu_and_locks_its_modules() {
        use crate::scenario::curriculum::{
            CountedAttempt, ExerciseEntry, Module, Proficiency, standing,
        };
        use crate::scenario::{AttemptCount, Score};
        let exercise = |name: &str| ExerciseEntry {
            scenario: PathBuf::from(format!("scenarios/{name}.scenario.ron")),
            proficiency: Proficiency::Attempts {
                count: AttemptCount(1),
                min_score: Score(80.0),
            },
        };
        let curriculum = Curriculum {
            title: "t".into(),
            modules: vec![
                Module {
                    name: "Basics".into(),
                    opens_after: Vec::new(),
                    exercises: vec![exercise("liver-steady-press"), exercise("pancreas-tour")],
                },
                Module {
                    name: "Tasks".into(),
                    opens_after: vec!["Basics".into()],
                    exercises: vec![exercise("gallbladder-grasp-retract")],
                },
            ],
        };
        let made = [CountedAttempt {
            scenario: "scenarios/liver-steady-press.scenario.ron",
            score: 90.0,
            passed: true,
            proficient: None,
        }];
        let menu = Menu {
            entries: curriculum_entries(&curriculum, &standing(&curriculum, &made)),
            selected: 2,
            problem: None,
        };
        let text = menu_text(&menu, 10);
        let lines: Vec<&str> = text.lines().skip(2).collect();
        assert_eq!(lines[0], "Basics (open)", "{text}");
        assert!(
            lines[1].starts_with("  [had] Steady press on the liver"),
            "{text}"
        );
        assert!(lines[2].starts_with("  Pancreas: head to tail"), "{text}");
        assert_eq!(lines[3], "Tasks (locked: opens after Basics)", "{text}");
        assert!(lines[4].starts_with("> [locked] "), "{text}");
        let refused = locked_problem(&menu.entries[2]).expect("locked");
        assert!(
            refused.contains("gallbladder-grasp-retract.scenario.ron is locked"),
            "{refused}"
        );
        assert!(locked_problem(&menu.entries[0]).is_none());
    }

    /// Thirty scenarios in eight rows: the menu shows eight entries around the selected one,
    /// says how many are above and below, and scrolls as the selection moves; at the ends it
    /// shows the first or the last eight.
    #[test]
    fn a_long_menu_scrolls_to_keep_the_selection_in_sight() {
        let entries = (0..30)
            .map(|k| Entry {
                file: PathBuf::from(format!("s{k:02}.scenario.ron")),
                scenario: Err("not read".into()),
                place: None,
            })
            .collect();
        let mut menu = Menu {
            entries,
            selected: 15,
            problem: None,
        };
        let text = menu_text(&menu, 8);
        assert!(
            text.contains("↑ 11 more") && text.contains("↓ 11 more"),
            "{text}"
        );
        assert!(text.contains("> s15.scenario.ron") && text.contains("  s11.scenario.ron"));
        assert!(!text.contains("s10.scenario.ron") && !text.contains("s19.scenario.ron"));
        menu.selected = 0;
        let top = menu_text(&menu, 8);
        assert!(
            !top.contains('↑') && top.contains("↓ 22 more") && top.contains("s07"),
            "{top}"
        );
        menu.selected = 29;
        let bottom = menu_text(&menu, 8);
        assert!(
            bottom.contains("↑ 22 more") && !bottom.contains('↓'),
            "{bottom}"
        );
        assert_eq!(crate::report::without_glyph(&text), Vec::<char>::new());
    }

    struct Fixture {
        app: App,
        folder: PathBuf,
        /// How many scenes the menu has had built.
        built: Arc<AtomicUsize>,
        swap: SceneSwap,
        lessons: Lessons,
        /// The files the next scene built runs linear tissue for meanwhile...
        meanwhile: Arc<Mutex<Vec<PathBuf>>>,
        /// ...and the files the background builder has built.
        finished: Arc<Mutex<Vec<PathBuf>>>,
    }

    /// A headless window on the first of three scenarios in a folder of the test's own (the
    /// third broken), opening on the menu; scenes are built without organs.
    fn fixture(test: &str) -> Fixture {
        let folder = std::env::temp_dir().join(format!("pgd-menu-{test}-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let write = |name: &str, text: &str| std::fs::write(folder.join(name), text).unwrap();
        write("a.scenario.ron", &scenario_text("Liver press", "liver"));
        write(
            "b.scenario.ron",
            &scenario_text("Pancreas press", "pancreas"),
        );
        write("c.scenario.ron", "Scenario(title: 3)");
        let file = folder.join("a.scenario.ron");
        let scene = scene_without_organs();
        let lesson = Lesson {
            scenario: scenario::load(&file).unwrap(),
            file,
            scene: scene.clone(),
            link: Arc::new(ExerciseLink::default()),
        };
        let built = Arc::new(AtomicUsize::new(0));
        let counter = built.clone();
        let swap = SceneSwap::default();
        let meanwhile = Arc::new(Mutex::new(Vec::new()));
        let finished = Arc::new(Mutex::new(Vec::new()));
        let (waiting, done) = (meanwhile.clone(), finished.clone());
        let plan = MenuPlan {
            folder: Some(folder.clone()),
            built_in: &[("scenarios/built-in.scenario.ron", "unused")],
            scenes: Arc::new(move |_: &Scenario| {
                counter.fetch_add(1, Ordering::SeqCst);
                let mut scene = scene_without_organs();
                scene.meanwhile = waiting.lock().unwrap().clone();
                Box::pin(std::future::ready(Ok(scene)))
            }),
            swap: swap.clone(),
            built: Arc::new(move || done.lock().unwrap().clone()),
            curriculum: None,
        };
        let lessons = Lessons::default();
        let mut app = App::new();
        let snapshots = HapticLoop::parked(&scene).unwrap().publish();
        app.add_plugins((MinimalPlugins, StatesPlugin))
            .init_resource::<ButtonInput<KeyCode>>()
            .init_resource::<Snapshot>()
            .insert_resource(HapticLink::headless(scene, snapshots))
            .add_message::<AppExit>()
            .add_message::<SceneChanged>();
        app.add_plugins((
            lesson::LessonPlugin {
                lesson: Some((lesson, Opening::Menu)),
                lessons: lessons.clone(),
            },
            MenuPlugin(Some(plan)),
        ));
        Fixture {
            app,
            folder,
            built,
            swap,
            lessons,
            meanwhile,
            finished,
        }
    }

    /// Updates until the chosen scenario's briefing opens (the loader is a thread), at most 20 s.
    fn until_briefing(app: &mut App) {
        let start = Instant::now();
        while stage(app) != Stage::Briefing {
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "never loaded: {:?}",
                stage(app)
            );
            std::thread::sleep(Duration::from_millis(5));
            app.update();
        }
        app.update();
    }

    /// The menu lists the folder's scenarios (a broken one with its error, not choosable);
    /// choosing another builds its scene, hands the haptic thread its world and opens its
    /// briefing; back on the menu, choosing the same scene again builds nothing.
    #[test]
    fn the_menu_changes_the_scenario_and_its_scene() {
        let Fixture {
            mut app,
            folder,
            built,
            swap,
            lessons,
            ..
        } = fixture("choose");
        app.update();
        app.update();
        assert_eq!(stage(&app), Stage::Menu);
        let menu = texts(&mut app);
        assert!(menu.contains("> Liver press"), "{menu}");
        assert!(menu.contains("  Pancreas press"), "{menu}");
        assert!(menu.contains("c.scenario.ron: cannot be run"), "{menu}");
        assert!(
            menu.contains("built-in.scenario.ron"),
            "the built-in scenario is offered when the folder lacks it: {menu}"
        );

        tap(&mut app, KeyCode::ArrowDown);
        assert!(texts(&mut app).contains("> Pancreas press"));
        tap(&mut app, KeyCode::Enter);
        until_briefing(&mut app);
        assert!(texts(&mut app).contains("Brief of Pancreas press."));
        assert_eq!(built.load(Ordering::SeqCst), 1);
        assert!(
            swap.pending(),
            "the haptic thread was not offered the new world"
        );
        let lesson = app.world().resource::<Lesson>();
        assert_eq!(lesson.scenario.organ_names(), "pancreas");
        assert_eq!(lessons.take().len(), 2);

        tap(&mut app, KeyCode::KeyM);
        assert_eq!(stage(&app), Stage::Menu);
        assert!(texts(&mut app).contains("> Pancreas press"));
        tap(&mut app, KeyCode::ArrowDown);
        tap(&mut app, KeyCode::Enter);
        assert_eq!(stage(&app), Stage::Menu, "a broken scenario was chosen");
        tap(&mut app, KeyCode::ArrowUp);
        tap(&mut app, KeyCode::Enter);
        until_briefing(&mut app);
        assert!(texts(&mut app).contains("Brief of Pancreas press."));
        assert_eq!(
            built.load(Ordering::SeqCst),
            1,
            "the same scene was built again"
        );
        std::fs::remove_dir_all(&folder).unwrap();
    }

    /// A scene that runs an organ's linear tissue while its nonlinear vademecum builds is
    /// loaded again on the briefing once that file is built, and only then, once; a file
    /// built during an exercise waits for the next briefing.
    #[test]
    fn a_briefing_takes_up_a_vademecum_built_in_the_background() {
        let Fixture {
            mut app,
            folder,
            built,
            meanwhile,
            finished,
            ..
        } = fixture("reload");
        let (liver, pancreas) = (folder.join("liver.vdm"), folder.join("pancreas.vdm"));
        *meanwhile.lock().unwrap() = vec![liver.clone()];
        app.update();
        tap(&mut app, KeyCode::ArrowDown);
        tap(&mut app, KeyCode::Enter);
        until_briefing(&mut app);
        assert_eq!(built.load(Ordering::SeqCst), 1);
        finished.lock().unwrap().push(folder.join("another.vdm"));
        for _ in 0..3 {
            app.update();
        }
        assert_eq!(stage(&app), Stage::Briefing, "reloaded for another file");

        meanwhile.lock().unwrap().clear();
        finished.lock().unwrap().push(liver.clone());
        app.update();
        app.update();
        assert_eq!(stage(&app), Stage::Loading);
        until_briefing(&mut app);
        assert_eq!(built.load(Ordering::SeqCst), 2, "not loaded again");
        let lesson = app.world().resource::<Lesson>();
        assert!(lesson.scene.meanwhile.is_empty());
        assert!(texts(&mut app).contains("Brief of Pancreas press."));
        for _ in 0..3 {
            app.update();
        }
        assert_eq!(built.load(Ordering::SeqCst), 2, "loaded once more");

        // Chosen again while the pancreas builds, begun, and built during the exercise.
        *meanwhile.lock().unwrap() = vec![pancreas.clone()];
        tap(&mut app, KeyCode::KeyM);
        tap(&mut app, KeyCode::ArrowUp);
        tap(&mut app, KeyCode::Enter);
        until_briefing(&mut app);
        assert_eq!(built.load(Ordering::SeqCst), 3);
        tap(&mut app, KeyCode::Space);
        assert_eq!(stage(&app), Stage::Exercise);
        finished.lock().unwrap().push(pancreas);
        for _ in 0..3 {
            app.update();
        }
        assert_eq!(stage(&app), Stage::Exercise);
        assert_eq!(
            built.load(Ordering::SeqCst),
            3,
            "loaded during the exercise"
        );
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
