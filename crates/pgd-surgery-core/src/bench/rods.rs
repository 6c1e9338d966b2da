//! The rods benchmark (`pgd bench rods`): a duct 50 mm long clamped at one end, its other end
//! pulled by a force that wanders as a hand's does (up to 50 mN, over seconds), settled once a
//! tick from the last tick's shape to a micronewton. Per number of segments: the solve's time
//! (median, p99) and its share of the 1 ms tick, and the Newton steps it took.

use std::fmt;
use std::time::Instant;

use nalgebra::Vector3;
use serde::Serialize;

use super::fem::quantile;
use crate::devices::TICK_S;
use crate::rods::{Rod, RodError, TubeSection};

/// How closely each tick's solve settles the rod (N): far below what a hand feels.
pub const TOLERANCE_N: f64 = 1e-6;

#[derive(Clone, Debug, Serialize)]
pub struct RodFigures {
    pub segments: usize,
    pub solve_p50_us: f64,
    pub solve_p99_us: f64,
    /// The p99 over the tick's period.
    pub tick_share_p99: f64,
    pub newton_steps_mean: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct RodsBenchReport {
    pub ticks: usize,
    pub tolerance_n: f64,
    pub rods: Vec<RodFigures>,
}

/// Times `ticks` ticks of a duct in 20, 30 and 60 segments.
pub fn run(ticks: usize) -> Result<RodsBenchReport, RodError> {
    let rods = [20, 30, 60]
        .into_iter()
        .map(|segments| time_rod(segments, ticks.max(1)))
        .collect::<Result<_, _>>()?;
    Ok(RodsBenchReport {
        ticks,
        tolerance_n: TOLERANCE_N,
        rods,
    })
}

fn time_rod(segments: usize, ticks: usize) -> Result<RodFigures, RodError> {
    let section = TubeSection {
        outer_radius_m: 2.5e-3,
        wall_m: 0.5e-3,
    };
    let mut rod = Rod::straight(
        Vector3::zeros(),
        Vector3::x() * 0.05,
        segments,
        section,
        4.7e6,
    )?;
    rod.clamp_start();
    let tip = rod.nodes() - 1;
    let mut times_us = Vec::with_capacity(ticks);
    let mut steps = 0;
    for tick in 0..ticks {
        let t = tick as f64 * TICK_S;
        let pull = Vector3::new(
            0.01 * (0.7 * t).sin(),
            0.02 * (2.0 * t).sin(),
            -0.05 * t.sin(),
        );
        let started = Instant::now();
        steps += rod.solve(&[(tip, pull)], TOLERANCE_N)?.newton_steps;
        times_us.push(started.elapsed().as_secs_f64() * 1e6);
    }
    let p99 = quantile(&times_us, 0.99);
    Ok(RodFigures {
        segments,
        solve_p50_us: quantile(&times_us, 0.5),
        solve_p99_us: p99,
        tick_share_p99: p99 * 1e-6 / TICK_S,
        newton_steps_mean: steps as f64 / ticks as f64,
    })
}

impl fmt::Display for RodsBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "rods benchmark: a 50 mm duct clamped at one end, its tip pulled; {} ticks, settled to {:.0e} N",
            self.ticks, self.tolerance_n
        )?;
        writeln!(
            f,
            "{:>9} {:>10} {:>10} {:>14} {:>14}",
            "segments", "p50 µs", "p99 µs", "tick share", "Newton steps"
        )?;
        for r in &self.rods {
            writeln!(
                f,
                "{:>9} {:>10.1} {:>10.1} {:>13.1}% {:>14.2}",
                r.segments,
                r.solve_p50_us,
                r.solve_p99_us,
                100.0 * r.tick_share_p99,
                r.newton_steps_mean
            )?;
        }
        Ok(())
    }
}
