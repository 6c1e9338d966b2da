//! The trainer in a web page (wasm32): the window drawn into the page's canvas, the mouse
//! driving the tool, the menu offering every shipped scenario, each exercise scored with its
//! debrief. The page has no file system and no threads: a scenario's vademecums are fetched
//! from the site (`vademecums/`) before its scene is built, and the frames tick the haptic
//! loop at its fixed 1 ms step ([`FramePaced`]).

mod fetch;
mod page;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::attempt::{scenario_files, scenario_scene};
use super::haptic::{FramePaced, HapticLoop, HapticScene, SceneSwap};
use super::scene::{Detail, HandDevices};
use super::window::{self, Lesson, Lessons, MenuPlan, Opening, WindowScene};
use super::{DEFAULT_SCENARIO, SHIPPED_SCENARIOS};
use crate::devices::{HapticDevice, Scripted, Trajectory};
use crate::pgd::{container, web_form};
use crate::scenario::{self, Scenario};
use crate::store::OnStale;

/// Where the site keeps the vademecums (relative to the page).
const VADEMECUMS: &str = "vademecums";

/// Starts the trainer in the page; what goes wrong is shown there and logged as an error.
pub fn start() {
    wasm_bindgen_futures::spawn_local(async {
        if let Err(why) = run(page::Query::read()).await {
            page::fail(&why);
        }
    });
}

async fn run(query: page::Query) -> Result<(), String> {
    let (file, scenario) = opening_scenario(query.scenario.as_deref())?;
    let scene = fetched_scene(scenario.clone(), query.detail).await?;
    let devices = match &query.script {
        Some(url) => HandDevices {
            devices: vec![scripted(url).await?],
            mice: vec![None],
        },
        None => HandDevices::mouse(&scene),
    };
    page::status("ready");
    window::run(window_scene(scene, scenario, file, devices, query.detail)?);
    Ok(())
}

/// The shipped scenario `stem` names (the default one when none is named), parsed.
fn opening_scenario(stem: Option<&str>) -> Result<(PathBuf, Scenario), String> {
    let (file, text) = match stem {
        None => DEFAULT_SCENARIO,
        Some(stem) => *SHIPPED_SCENARIOS
            .iter()
            .find(|(file, _)| {
                Path::new(file).file_name() == Some(format!("{stem}.scenario.ron").as_ref())
            })
            .ok_or_else(|| format!("no shipped scenario is called {stem}"))?,
    };
    let scenario = scenario::parse(Path::new(file), text).map_err(|e| e.to_string())?;
    Ok((PathBuf::from(file), scenario))
}

/// The scene of `scenario`, its files fetched first (those already fetched are kept).
async fn fetched_scene(scenario: Scenario, detail: Detail) -> Result<HapticScene, String> {
    let dir = Path::new(VADEMECUMS);
    let scenario = scenario.for_the_web();
    for file in scenario_files(&scenario, dir, detail)? {
        if container::is_provided(&file) {
            continue;
        }
        page::status(&format!("{}: fetching {}", scenario.title, file.display()));
        if let Some(bytes) = fetched_file(&file).await? {
            container::provide(&file, bytes.into());
        }
    }
    page::status(&format!("{}: building its scene", scenario.title));
    scenario_scene(&scenario, dir, detail, OnStale::Refuse)
}

/// The file at `file` on the site: its web form expanded, or the file itself where the site
/// has no web form of it; `None` if it has neither.
async fn fetched_file(file: &Path) -> Result<Option<Vec<u8>>, String> {
    let url = file.to_string_lossy();
    match fetch::bytes(&format!("{url}.{}", web_form::EXTENSION)).await? {
        Some(web) => web_form::expand(file, &web)
            .map(Some)
            .map_err(|e| e.to_string()),
        None => fetch::bytes(&url).await,
    }
}

/// A scripted device replaying the trajectory CSV at `url`.
async fn scripted(url: &str) -> Result<Box<dyn HapticDevice>, String> {
    let text = fetch::text(url).await?;
    let trajectory =
        Trajectory::read(Path::new(url), text.as_bytes()).map_err(|e| e.to_string())?;
    Ok(Box::new(Scripted::new(
        format!("scripted ({url})"),
        trajectory,
    )))
}

/// The window over `scene`, on `scenario`'s lesson, its haptic loop ticked by the frames; the
/// menu builds the other scenarios' scenes from fetched files.
fn window_scene(
    scene: HapticScene,
    scenario: Scenario,
    file: PathBuf,
    HandDevices { devices, mice }: HandDevices,
    detail: Detail,
) -> Result<WindowScene, String> {
    let names: Vec<&str> = devices.iter().map(|d| d.name()).collect();
    let device_name = names.join(" + ");
    let mut haptic = HapticLoop::with_devices(&scene, devices).map_err(|e| e.to_string())?;
    let lesson = Lesson::prepare(&mut haptic, scenario, file, scene.clone());
    if mice.iter().all(Option::is_none) {
        lesson.link.start();
    }
    let snapshots = haptic.publish();
    let swap = SceneSwap::default();
    let menu = MenuPlan {
        folder: None,
        built_in: SHIPPED_SCENARIOS,
        scenes: Arc::new(move |scenario: &Scenario| {
            Box::pin(fetched_scene(scenario.clone(), detail))
        }),
        swap: swap.clone(),
        built: Arc::new(Vec::new),
        curriculum: None,
    };
    Ok(WindowScene {
        scene,
        snapshots,
        mice,
        device_name,
        exit_after_s: None,
        screenshot: None,
        lesson: Some((lesson, Opening::Lesson)),
        lessons: Lessons::default(),
        menu: Some(menu),
        free_camera: false,
        offscreen: None,
        paced: Some(FramePaced::new(haptic, swap)),
    })
}
