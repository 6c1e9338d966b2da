//! A run of the trainer: the default scene, the device the options name, and the haptic loop —
//! headless on a simulated clock (deterministic) or the real one, or behind the window — and
//! what it reports.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::Serialize;

use bevy::app::AppExit;

use super::attempt::{Outcome, outcome_of, run_simulated, scenario_scene};
use super::haptic::ExerciseRun;
use super::haptic::{
    HapticLoop, HapticScene, HapticThread, HeadlessReport, RealTimeReport, Scheduling,
};
use super::scene::{Detail, HandDevices, default_scene, press_targets};
use super::window::{
    FrameReport, Lesson, Lessons, MenuPlan, Opening, SceneSource, ScreenshotPlan, WindowScene,
};
use crate::devices::{
    DeviceSpec, ForceDimension, Haply, HapticDevice, OpenHaptics, PressMotion, Recorder, Scripted,
    TICK_S, TimerMode, Trajectory, press_and_slide, stop_requested,
};
use crate::scenario::Scenario;
use crate::store::OnStale;

#[derive(Clone)]
pub struct Options {
    pub vademecums: PathBuf,
    pub detail: Detail,
    pub on_stale: OnStale,
    pub device: Option<DeviceSpec>,
    /// A bimanual scenario's left-hand device (the right's is `device`).
    pub left_device: Option<DeviceSpec>,
    pub record: Option<PathBuf>,
    pub ticks: Option<u64>,
    /// Headless: tick on the real clock with this timer instead of a simulated one. The
    /// window always ticks on the real clock, with this timer or the default.
    pub realtime: Option<TimerMode>,
    pub max_force_n: f64,
    /// The window opens a laparoscopic scenario with the free camera, not the laparoscope.
    pub free_camera: bool,
    /// Render into an image of this size (pixels) instead of a window.
    pub offscreen: Option<(u32, u32)>,
    /// The menu offers this curriculum's exercises in its order, the locked ones refused.
    pub curriculum: Option<super::window::MenuCurriculum>,
}

/// What a headless run reports.
#[derive(Serialize)]
#[serde(untagged)]
pub enum Report {
    Simulated(HeadlessReport),
    RealTime(RealTimeReport),
    Window {
        haptic: RealTimeReport,
        frames: Option<FrameReport>,
    },
}

impl Report {
    pub fn print(&self, json: bool) {
        if json {
            match serde_json::to_string_pretty(self) {
                Ok(text) => println!("{text}"),
                Err(e) => eprintln!("trainer: could not write the JSON summary: {e}"),
            }
            return;
        }
        match self {
            Report::Simulated(report) => println!("{report}"),
            Report::RealTime(report) => print_realtime(report),
            Report::Window { haptic, frames } => {
                print_realtime(haptic);
                match frames {
                    Some(f) => println!(
                        "window: {} frames after warm-up, frame time p50 {:.1} ms ({:.1} fps), p95 {:.1} ms, p99 {:.1} ms",
                        f.frames, f.frame_ms_p50, f.fps_p50, f.frame_ms_p95, f.frame_ms_p99
                    ),
                    None => println!("window: closed before drawing past its warm-up"),
                }
            }
        }
    }
}

fn print_realtime(report: &RealTimeReport) {
    println!(
        "real-time haptic loop ({:?}, {} scheduling): {} ticks, {} deadlines skipped\n\
                 tick lateness: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs\n\
                 period error: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs\n\
                 tick compute: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        report.timer,
        report.scheduling,
        report.ticks,
        report.skipped,
        report.lateness.p50_us,
        report.lateness.p99_us,
        report.lateness.max_us,
        report.period_error.p50_us,
        report.period_error.p99_us,
        report.period_error.max_us,
        report.compute.p50_us,
        report.compute.p99_us,
        report.compute.max_us,
    );
}

