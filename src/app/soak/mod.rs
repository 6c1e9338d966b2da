//! An hour of use on the simulated clock: a scripted trainee goes through the shipped
//! scenarios in turn — presses, slides, palpations, grasps, cuts — each attempted carelessly
//! and then retried competently (their shipped runs), every attempt scored and kept in a
//! history, while the resident memory, the tick's compute time, the forces sent and their
//! steps are watched for what only long use shows: leaks, drift, a NaN, a jump.

mod memory;
mod watch;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use serde::Serialize;

use super::attempt::{Outcome, observe_attempt, scenario_scene};
use super::haptic::{HapticLoop, HapticScene, TickTimes};
use super::scene::Detail;
use super::shipped::SHIPPED_RUNS;
use crate::devices::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, Scripted, TICK_S, Trajectory,
    stop_requested,
};
use crate::history::{AttemptRecord, History, now_unix_s};
use crate::scenario::{self, Scenario};
use crate::store::OnStale;
use memory::resident_bytes;
pub use memory::{Growth, MemorySample};
pub use watch::StepPlace;
use watch::Watch;

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
    /// Only this shipped scenario (its file, as `scenarios/NAME.scenario.ron`), over and
    /// over: with one scene, the memory after each attempt varies only by what leaks.
    pub only: Option<String>,
    /// Leak each attempt's haptic world (a scene's worth of memory): a defect planted for the
    /// tests to show that the growth check fails on it.
    pub leak_each_attempt: bool,
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
    /// The resident memory every simulated minute, from the start (every scene built, no
    /// attempt made).
    pub memory: Vec<MemorySample>,
    /// Its growth per attempt after the first round, fitted to a sample after every attempt.
    pub growth: Growth,
    /// The simulated seconds at the start and at the end whose ticks the first and last
    /// figures are taken over (ten minutes, or a third of a shorter soak).
    pub window_s: f64,
    pub tick_p50_first_us: f64,
    pub tick_p99_first_us: f64,
    pub tick_p50_last_us: f64,
    pub tick_p99_last_us: f64,
    /// Ticks whose computed or sent force was not finite.
    pub nan_count: u64,
    /// The largest change (N) of the force the device was sent from one tick to the next, the
    /// device and its safety filter passing from each attempt to the next as between scenes.
    pub max_force_step_n: f64,
    /// The largest such change outside a fault's fade and a lowered limit's clamp, and where.
    pub largest_plain_step: StepPlace,
    /// Scene changes to a lower force limit whose first tick clamped the force.
    pub lowered_limit_steps: u64,
    /// Faults by kind over every attempt.
    pub faults: BTreeMap<&'static str, u64>,
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

/// The soak's one device: each attempt hands it the script to play, and it passes, with the
/// safety filter behind it, from each attempt's world to the next, as a device passes from
/// scene to scene in the window; so what it is sent is watched as one device receives it.
#[derive(Clone, Default)]
struct Hand(Arc<Mutex<Option<Scripted>>>);

impl Hand {
    fn play(&self, script: &Trajectory) {
        let scripted = Scripted::new("soak", script.clone());
        *self.0.lock().unwrap_or_else(PoisonError::into_inner) = Some(scripted);
    }
}

impl HapticDevice for Hand {
    fn name(&self) -> &str {
        "soak"
    }

    fn limits(&self) -> DeviceLimits {
        DeviceLimits::default()
    }

    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError> {
        let mut script = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        match script.as_mut() {
            Some(script) => script.read(time_s),
            None => Ok(DeviceSample::at(nalgebra::Vector3::zeros())),
        }
    }

