//! The dynamics benchmark.
//!
//! - Per organ and basis size: the reduced KSV model's precompute, and its energy–momentum
//!   step over a pull held then released (nonlinear terms large), median and p99, against
//!   the same step of the linear law at the same size, measured in the same run.
//! - The four organs stepped together at one size: the haptic tick's share.
//! - The energy of an undamped swing on the first organ under the energy–momentum step,
//!   implicit Euler, and Newmark (average acceleration, and with numerical damping
//!   γ = 0.6, β = 0.3025), for the energy-against-time plot.

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::dynamics::{
    DynamicsError, EnergyMomentum, ModalBasis, RayleighDamping, ReducedKsv, ReducedState,
};
use crate::fem::{FemModel, Law};
use crate::pgd::Vademecum;

const TICK_S: f64 = 1e-3;

/// How far the pull moves the pulled node in the linear static answer (m): deep enough for
/// the nonlinear terms to matter.
const PULL_M: f64 = 0.015;

/// The modal damping ratio while the pull is held (tissue's, `docs/dynamics.md`).
const DAMPING_RATIO: f64 = 0.1;

/// An organ to step: its model under the KSV law and its linear vademecum.
pub struct DynamicsOrgan<'a> {
    pub name: &'a str,
    pub model: &'a FemModel,
    pub vademecum: &'a Vademecum,
}

