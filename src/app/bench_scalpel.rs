//! The scalpel's benchmark (`pgd bench scalpel`): the four-organ scene with the liver cut by a
//! stroke of the blade, ticked at 1 kHz on the real clock as the trainer ticks it (the cut
//! state growing on its worker thread meanwhile), against the same stroke with a probe in
//! the same run. Reports the tick's compute time, the worker's time per step and the cut
//! made.

use std::fmt;
use std::time::Duration;

use nalgebra::Vector3;
use serde::Serialize;

use super::haptic::{HapticLoop, HapticScene, OrganBody, OrganCut, TickClock};
use crate::devices::{
    DeviceSample, Histogram, Metronome, Scripted, TICK_S, TimerMode, Trajectory, TrajectoryRow,
};

/// One run's tick compute quantiles (µs).
#[derive(Clone, Debug, Default, Serialize)]
pub struct TickFigures {
    pub p50_us: f64,
    pub p99_us: f64,
    pub max_us: f64,
}

impl TickFigures {
    /// The quantiles of the ticks `compute` recorded.
    pub fn of(compute: &Histogram) -> Self {
        let us = |q: f64| compute.quantile(q).as_secs_f64() * 1e6;
        Self {
            p50_us: us(0.5),
            p99_us: us(0.99),
            max_us: compute.max().as_secs_f64() * 1e6,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct ScalpelBenchReport {
    pub repeats: usize,
    /// Medians over the repeats of each run's quantiles: with the scalpel cutting the liver,
    /// and with a probe on the same path.
    pub scalpel: TickFigures,
    pub probe: TickFigures,
    /// The worker's time per step (ms), over every step of every run: median and p99.
    pub step_p50_ms: f64,
    pub step_p99_ms: f64,
    pub steps: usize,
    /// The last run's cut: enriched unknowns, length and depth (mm).
    pub unknowns: usize,
    pub cut_length_mm: f64,
    pub cut_depth_mm: f64,
}

/// Runs the stroke `repeats` times with `scene` (whose liver the scalpel cuts) and with the
/// same scene uncut; `tip_radius_m` places the stroke's depth.
pub fn run(scene: &HapticScene, repeats: usize) -> Result<ScalpelBenchReport, String> {
    let probe_scene = HapticScene {
        cutting: None,
        ..scene.clone()
    };
    let stroke = stroke(scene.probe.tip_radius_m);
    let mut scalpel = Vec::new();
    let mut probe = Vec::new();
    let mut steps = Vec::new();
    let mut last = (0, 0.0, 0.0);
    for _ in 0..repeats {
        let (figures, haptic) = paced(scene, &stroke)?;
        scalpel.push(figures);
        let (step_seconds, cut) = cut_of(haptic);
        steps.extend(step_seconds);
        last = cut;
        probe.push(paced(&probe_scene, &stroke)?.0);
    }
    steps.sort_by(f64::total_cmp);
    let quantile = |q: f64| steps.get(((steps.len() as f64 - 1.0) * q).round() as usize);
    Ok(ScalpelBenchReport {
        repeats,
        scalpel: median_figures(&scalpel),
        probe: median_figures(&probe),
        step_p50_ms: quantile(0.5).map_or(0.0, |s| s * 1e3),
        step_p99_ms: quantile(0.99).map_or(0.0, |s| s * 1e3),
        steps: steps.len(),
        unknowns: last.0,
        cut_length_mm: last.1 * 1e3,
        cut_depth_mm: last.2 * 1e3,
    })
}

/// Down onto the liver's front at (22, ·, 0.3) mm, the tip's centre pressed 20 mm below the
/// rest surface, drawn 26 mm along x (the blade's edge), lifted: 7 s.
fn stroke(tip_radius_m: f64) -> Trajectory {
    let surface_y_mm = 59.8;
    let pressed = surface_y_mm + tip_radius_m * 1e3 - 20.0;
    let at = |t: f64, x: f64, y: f64| {
        TrajectoryRow::new(t, &DeviceSample::at(Vector3::new(x, y, 0.3) * 1e-3))
    };
    Trajectory {
        rows: vec![
            at(0.0, 22.0, 95.0),
            at(1.0, 22.0, surface_y_mm + 20.0),
            at(2.5, 22.0, pressed),
            at(5.5, 48.0, pressed - 1.8),
            at(6.0, 48.0, pressed - 1.8),
            at(7.0, 48.0, 95.0),
        ],
    }
}

/// The stroke ticked at 1 kHz on the real clock; the tick compute quantiles and the loop.
fn paced(scene: &HapticScene, stroke: &Trajectory) -> Result<(TickFigures, HapticLoop), String> {
    let ticks = (stroke.duration_s() / TICK_S).ceil() as u64;
    let device = Box::new(Scripted::new("stroke", stroke.clone()));
    let mut haptic = HapticLoop::new(scene, device).map_err(|e| e.to_string())?;
    let mut compute = Histogram::default();
    let mut metronome = Metronome::new(Duration::from_secs_f64(TICK_S), TimerMode::default());
    for tick in 0..ticks {
        metronome.wait();
        compute.record(haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        }));
    }
    Ok((TickFigures::of(&compute), haptic))
}

/// The liver's cut after a run: the worker's step times (s), and (unknowns, length m, depth m).
fn cut_of(mut haptic: HapticLoop) -> (Vec<f64>, (usize, f64, f64)) {
    let world = haptic.world_mut();
    let mut organs = world.query::<(&OrganBody, &mut OrganCut)>();
    let Some((_, mut cut)) = organs.iter_mut(world).find(|(b, _)| b.name == "liver") else {
        return (Vec::new(), (0, 0.0, 0.0));
    };
    let unknowns = cut.worker.settle().unknowns;
    let stroke = cut.scalpel.strokes().first().copied();
    let made = stroke.map_or((unknowns, 0.0, 0.0), |s| {
        (unknowns, s.length_m, s.max_depth_m)
    });
    (cut.worker.step_seconds(), made)
}

/// Each quantile's median over `runs`.
pub(super) fn median_figures(runs: &[TickFigures]) -> TickFigures {
    let median = |f: fn(&TickFigures) -> f64| {
        let mut values: Vec<f64> = runs.iter().map(f).collect();
        values.sort_by(f64::total_cmp);
        values.get(values.len() / 2).copied().unwrap_or(0.0)
    };
    TickFigures {
        p50_us: median(|t| t.p50_us),
        p99_us: median(|t| t.p99_us),
        max_us: median(|t| t.max_us),
    }
}

impl fmt::Display for ScalpelBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "scalpel stroke on the liver, four-organ scene, 1 kHz real clock (medians of {} runs)",
            self.repeats
        )?;
        for (name, t) in [
            ("scalpel", &self.scalpel),
            ("probe (baseline)", &self.probe),
        ] {
            writeln!(
                f,
                "  tick with {name:<17} p50 {:>6.1} µs  p99 {:>6.1} µs  max {:>7.1} µs",
                t.p50_us, t.p99_us, t.max_us
            )?;
        }
        writeln!(
            f,
            "  cut state step (worker thread): median {:.2} ms, p99 {:.2} ms over {} steps",
            self.step_p50_ms, self.step_p99_ms, self.steps
        )?;
        writeln!(
            f,
            "  the cut: {} enriched unknowns, {:.1} mm long, {:.1} mm deep",
            self.unknowns, self.cut_length_mm, self.cut_depth_mm
        )
    }
}
