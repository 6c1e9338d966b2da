//! `trainer --headless`: the default scene's haptic loop without a window, on a simulated
//! clock (deterministic) or on the real one, and its summary.

use std::path::PathBuf;
use std::time::Duration;

use serde::Serialize;

use super::haptic::{HapticLoop, HapticThread, HeadlessReport, RealTimeReport};
use super::scene::{default_scene, press_targets};
use crate::cli::OnStale;
use crate::haptics::{
    DeviceLimits, DeviceSpec, HapticDevice, PressMotion, Recorder, Scripted, TICK_S, TimerMode,
    Trajectory, press_and_slide,
};

pub struct Options {
    pub vademecums: PathBuf,
    pub on_stale: OnStale,
    pub device: Option<DeviceSpec>,
    pub record: Option<PathBuf>,
    pub ticks: Option<u64>,
    /// Tick on the real clock with this timer instead of a simulated one.
    pub realtime: Option<TimerMode>,
    pub max_force_n: f64,
}

/// What a headless run reports.
#[derive(Serialize)]
#[serde(untagged)]
pub enum Report {
    Simulated(HeadlessReport),
    RealTime(RealTimeReport),
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
            Report::RealTime(report) => println!(
                "real-time haptic loop ({:?}): {} ticks, {} deadlines skipped\n\
                 tick lateness: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs\n\
                 period error: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs\n\
                 tick compute: p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
                report.timer,
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
            ),
        }
    }
}

pub fn run(options: &Options) -> Result<Report, String> {
    let mut scene = default_scene(&options.vademecums, options.on_stale)?;
    scene.safety.max_force_n = options.max_force_n;
    let trajectory = match &options.device {
        None => press_and_slide(&press_targets(&scene), &PressMotion::default()),
        Some(DeviceSpec::Scripted(path)) => Trajectory::load(path).map_err(|e| e.to_string())?,
        Some(DeviceSpec::Virtual) => {
            return Err("the virtual device needs the window: drop --headless".into());
        }
    };
    let ticks = options
        .ticks
        .unwrap_or_else(|| ((trajectory.duration_s() + 0.1) / TICK_S).ceil() as u64);
    let device = scripted_device(&options.device, trajectory, &options.record);
    let mut haptic = HapticLoop::new(&scene, device).map_err(|e| e.to_string())?;
    Ok(match options.realtime {
        None => Report::Simulated(haptic.run_simulated(ticks)),
        Some(timer) => Report::RealTime(run_realtime(haptic, timer, ticks)?),
    })
}

fn scripted_device(
    spec: &Option<DeviceSpec>,
    trajectory: Trajectory,
    record: &Option<PathBuf>,
) -> Box<dyn HapticDevice> {
    let name = match spec {
        Some(DeviceSpec::Scripted(path)) => format!("scripted ({})", path.display()),
        _ => "scripted (built-in press and slide on each organ)".into(),
    };
    let device = Box::new(Scripted::new(name, trajectory).with_limits(DeviceLimits::default()));
    match record {
        Some(path) => Box::new(Recorder::new(device, path)),
        None => device,
    }
}

fn run_realtime(
    haptic: HapticLoop,
    timer: TimerMode,
    ticks: u64,
) -> Result<RealTimeReport, String> {
    let thread = HapticThread::spawn(haptic, timer).map_err(|e| e.to_string())?;
    std::thread::sleep(Duration::from_secs_f64(ticks as f64 * TICK_S));
    Ok(thread.stop())
}
