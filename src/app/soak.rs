//! An hour of use on the simulated clock: a scripted trainee goes through the shipped
//! scenarios in turn — presses, slides, palpations, grasps, cuts — each attempted carelessly
//! and then retried competently (their shipped runs), every attempt scored and kept in a
//! history, while the resident memory, the tick's compute time, the forces sent and their
//! steps are watched for what only long use shows: leaks, drift, a NaN, a jump.

use std::path::{Path, PathBuf};
use std::time::Duration;

use nalgebra::Vector3;
use serde::Serialize;

use super::attempt::{Outcome, run_observed, scenario_scene};
use super::haptic::{DeviceForce, HapticLoop, HapticScene, TickTimes};
use super::scene::Detail;
use super::shipped::SHIPPED_RUNS;
use crate::devices::{Histogram, Scripted, TICK_S, Trajectory, stop_requested};
use crate::history::{AttemptRecord, History, now_unix_s};
use crate::scenario::{self, Scenario};
use crate::store::OnStale;

/// What a soak runs.
pub struct SoakPlan {
    /// Simulated seconds of use (the sum of the attempts' ticks).
    pub duration_s: f64,
    pub vademecums: PathBuf,
    pub detail: Detail,
    /// The history database the attempts are kept in (created if missing).
    pub history: PathBuf,
    /// Whom the attempts are kept under.
    pub trainee: String,
}

/// What a soak measured.
#[derive(Clone, Debug, Serialize)]
pub struct SoakReport {
    pub duration_s: f64,
    pub ticks: u64,
    /// Resident memory (bytes) once every scenario had been run once (its scene loaded, its
    /// first attempt scored), and at the end.
    pub rss_start_bytes: u64,
    pub rss_end_bytes: u64,
    /// `rss_end_bytes` over `rss_start_bytes`, minus one.
    pub rss_growth: f64,
    /// The simulated seconds at the start and at the end whose ticks the first and last
    /// figures are taken over (ten minutes, or a third of a shorter soak).
    pub window_s: f64,
    pub tick_p50_first_us: f64,
    pub tick_p99_first_us: f64,
    pub tick_p50_last_us: f64,
    pub tick_p99_last_us: f64,
    /// Ticks whose computed or sent force was not finite.
    pub nan_count: u64,
    /// The largest change (N) of the force sent from one tick to the next.
    pub max_force_step_n: f64,
    pub attempts_scored: u64,
    /// Attempts the history took (its count of the trainee's attempts grew by this much).
    pub attempts_kept: u64,
    /// Scenarios gone through, in turn.
    pub scenarios: Vec<String>,
}

/// One shipped scenario with its scene and its two scripted runs.
struct SoakScenario {
    file: &'static str,
    scenario: Scenario,
    scene: HapticScene,
    careless: Trajectory,
    competent: Trajectory,
}

/// What the ticks of a soak have shown so far.
struct Watch {
    ticks: u64,
    window_ticks: u64,
    total_ticks: u64,
    first: Histogram,
    last: Histogram,
    nan_count: u64,
    last_sent_n: Vector3<f64>,
    max_force_step_n: f64,
}

impl Watch {
    fn new(total_ticks: u64, window_ticks: u64) -> Self {
        Self {
            ticks: 0,
            window_ticks,
            total_ticks,
            first: Histogram::default(),
            last: Histogram::default(),
            nan_count: 0,
            last_sent_n: Vector3::zeros(),
            max_force_step_n: 0.0,
        }
    }

    fn left(&self) -> u64 {
        self.total_ticks.saturating_sub(self.ticks)
    }

    /// One tick's compute time and forces.
    fn record(&mut self, haptic: &HapticLoop, compute: Duration) {
        if self.ticks < self.window_ticks {
            self.first.record(compute);
        }
        if self.ticks >= self.total_ticks.saturating_sub(self.window_ticks) {
            self.last.record(compute);
        }
        let force = haptic.world().resource::<DeviceForce>();
        let finite = |f: &Vector3<f64>| f.iter().all(|c| c.is_finite());
        if !finite(&force.desired_n) || !finite(&force.sent_n) {
            self.nan_count += 1;
        } else {
            let step = (force.sent_n - self.last_sent_n).norm();
            self.max_force_step_n = self.max_force_step_n.max(step);
            self.last_sent_n = force.sent_n;
        }
        self.ticks += 1;
    }
}