/// Runs the haptic loop without a window: on a simulated clock unless `options.realtime`.
pub fn run_headless(options: &Options) -> Result<Report, String> {
    if let Some(device) = open_hardware(&options.device) {
        return run_hardware_headless(options, device?);
    }
    let script = match &options.device {
        Some(DeviceSpec::Scripted(path)) => {
            Some(Trajectory::load(path).map_err(|e| e.to_string())?)
        }
        Some(DeviceSpec::Virtual) => {
            return Err("the virtual device needs the window: drop --headless".into());
        }
        // Hardware is served above; no device: the built-in press and slide.
        _ => None,
    };
    let scene = scene(options)?;
    let trajectory = script.unwrap_or_else(|| {
        let motion = PressMotion {
            tip_radius_m: scene.probe.tip_radius_m,
            ..PressMotion::default()
        };
        press_and_slide(&press_targets(&scene), &motion)
    });
    let ticks = ticks_for(options, &trajectory);
    let device = recorded(scripted(&options.device, trajectory), &options.record);
    let mut haptic = HapticLoop::new(&scene, device).map_err(|e| e.to_string())?;
    Ok(match options.realtime {
        None => Report::Simulated(haptic.run_simulated(ticks)),
        Some(timer) => Report::RealTime(run_realtime(haptic, timer, ticks)?),
    })
}

/// Serves a hardware device without a window, on the real clock, for `--ticks` (ten seconds
/// when it does not say). The device is opened first: a missing one is said before the scene
/// is loaded.
fn run_hardware_headless(
    options: &Options,
    device: Box<dyn HapticDevice>,
) -> Result<Report, String> {
    let timer = options
        .realtime
        .ok_or("a hardware device runs on the real clock: add --realtime (and --ticks)")?;
    let device = recorded(device, &options.record);
    let scene = scene(options)?;
    let haptic = HapticLoop::new(&scene, device).map_err(|e| e.to_string())?;
    let ticks = options.ticks.unwrap_or(HARDWARE_TICKS);
    Ok(Report::RealTime(run_realtime(haptic, timer, ticks)?))
}

/// A scenario for the window: the lesson it opens with, and the scenarios its menu offers.
pub struct WindowLesson {
    pub scenario: Scenario,
    /// The file it was read from (the built-in one's shipped name): its reports are named
    /// after it.
    pub file: PathBuf,
    pub opening: Opening,
    /// The folder whose scenarios the menu offers, watched for edits.
    pub folder: Option<PathBuf>,
}

/// Each attempt at an exercise begun in the window, in order, with its scenario's file.
pub type Attempts = Vec<(PathBuf, Outcome)>;

/// Opens the trainer window over the real-time haptic loop, driven by the mouse unless a
/// scripted device is named; reports how the loop kept time while the renderer ran, and each
/// attempt at an exercise that was begun, in order. The scenarios folder is watched: an edit
/// of the lesson's file reloads it (see the window's `reload`).
pub fn open_window(
    options: &Options,
    exit_after_s: Option<f64>,
    screenshot: Option<ScreenshotPlan>,
    lesson: Option<WindowLesson>,
) -> Result<(Report, Attempts), String> {
    // `--device` and `--left-device` first, else the devices the opening scenario is meant for.
    let scenario = lesson.as_ref().map(|lesson| &lesson.scenario.device);
    let spec = (options.device.clone()).or_else(|| scenario?.spec());
    let left_spec = (options.left_device.clone()).or_else(|| scenario?.left_spec());
    let scene = match &lesson {
        Some(lesson) => scenario_scene_capped(options, &lesson.scenario)?,
        None => scene(options)?,
    };
    let HandDevices { devices, mice } = window_devices([&spec, &left_spec], &scene)?;
    let devices = recorded_hands(devices, &options.record);
    let names: Vec<&str> = devices.iter().map(|d| d.name()).collect();
    let device_name = names.join(" + ");
    let mut haptic = HapticLoop::with_devices(&scene, devices).map_err(|e| e.to_string())?;
    let (lesson, folder) = match lesson {
        Some(WindowLesson {
            scenario,
            file,
            opening,
            folder,
        }) => {
            let lesson = Lesson::prepare(&mut haptic, scenario, file, scene.clone());
            if let Some(DeviceSpec::Scripted(_)) = &spec {
                lesson.link.start();
            }
            (Some((lesson, opening)), folder)
        }
        None => (None, None),
    };
    let snapshots = haptic.publish();
    let timer = options.realtime.unwrap_or_default();
    let haptic =
        HapticThread::spawn(haptic, timer, Scheduling::RealTime).map_err(|e| e.to_string())?;
    let menu = lesson.is_some().then(|| MenuPlan {
        folder,
        built_in: super::SHIPPED_SCENARIOS,
        scenes: scene_source(options),
        swap: haptic.swap(),
        built: Arc::new(|| crate::store::background_status().built),
        curriculum: options.curriculum.clone(),
    });
    let lessons = Lessons::default();
    let (exit, frames) = super::window::run(WindowScene {
        scene,
        snapshots,
        mice,
        device_name,
        exit_after_s,
        screenshot,
        lesson,
        lessons: lessons.clone(),
        menu,
        free_camera: options.free_camera,
        offscreen: options.offscreen,
        paced: None,
    });
    let (report, mut haptic) = haptic.stop();
    let attempts = attempts(&lessons, &mut haptic);
    match exit {
        // A signal closes the window through Bevy's Ctrl-C exit, which carries an error code:
        // it was closed as its close button would, and its attempts are kept.
        AppExit::Error(code) if !crate::devices::stop_requested() => {
            Err(format!("the window closed with error code {code}"))
        }
        _ => Ok((
            Report::Window {
                haptic: report,
                frames,
            },
            attempts,
        )),
    }
}