    fn render(&mut self, _force: EdgeForce) -> Result<(), DeviceError> {
        Ok(())
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
    watch.memory.push(MemorySample {
        simulated_s: 0.0,
        attempts: 0,
        bytes: resident_bytes()?,
    });
    let hand = Hand::default();
    let mut previous: Option<HapticLoop> = None;
    let mut after_attempts = Vec::new();
    for (attempt, entry) in (0..).zip(scenarios.iter().cycle()) {
        if watch.left() == 0 || stop_requested() {
            break;
        }
        let script = match attempt / scenarios.len() % 2 {
            0 => &entry.careless,
            _ => &entry.competent,
        };
        hand.play(script);
        let haptic = next_world(&entry.scene, &hand, previous.take(), plan.leak_each_attempt)?;
        let (outcome, haptic) = attempt_once(entry, haptic, script, &mut watch)?;
        previous = Some(haptic);
        keep(&history, &outcome, entry.file, &plan.trainee)?;
        after_attempts.push(MemorySample {
            simulated_s: watch.ticks as f64 * TICK_S,
            attempts: watch.attempts,
            bytes: resident_bytes()?,
        });
        progress(
            watch.ticks as f64 * TICK_S,
            &entry.scenario.title,
            outcome.card.score,
        );
    }
    drop(previous);
    let rss_end_bytes = resident_bytes()?;
    let first_round = scenarios.len() as u64;
    let rss_start_bytes = (after_attempts.iter())
        .find(|s| s.attempts == first_round)
        .map_or(rss_end_bytes, |s| s.bytes);
    let (first, last) = (TickTimes::of(&watch.first), TickTimes::of(&watch.last));
    Ok(SoakReport {
        duration_s: plan.duration_s,
        ticks: watch.ticks,
        rss_start_bytes,
        rss_end_bytes,
        rss_growth: rss_end_bytes as f64 / rss_start_bytes as f64 - 1.0,
        growth: Growth::of(&after_attempts, first_round),
        memory: watch.memory,
        window_s: window_ticks as f64 * TICK_S,
        tick_p50_first_us: first.p50_us,
        tick_p99_first_us: first.p99_us,
        tick_p50_last_us: last.p50_us,
        tick_p99_last_us: last.p99_us,
        nan_count: watch.nan_count,
        max_force_step_n: watch.max_force_step_n,
        largest_plain_step: watch.largest_plain_step,
        lowered_limit_steps: watch.lowered_limit_steps,
        faults: watch.faults,
        attempts_scored: watch.attempts,
        attempts_kept: kept_count(&history, &plan.trainee)? - kept_before,
        scenarios: scenarios.iter().map(|s| s.file.to_owned()).collect(),
    })
}

/// The world of `scene`, with the hand and its filter taken from the `previous` attempt's
/// world (the first: a new filter on the hand), which is then dropped, or leaked when the
/// plan plants that defect.
fn next_world(
    scene: &HapticScene,
    hand: &Hand,
    previous: Option<HapticLoop>,
    leak: bool,
) -> Result<HapticLoop, String> {
    let Some(mut previous) = previous else {
        return HapticLoop::new(scene, Box::new(hand.clone())).map_err(|e| e.to_string());
    };
    let mut haptic = HapticLoop::parked(scene).map_err(|e| e.to_string())?;
    haptic.take_devices(&mut previous);
    if leak {
        std::mem::forget(previous);
    }
    Ok(haptic)
}

/// Keeps `outcome` in `history`.
fn keep(history: &History, outcome: &Outcome, file: &str, trainee: &str) -> Result<(), String> {
    let record = AttemptRecord::of(&outcome.card, Path::new(file), trainee, None, now_unix_s());
    history.record(&record).map(drop).map_err(|e| e.to_string())
}

/// One attempt at `entry` with `script` in `haptic`, cut short where the soak's time runs
/// out; the world is handed back for the next attempt to take its device.
fn attempt_once(
    entry: &SoakScenario,
    haptic: HapticLoop,
    script: &Trajectory,
    watch: &mut Watch,
) -> Result<(Outcome, HapticLoop), String> {
    let ticks = (((script.duration_s() + 0.1) / TICK_S).ceil() as u64).min(watch.left());
    watch.begin(entry.file);
    let (outcome, haptic) = observe_attempt(
        entry.scenario.clone(),
        &entry.scene,
        haptic,
        ticks,
        |haptic, compute| watch.record(haptic, compute),
    )?;
    watch.end(&haptic);
    Ok((outcome, haptic))
}

/// Every shipped one-hand scenario with a shipped run, its scene built once (its
/// vademecums built where missing).
fn soak_scenarios(plan: &SoakPlan) -> Result<Vec<SoakScenario>, String> {
    let runs: Vec<_> = (SHIPPED_RUNS.iter())
        .filter(|run| plan.only.as_deref().is_none_or(|only| run.file == only))
        .collect();
    if runs.is_empty() {
        let shipped: Vec<&str> = SHIPPED_RUNS.iter().map(|run| run.file).collect();
        return Err(format!(
            "--scenario {}: not a shipped scenario with scripted runs; one of: {}",
            plan.only.as_deref().unwrap_or(""),
            shipped.join(", ")
        ));
    }
    let script = |name: &str, text: &str| {
        Trajectory::read(Path::new(name), text.as_bytes()).map_err(|e| e.to_string())
    };
    let mut soaked = Vec::with_capacity(runs.len());
    for run in runs {
        let scenario =
            scenario::parse(Path::new(run.file), run.scenario).map_err(|e| e.to_string())?;
        // The soak's one device is one hand: the bimanual exercises are left out.
        if scenario.bimanual() {
            continue;
        }
        let scene = scenario_scene(&scenario, &plan.vademecums, plan.detail, OnStale::Rebuild)?;
        soaked.push(SoakScenario {
            file: run.file,
            careless: script(run.careless_file, run.careless)?,
            competent: script(run.competent_file, run.competent)?,
            scenario,
            scene,
        });
    }
    match soaked.is_empty() {
        true => Err("the soak plays one-hand scenarios, and this one is bimanual".into()),
        false => Ok(soaked),
    }
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
            "  memory growth     {:+.0} kB an attempt after the first round ({:+.0} kB over the \
             second half of those {} attempts)",
            self.growth.per_attempt_bytes / 1e3,
            self.growth.late_per_attempt_bytes / 1e3,
            self.growth.attempts
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
            "  forces            {} not finite; largest step between ticks {:.3} N; outside \
             faults and lowered limits {:.3} N ({}, tick {}); {} lowered-limit clamps",
            self.nan_count,
            self.max_force_step_n,
            self.largest_plain_step.step_n,
            self.largest_plain_step.scenario,
            self.largest_plain_step.tick,
            self.lowered_limit_steps
        )?;
        writeln!(f, "  faults            {:?}", self.faults)?;
        writeln!(
            f,
            "  attempts          {} scored, {} kept in the history",
            self.attempts_scored, self.attempts_kept
        )
    }
}