/// Runs the soak `plan` describes; `progress` hears each attempt's end (simulated seconds so
/// far, the scenario, its score).
pub fn soak(
    plan: &SoakPlan,
    mut progress: impl FnMut(f64, &str, f64),
) -> Result<SoakReport, String> {
    if !(plan.duration_s.is_finite() && plan.duration_s > 0.0) {
        return Err(format!(
            "--duration-s: {} is not a duration: simulated seconds, more than 0",
            plan.duration_s
        ));
    }
    let scenarios = soak_scenarios(plan)?;
    let history = History::open(&plan.history).map_err(|e| e.to_string())?;
    let kept_before = kept_count(&history, &plan.trainee)?;
    let total_ticks = (plan.duration_s / TICK_S).round() as u64;
    let window_ticks = (total_ticks / 3).min((600.0 / TICK_S) as u64);
    let mut watch = Watch::new(total_ticks, window_ticks);
    let (mut scored, mut rss_start) = (0u64, None);
    for (attempt, entry) in (0..).zip(scenarios.iter().cycle()) {
        if watch.left() == 0 || stop_requested() {
            break;
        }
        let script = match attempt / scenarios.len() % 2 {
            0 => &entry.careless,
            _ => &entry.competent,
        };
        let outcome = attempt_once(entry, script, &mut watch)?;
        scored += 1;
        let record = AttemptRecord::of(
            &outcome.card,
            Path::new(entry.file),
            &plan.trainee,
            None,
            now_unix_s(),
        );
        history.record(&record).map_err(|e| e.to_string())?;
        progress(
            watch.ticks as f64 * TICK_S,
            &entry.scenario.title,
            outcome.card.score,
        );
        if attempt + 1 == scenarios.len() {
            rss_start = Some(resident_bytes()?);
        }
    }
    let rss_end_bytes = resident_bytes()?;
    let rss_start_bytes = rss_start.unwrap_or(rss_end_bytes);
    let (first, last) = (TickTimes::of(&watch.first), TickTimes::of(&watch.last));
    Ok(SoakReport {
        duration_s: plan.duration_s,
        ticks: watch.ticks,
        rss_start_bytes,
        rss_end_bytes,
        rss_growth: rss_end_bytes as f64 / rss_start_bytes as f64 - 1.0,
        window_s: window_ticks as f64 * TICK_S,
        tick_p50_first_us: first.p50_us,
        tick_p99_first_us: first.p99_us,
        tick_p50_last_us: last.p50_us,
        tick_p99_last_us: last.p99_us,
        nan_count: watch.nan_count,
        max_force_step_n: watch.max_force_step_n,
        attempts_scored: scored,
        attempts_kept: kept_count(&history, &plan.trainee)? - kept_before,
        scenarios: scenarios.iter().map(|s| s.file.to_owned()).collect(),
    })
}

/// One attempt at `entry` with `script`, cut short where the soak's time runs out.
fn attempt_once(
    entry: &SoakScenario,
    script: &Trajectory,
    watch: &mut Watch,
) -> Result<Outcome, String> {
    let ticks = (((script.duration_s() + 0.1) / TICK_S).ceil() as u64).min(watch.left());
    let device = Box::new(Scripted::new("soak", script.clone()));
    run_observed(
        entry.scenario.clone(),
        &entry.scene,
        device,
        ticks,
        |haptic, compute| watch.record(haptic, compute),
    )
}

/// Every shipped scenario with a shipped run, its scene built once (its vademecums built
/// where missing).
fn soak_scenarios(plan: &SoakPlan) -> Result<Vec<SoakScenario>, String> {
    SHIPPED_RUNS
        .iter()
        .map(|run| {
            let scenario =
                scenario::parse(Path::new(run.file), run.scenario).map_err(|e| e.to_string())?;
            let scene = scenario_scene(&scenario, &plan.vademecums, plan.detail, OnStale::Rebuild)?;
            let script = |name: &str, text: &str| {
                Trajectory::read(Path::new(name), text.as_bytes()).map_err(|e| e.to_string())
            };
            Ok(SoakScenario {
                file: run.file,
                careless: script(run.careless_file, run.careless)?,
                competent: script(run.competent_file, run.competent)?,
                scenario,
                scene,
            })
        })
        .collect()
}

/// How many attempts the history holds for `trainee`.
fn kept_count(history: &History, trainee: &str) -> Result<u64, String> {
    let filter = crate::history::HistoryFilter {
        trainee: Some(trainee.to_owned()),
        scenario: None,
    };
    let attempts = history.attempts(&filter).map_err(|e| e.to_string())?;
    Ok(attempts.len() as u64)
}

/// This process's resident memory (bytes), from `/proc/self/status`, once the allocator has
/// handed its free pages back to the system: what is live, not what the allocator keeps
/// cached for threads that have ended (each attempt's cut worker gets an arena of its own).
fn resident_bytes() -> Result<u64, String> {
    release_free_memory();
    let status = std::fs::read_to_string("/proc/self/status")
        .map_err(|e| format!("cannot read /proc/self/status for the resident memory: {e}"))?;
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmRSS:"))
        .and_then(|kb| kb.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .ok_or_else(|| "no VmRSS line in /proc/self/status".into())
}

impl std::fmt::Display for SoakReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
        writeln!(
            f,
            "soak: {:.0} simulated s ({} ticks) over {} scenarios",
            self.duration_s,
            self.ticks,
            self.scenarios.len()
        )?;
        writeln!(
            f,
            "  resident memory   {:.1} MiB after the first round, {:.1} MiB at the end ({:+.2} %)",
            mib(self.rss_start_bytes),
            mib(self.rss_end_bytes),
            self.rss_growth * 100.0
        )?;
        writeln!(
            f,
            "  tick p50 / p99    first {:.0} s: {:.0} / {:.0} µs; last {:.0} s: {:.0} / {:.0} µs",
            self.window_s,
            self.tick_p50_first_us,
            self.tick_p99_first_us,
            self.window_s,
            self.tick_p50_last_us,
            self.tick_p99_last_us
        )?;
        writeln!(
            f,
            "  forces            {} not finite; largest step between ticks {:.3} N",
            self.nan_count, self.max_force_step_n
        )?;
        writeln!(
            f,
            "  attempts          {} scored, {} kept in the history",
            self.attempts_scored, self.attempts_kept
        )
    }
}

/// Hands the allocator's free pages, in every arena, back to the system (glibc's `malloc_trim`).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn release_free_memory() {
    unsafe extern "C" {
        fn malloc_trim(pad: usize) -> std::ffi::c_int;
    }
    // SAFETY: `malloc_trim` takes a byte count and only returns free memory to the system.
    unsafe { malloc_trim(0) };
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn release_free_memory() {}