/// Each hand's device in the window: a bimanual script serves both hands; otherwise the
/// hardware or scripted device `specs` asks for the hand (the right's first), else the mouse.
fn window_devices(
    specs: [&Option<DeviceSpec>; 2],
    scene: &HapticScene,
) -> Result<HandDevices, String> {
    let hands = scene.hands.len();
    if let Some(DeviceSpec::Scripted(path)) = specs[0] {
        let scripts = Trajectory::load_hands(path).map_err(|e| e.to_string())?;
        if scripts.len() > 1 || hands == 1 {
            if scripts.len() != hands {
                return Err(format!(
                    "{}: {} hand(s) in the file, and the scene has {hands}",
                    path.display(),
                    scripts.len()
                ));
            }
            return Ok(HandDevices {
                devices: scripts.into_iter().map(|t| scripted(specs[0], t)).collect(),
                mice: vec![None; hands],
            });
        }
    }
    let mut devices = HandDevices::mouse(scene);
    for (hand, spec) in specs.into_iter().enumerate().take(hands) {
        let device = match (open_hardware(spec), spec) {
            (Some(device), _) => device?,
            (None, Some(DeviceSpec::Scripted(path))) => {
                scripted(spec, Trajectory::load(path).map_err(|e| e.to_string())?)
            }
            (None, _) => continue,
        };
        devices.devices[hand] = device;
        devices.mice[hand] = None;
    }
    Ok(devices)
}

/// How the window's menu builds the scene of the scenario chosen.
fn scene_source(options: &Options) -> SceneSource {
    let options = options.clone();
    Arc::new(move |scenario: &Scenario| {
        let (options, scenario) = (options.clone(), scenario.clone());
        Box::pin(async move { scenario_scene_capped(&options, &scenario) })
    })
}

/// Every attempt begun under the window's lessons, in order, scored: the ended ones from each
/// lesson's link, and the one under way in `haptic` (the current lesson's).
fn attempts(lessons: &Lessons, haptic: &mut HapticLoop) -> Attempts {
    let running = haptic
        .world()
        .get_resource::<ExerciseRun>()
        .map(|run| run.link.clone());
    let mut attempts = Attempts::new();
    for (file, link) in lessons.take() {
        let mut ended = link.take_earlier();
        if running.as_ref().is_some_and(|r| Arc::ptr_eq(r, &link)) {
            // An attempt never begun (the window closed on the briefing) has nothing to score.
            if link.started() {
                let run = haptic.world_mut().remove_resource::<ExerciseRun>();
                ended.extend(run.and_then(ExerciseRun::into_exercise));
            }
        } else {
            ended.extend(link.take_ended());
        }
        attempts.extend(ended.into_iter().map(|e| (file.clone(), outcome_of(e))));
    }
    attempts
}

/// Runs a scenario's exercise on the scripted device `options` names, on a simulated clock,
/// until its tasks have ended or the script has (plus 100 ms).
/// A bimanual scenario's script carries both hands (a bimanual trajectory file).
pub fn run_scenario_headless(options: &Options, scenario: Scenario) -> Result<Outcome, String> {
    let scene = scenario_scene_capped(options, &scenario)?;
    let Some(DeviceSpec::Scripted(path)) = &options.device else {
        return Err("a headless exercise needs a scripted device: --device scripted:FILE".into());
    };
    let hands = Trajectory::load_hands(path).map_err(|e| e.to_string())?;
    if hands.len() != scene.hands.len() {
        return Err(format!(
            "{}: {} hand(s) in the file, and the scenario is for {} (a bimanual file has the \
             left hand's columns, `left_x_m`…: docs/devices.md)",
            path.display(),
            hands.len(),
            scene.hands.len()
        ));
    }
    let ticks = ticks_for(options, &hands[0]);
    let devices = hands
        .into_iter()
        .map(|t| scripted(&options.device, t))
        .collect();
    run_simulated(
        scenario,
        &scene,
        recorded_hands(devices, &options.record),
        ticks,
    )
}