#[derive(Clone, Debug, Serialize)]
pub struct StepTimes {
    pub p50_us: f64,
    pub p99_us: f64,
    pub mean_iterations: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct OrganFigures {
    pub organ: String,
    /// The basis size: as asked, or all the vademecum's modes where it has fewer.
    pub modes: usize,
    pub lowest_hz: f64,
    /// The highest kept mode's frequency: what the basis resolves in time.
    pub highest_hz: f64,
    pub precompute_s: f64,
    pub ksv: StepTimes,
    /// The linear law's step of the same size: the baseline.
    pub linear: StepTimes,
    pub ksv_to_linear_p50: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct EnergyTrace {
    pub organ: String,
    pub modes: usize,
    /// Every 10 ms.
    pub time_s: Vec<f64>,
    /// Total energy relative to its start, per scheme.
    pub schemes: Vec<(String, Vec<f64>)>,
}

#[derive(Clone, Debug, Serialize)]
pub struct DynamicsBenchReport {
    pub ticks: usize,
    pub organs: Vec<OrganFigures>,
    /// All organs stepped in one tick at the scene's size.
    pub scene_modes: usize,
    pub scene: StepTimes,
    pub energy: EnergyTrace,
}

/// Times `organs` at each of `sizes` over `ticks` ticks, the scene at `scene_modes`, and
/// traces the energy of the first organ's swing at `scene_modes`.
pub fn run(
    organs: &[DynamicsOrgan],
    sizes: &[usize],
    scene_modes: usize,
    ticks: usize,
) -> Result<DynamicsBenchReport, DynamicsError> {
    let mut figures = Vec::new();
    for organ in organs {
        for &modes in sizes {
            figures.push(organ_figures(organ, modes, ticks)?);
        }
    }
    let swings: Vec<Swing> = organs
        .iter()
        .map(|organ| Swing::new(organ, scene_modes, Law::KirchhoffSaintVenant))
        .collect::<Result<_, _>>()?;
    let scene = time_together(swings, ticks)?;
    let energy = energy_trace(&organs[0], scene_modes)?;
    Ok(DynamicsBenchReport {
        ticks,
        organs: figures,
        scene_modes,
        scene,
        energy,
    })
}

/// One organ's reduced model, its step and a pull that moves its most anterior free node.
struct Swing {
    reduced: ReducedKsv,
    step: EnergyMomentum,
    state: ReducedState,
    pull: Vec<f64>,
    /// No load, for the ticks after the release (allocated once, outside the timed ticks).
    none: Vec<f64>,
    /// The lowest and highest kept frequencies (Hz).
    band_hz: (f64, f64),
    precompute_s: f64,
}

impl Swing {
    fn new(organ: &DynamicsOrgan, modes: usize, law: Law) -> Result<Self, DynamicsError> {
        let started = Instant::now();
        let basis = ModalBasis::of_vademecum(organ.model, organ.vademecum, modes)?;
        let reduced = match law {
            Law::Linear => ReducedKsv::linear(&basis),
            _ => ReducedKsv::new(organ.model, &basis)?,
        };
        let precompute_s = started.elapsed().as_secs_f64();
        let omega = |k: usize| basis.omega2[k].sqrt();
        let damping = RayleighDamping::with_ratio(DAMPING_RATIO, omega(0), omega(basis.len() - 1));
        let step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, damping);
        Ok(Self {
            pull: pull(organ.model, &basis),
            none: vec![0.0; basis.len()],
            state: ReducedState::at_rest(basis.len()),
            band_hz: (
                omega(0) / (2.0 * std::f64::consts::PI),
                omega(basis.len() - 1) / (2.0 * std::f64::consts::PI),
            ),
            reduced,
            step,
            precompute_s,
        })
    }

    /// Tick `tick` of `ticks`: pulled for the first half, released for the second.
    fn tick(&mut self, tick: usize, ticks: usize) -> Result<usize, DynamicsError> {
        let load = if tick < ticks / 2 {
            &self.pull
        } else {
            &self.none
        };
        Ok(self
            .step
            .step(&self.reduced, &mut self.state, load)?
            .iterations)
    }
}

/// The generalized force of a pull at the free node of largest `y` (the organs' anterior
/// side), outward along `y`, sized so that its linear static answer moves that node by
/// `PULL_M`.
fn pull(model: &FemModel, basis: &ModalBasis) -> Vec<f64> {
    let nodes = model.mesh().nodes();
    let free = |n: usize| model.dofs().free_index[3 * n + 1] != crate::fem::PRESCRIBED;
    let node = (0..nodes.len())
        .filter(|&n| free(n))
        .max_by(|&a, &b| nodes[a].y.total_cmp(&nodes[b].y))
        .unwrap_or(0);
    let mut force = vec![0.0; basis.dof_count];
    force[3 * node + 1] = 1.0;
    let unit = basis.project(&force);
    let moved = basis.displacement(&basis.static_coordinates(&unit))[3 * node + 1];
    let scale = if moved > 0.0 { PULL_M / moved } else { 0.0 };
    unit.iter().map(|f| f * scale).collect()
}

fn organ_figures(
    organ: &DynamicsOrgan,
    modes: usize,
    ticks: usize,
) -> Result<OrganFigures, DynamicsError> {
    let ksv = Swing::new(organ, modes, Law::KirchhoffSaintVenant)?;
    let linear = Swing::new(organ, modes, Law::Linear)?;
    let ((lowest_hz, highest_hz), precompute_s) = (ksv.band_hz, ksv.precompute_s);
    let kept = ksv.reduced.len();
    let ksv = time_together(vec![ksv], ticks)?;
    let linear = time_together(vec![linear], ticks)?;
    Ok(OrganFigures {
        organ: organ.name.to_owned(),
        modes: kept,
        lowest_hz,
        highest_hz,
        precompute_s,
        ksv_to_linear_p50: ksv.p50_us / linear.p50_us,
        ksv,
        linear,
    })
}

/// Steps every swing once per tick over `ticks` ticks; the tick's time quantiles.
fn time_together(mut swings: Vec<Swing>, ticks: usize) -> Result<StepTimes, DynamicsError> {
    let mut times_us = Vec::with_capacity(ticks);
    let mut iterations = 0;
    for tick in 0..ticks {
        let started = Instant::now();
        for swing in &mut swings {
            iterations += swing.tick(tick, ticks)?;
        }
        times_us.push(started.elapsed().as_secs_f64() * 1e6);
    }
    times_us.sort_by(f64::total_cmp);
    let quantile = |q: f64| times_us[((q * ticks as f64) as usize).min(ticks - 1)];
    Ok(StepTimes {
        p50_us: quantile(0.5),
        p99_us: quantile(0.99),
        mean_iterations: iterations as f64 / (ticks * swings.len()) as f64,
    })
}

/// Seconds of the undamped swing traced.
const SWING_S: f64 = 5.0;

/// The first organ released from its pull with no damping, under each scheme.
fn energy_trace(organ: &DynamicsOrgan, modes: usize) -> Result<EnergyTrace, DynamicsError> {
    let swing = Swing::new(organ, modes, Law::KirchhoffSaintVenant)?;
    let basis = ModalBasis::of_vademecum(organ.model, organ.vademecum, modes)?;
    let modes = basis.len();
    let start = ReducedState {
        q: basis.static_coordinates(&swing.pull),
        v: vec![0.0; modes],
    };
    let reduced = &swing.reduced;
    let energy = |s: &ReducedState| s.kinetic_energy() + reduced.energy(&s.q);
    let e0 = energy(&start);
    let steps = (SWING_S / TICK_S) as usize;
    let mut conserving = EnergyMomentum::new(reduced, &basis.omega2, TICK_S, RayleighDamping::NONE);
    let schemes: [(&str, Scheme); 4] = [
        ("energy-momentum", Scheme::EnergyMomentum),
        ("implicit Euler", Scheme::ImplicitEuler),
        (
            "Newmark average acceleration",
            Scheme::Newmark {
                gamma: 0.5,
                beta: 0.25,
            },
        ),
        (
            "Newmark damped (γ 0.6, β 0.3025)",
            Scheme::Newmark {
                gamma: 0.6,
                beta: 0.3025,
            },
        ),
    ];
    let mut traces = Vec::new();
    for (name, scheme) in schemes {
        let mut state = start.clone();
        let mut acceleration = acceleration_of(reduced, &state.q);
        let mut trace = Vec::new();
        for step in 0..=steps {
            if step % 10 == 0 {
                trace.push(energy(&state) / e0);
            }
            match scheme {
                Scheme::EnergyMomentum => {
                    conserving.step(reduced, &mut state, &swing.none)?;
                }
                Scheme::ImplicitEuler => implicit_euler(reduced, &mut state)?,
                Scheme::Newmark { gamma, beta } => {
                    acceleration = newmark(reduced, &mut state, &acceleration, gamma, beta)?;
                }
            }
        }
        traces.push((name.to_owned(), trace));
    }
    Ok(EnergyTrace {
        organ: organ.name.to_owned(),
        modes,
        time_s: (0..=steps).step_by(10).map(|k| k as f64 * TICK_S).collect(),
        schemes: traces,
    })
}

#[derive(Clone, Copy)]
enum Scheme {
    EnergyMomentum,
    ImplicitEuler,
    Newmark { gamma: f64, beta: f64 },
}

/// `−f(q)` (unit mass, no load).
fn acceleration_of(reduced: &ReducedKsv, q: &[f64]) -> Vec<f64> {
    let mut force = vec![0.0; q.len()];
    reduced.force(q, &mut force, &mut reduced.scratch());
    force.iter().map(|f| -f).collect()
}

/// Newton's method on `q₁` for `residual(q₁) = inertia(q₁) + f(q₁)` with the Jacobian
/// `inertia_per_m · I + K_T(q₁)`.
fn solve_for_q1(
    reduced: &ReducedKsv,
    mut q1: Vec<f64>,
    inertia: impl Fn(&[f64]) -> Vec<f64>,
    inertia_per_m: f64,
) -> Result<Vec<f64>, DynamicsError> {
    let r = q1.len();
    let mut scratch = reduced.scratch();
    let (mut force, mut tangent) = (vec![0.0; r], vec![0.0; r * r]);
    for _ in 0..50 {
        reduced.force(&q1, &mut force, &mut scratch);
        reduced.tangent(&q1, &mut tangent, &mut scratch);
        let residual: Vec<f64> = inertia(&q1)
            .iter()
            .zip(&force)
            .map(|(a, f)| a + f)
            .collect();
        let mut jacobian = DMatrix::from_row_slice(r, r, &tangent);
        for i in 0..r {
            jacobian[(i, i)] += inertia_per_m;
        }
        let update = jacobian
            .lu()
            .solve(&DVector::from_column_slice(&residual))
            .ok_or(DynamicsError::NonFinite)?;
        let size = q1.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        q1.iter_mut().zip(update.iter()).for_each(|(q, u)| *q -= u);
        if update.amax() <= 1e-13 * size {
            return Ok(q1);
        }
    }
    Err(DynamicsError::NotConverged {
        iterations: 50,
        update: f64::NAN,
    })
}

/// `(q₁ − q₀)/h = v₁`, `(v₁ − v₀)/h = −f(q₁)`.
fn implicit_euler(reduced: &ReducedKsv, state: &mut ReducedState) -> Result<(), DynamicsError> {
    let h = TICK_S;
    let (q0, v0) = (state.q.clone(), state.v.clone());
    let inertia = |q1: &[f64]| -> Vec<f64> {
        (0..q1.len())
            .map(|i| (q1[i] - q0[i] - h * v0[i]) / (h * h))
            .collect()
    };
    let q1 = solve_for_q1(reduced, q0.clone(), inertia, 1.0 / (h * h))?;
    state.v = q1.iter().zip(&q0).map(|(a, b)| (a - b) / h).collect();
    state.q = q1;
    Ok(())
}

/// One Newmark step; returns the new acceleration.
fn newmark(
    reduced: &ReducedKsv,
    state: &mut ReducedState,
    a0: &[f64],
    gamma: f64,
    beta: f64,
) -> Result<Vec<f64>, DynamicsError> {
    let h = TICK_S;
    let (q0, v0) = (state.q.clone(), state.v.clone());
    let accel = |q1: &[f64]| -> Vec<f64> {
        (0..q1.len())
            .map(|i| (q1[i] - q0[i] - h * v0[i] - h * h * (0.5 - beta) * a0[i]) / (beta * h * h))
            .collect()
    };
    let q1 = solve_for_q1(reduced, q0.clone(), accel, 1.0 / (beta * h * h))?;
    let a1 = accel(&q1);
    state.v = (0..q1.len())
        .map(|i| v0[i] + h * ((1.0 - gamma) * a0[i] + gamma * a1[i]))
        .collect();
    state.q = q1;
    Ok(a1)
}

impl std::fmt::Display for DynamicsBenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "Dynamics benchmark: a pull held for {} ticks, then released for as many; step time \
             per tick (µs), KSV against the linear law at the same basis size",
            self.ticks / 2
        )?;
        writeln!(
            f,
            "{:<12} {:>5} {:>9} {:>9} {:>11} {:>9} {:>9} {:>7} {:>10} {:>10} {:>8}",
            "organ",
            "modes",
            "f1 (Hz)",
            "fr (Hz)",
            "precompute",
            "KSV p50",
            "KSV p99",
            "iters",
            "linear p50",
            "linear p99",
            "KSV/lin"
        )?;
        for o in &self.organs {
            writeln!(
                f,
                "{:<12} {:>5} {:>9.2} {:>9.2} {:>10.2}s {:>9.1} {:>9.1} {:>7.2} {:>10.1} {:>10.1} {:>8.1}",
                o.organ,
                o.modes,
                o.lowest_hz,
                o.highest_hz,
                o.precompute_s,
                o.ksv.p50_us,
                o.ksv.p99_us,
                o.ksv.mean_iterations,
                o.linear.p50_us,
                o.linear.p99_us,
                o.ksv_to_linear_p50
            )?;
        }
        writeln!(
            f,
            "all organs in one tick, {} modes each: p50 {:.1} µs, p99 {:.1} µs",
            self.scene_modes, self.scene.p50_us, self.scene.p99_us
        )?;
        write!(
            f,
            "undamped swing of the {}, energy after {:.0} s relative to its start:",
            self.energy.organ, SWING_S
        )?;
        for (name, trace) in &self.energy.schemes {
            write!(
                f,
                "\n  {name}: {:.6}",
                trace.last().copied().unwrap_or(f64::NAN)
            )?;
        }
        writeln!(f)
    }
}
