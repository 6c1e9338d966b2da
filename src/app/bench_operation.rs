//! The operation's benchmark (`pgd bench operation`): a scenario played by its scripted run
//! through the haptic loop on the simulated clock, every tick's compute timed, against a
//! baseline scenario's run timed the same way in the same process. The whole cholecystectomy
//! (three instruments, the biliary tree, the bed) against the liver press is the figure its
//! docs give.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::attempt::{run_observed, scenario_scene};
use super::bench_scalpel::{TickFigures, median_figures};
use super::scene::Detail;
use crate::devices::{HapticDevice, Histogram, Scripted, TICK_S, Trajectory};
use crate::scenario::load;
use crate::store::OnStale;

/// A scenario file and the scripted run that plays it.
pub struct ScenarioRun {
    pub scenario: PathBuf,
    pub run: PathBuf,
}

/// One scenario's figures: its ticks and their compute quantiles (medians over the repeats),
/// and the score its run made (the same every repeat: the run is deterministic enough to
/// say whether the scene did what the run expects).
#[derive(Clone, Debug, Serialize)]
pub struct RunFigures {
    pub scenario: String,
    pub ticks: u64,
    pub tick: TickFigures,
    pub score: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct OperationBenchReport {
    /// Whether the organs were the coarse ones.
    pub coarse: bool,
    pub repeats: usize,
    pub operation: RunFigures,
    pub baseline: RunFigures,
    /// The operation's tick p99 over the baseline's.
    pub p99_ratio: f64,
}

/// Times `operation` and `baseline`, one after the other `repeats` times, their vademecums
/// from `dir` at `detail` (built first when missing).
pub fn run(
    operation: &ScenarioRun,
    baseline: &ScenarioRun,
    dir: &Path,
    detail: Detail,
    repeats: usize,
) -> Result<OperationBenchReport, String> {
    let mut runs: [Vec<(TickFigures, u64, f64)>; 2] = [Vec::new(), Vec::new()];
    for _ in 0..repeats.max(1) {
        for (k, scenario) in [operation, baseline].into_iter().enumerate() {
            runs[k].push(timed(scenario, dir, detail)?);
        }
    }
    let figures = |k: usize, scenario: &ScenarioRun| {
        let ticks: Vec<TickFigures> = runs[k].iter().map(|r| r.0.clone()).collect();
        let (_, last_ticks, last_score) = runs[k][runs[k].len() - 1];
        RunFigures {
            scenario: scenario.scenario.display().to_string(),
            ticks: last_ticks,
            tick: median_figures(&ticks),
            score: last_score,
        }
    };
    let (operation, baseline) = (figures(0, operation), figures(1, baseline));
    Ok(OperationBenchReport {
        coarse: detail == Detail::Coarse,
        repeats: repeats.max(1),
        p99_ratio: operation.tick.p99_us / baseline.tick.p99_us.max(f64::MIN_POSITIVE),
        operation,
        baseline,
    })
}

/// One attempt at `scenario` by its run, each tick's compute recorded: the quantiles, the
/// ticks run and the score.
fn timed(
    scenario: &ScenarioRun,
    dir: &Path,
    detail: Detail,
) -> Result<(TickFigures, u64, f64), String> {
    let named = |e: &dyn fmt::Display| format!("{}: {e}", scenario.scenario.display());
    let loaded = load(&scenario.scenario).map_err(|e| e.to_string())?;
    let scene = scenario_scene(&loaded, dir, detail, OnStale::Rebuild).map_err(|e| named(&e))?;
    let hands = Trajectory::load_hands(&scenario.run).map_err(|e| e.to_string())?;
    let ticks = ((hands[0].duration_s() + 0.1) / TICK_S).ceil() as u64;
    let devices = (hands.into_iter())
        .map(|hand| Box::new(Scripted::new("benchmark run", hand)) as Box<dyn HapticDevice>)
        .collect();
    let mut compute = Histogram::default();
    let mut ran = 0;
    let outcome = run_observed(loaded, &scene, devices, ticks, |_, spent| {
        compute.record(spent);
        ran += 1;
    })?;
    Ok((TickFigures::of(&compute), ran, outcome.card.score))
}

impl fmt::Display for OperationBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "scripted runs through the haptic loop, simulated clock, {} organs (medians of {} runs)",
            if self.coarse { "coarse" } else { "full" },
            self.repeats
        )?;
        for run in [&self.operation, &self.baseline] {
            writeln!(
                f,
                "  {}: {} ticks, p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs; score {:.0}",
                run.scenario,
                run.ticks,
                run.tick.p50_us,
                run.tick.p99_us,
                run.tick.max_us,
                run.score
            )?;
        }
        writeln!(f, "  p99 ratio {:.2}", self.p99_ratio)
    }
}