/// The ticks `--ticks` asks for, or the script's length plus 100 ms.
fn ticks_for(options: &Options, trajectory: &Trajectory) -> u64 {
    options
        .ticks
        .unwrap_or_else(|| ((trajectory.duration_s() + 0.1) / TICK_S).ceil() as u64)
}

/// The scenario's scene, its force limit capped by the command line's.
fn scenario_scene_capped(options: &Options, scenario: &Scenario) -> Result<HapticScene, String> {
    let mut scene = scenario_scene(
        scenario,
        &options.vademecums,
        options.detail,
        options.on_stale,
    )?;
    scene.safety.max_force_n = scene.safety.max_force_n.min(options.max_force_n);
    Ok(scene)
}

fn scene(options: &Options) -> Result<HapticScene, String> {
    let mut scene = default_scene(&options.vademecums, options.detail, options.on_stale)?;
    scene.safety.max_force_n = options.max_force_n;
    Ok(scene)
}

fn scripted(spec: &Option<DeviceSpec>, trajectory: Trajectory) -> Box<dyn HapticDevice> {
    let name = match spec {
        Some(DeviceSpec::Scripted(path)) => format!("scripted ({})", path.display()),
        _ => "scripted (built-in press and slide on each organ)".into(),
    };
    Box::new(Scripted::new(name, trajectory))
}

/// Headless ticks on a hardware device when `--ticks` does not say: ten seconds.
const HARDWARE_TICKS: u64 = 10_000;

/// Installs the panic hook and the SIGINT/SIGTERM handler that release every open device at
/// zero force ([`crate::devices::install_exit_guards`]); a signal closes the window as its
/// close button would.
pub fn install_exit_guards() -> Result<(), String> {
    crate::devices::install_exit_guards(bevy::app::TerminalCtrlCHandlerPlugin::gracefully_exit)
}

/// The hardware device `spec` names, opened (`None` when it names none): a Geomagic device
/// through OpenHaptics, a Force Dimension one through its SDK, or a Haply Inverse3 through its
/// service.
fn open_hardware(spec: &Option<DeviceSpec>) -> Option<Result<Box<dyn HapticDevice>, String>> {
    let opened = match spec {
        Some(DeviceSpec::OpenHaptics(name)) => {
            OpenHaptics::open(None, name.as_deref()).map(|d| Box::new(d) as Box<dyn HapticDevice>)
        }
        Some(DeviceSpec::ForceDimension(index)) => {
            ForceDimension::open(None, *index).map(|d| Box::new(d) as Box<dyn HapticDevice>)
        }
        Some(DeviceSpec::Haply { url, device_id }) => {
            Haply::open(url.as_deref(), device_id.as_deref())
                .map(|d| Box::new(d) as Box<dyn HapticDevice>)
        }
        _ => return None,
    };
    Some(opened.map_err(|e| e.to_string()))
}

fn recorded(device: Box<dyn HapticDevice>, record: &Option<PathBuf>) -> Box<dyn HapticDevice> {
    recorded_hands(vec![device], record).remove(0)
}

/// The hands' devices, recorded to one file if `record` names one.
fn recorded_hands(
    devices: Vec<Box<dyn HapticDevice>>,
    record: &Option<PathBuf>,
) -> Vec<Box<dyn HapticDevice>> {
    match record {
        Some(path) => (Recorder::hands(devices, path).into_iter())
            .map(|r| Box::new(r) as Box<dyn HapticDevice>)
            .collect(),
        None => devices,
    }
}

fn run_realtime(
    haptic: HapticLoop,
    timer: TimerMode,
    ticks: u64,
) -> Result<RealTimeReport, String> {
    let thread =
        HapticThread::spawn(haptic, timer, Scheduling::RealTime).map_err(|e| e.to_string())?;
    let until = Instant::now() + Duration::from_secs_f64(ticks as f64 * TICK_S);
    while Instant::now() < until && !stop_requested() {
        std::thread::sleep(Duration::from_millis(20).min(until - Instant::now()));
    }
    Ok(thread.stop().0)
}
