//! Exact responses, one column per load parameter: `U = K⁻¹ F` for the linear law, and the
//! secant responses of a Kirchhoff–Saint Venant load step. They are what the brute-force
//! baseline computes, and what the vademecum's local part (compliances, near-field
//! corrections) is cut from.

use faer::MatRef;
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::anderson::Anderson;
use super::load_patches::{LoadOperator, LoadPatches, UnitLoads, parameter_load};
use super::stiffness::RestStiffness;
use crate::fem::{KrylovStatistics, NewtonSettings};
use web_time::Instant;

/// Columns solved together: one pass over the factor serves them all.
pub(super) const BLOCK_COLUMNS: usize = 48;

/// Smaller increments a load that diverged over its step's whole increment is taken through:
/// eight reach further than four at about the same cost (docs/pgd.md).
const SUBSTEPS: usize = 8;

/// Some of a step's loads, renumbered from zero: what the substeps of those that diverged
/// iterate on together.
/// A load step's loads: the unit loads and the magnitude (N) each is applied at.
pub struct ScaledLoads<'a, L> {
    pub unit: &'a L,
    pub magnitudes_n: &'a [f64],
}

impl<L> Clone for ScaledLoads<'_, L> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<L> Copy for ScaledLoads<'_, L> {}

/// Where a step's iteration starts: the responses held at `fraction_before` of its
/// magnitude (the step before's level), moved along the trend through the steps before.
#[derive(Clone, Copy)]
pub struct StepStart<'a> {
    pub trend: Option<&'a Trend>,
    pub fraction_before: f64,
}

struct Subset<'a, L> {
    loads: &'a L,
    parameters: &'a [usize],
}

impl<L: UnitLoads> UnitLoads for Subset<'_, L> {
    fn nodal_shares(&self, j: usize) -> impl Iterator<Item = (usize, f64)> {
        self.loads.nodal_shares(self.parameters[j])
    }

    fn direction(&self, j: usize) -> Vector3<f64> {
        self.loads.direction(self.parameters[j])
    }
}

/// Unit loads renumbered from `first`: load `j` here is load `first + j` of `loads`, so that
/// a shard's responses, numbered from zero, load its own positions.
pub struct Offset<'a, L> {
    pub loads: &'a L,
    pub first: usize,
}

impl<L: UnitLoads> UnitLoads for Offset<'_, L> {
    fn nodal_shares(&self, j: usize) -> impl Iterator<Item = (usize, f64)> {
        self.loads.nodal_shares(self.first + j)
    }

    fn direction(&self, j: usize) -> Vector3<f64> {
        self.loads.direction(self.first + j)
    }
}

/// Halvings of a fixed-point update allowed to keep every element's volume positive.
const MAX_HALVINGS: usize = 20;

/// Relative residual at which a Newton solve of a load the fixed point left is converged: a
/// hundred times below the fixed point's tolerance on its change, which the other loads of
/// the step are held to. Tighter costs Newton iterations that change nothing the step keeps
/// (1e-8 took 23–45 % more conjugate-gradient iterations on the coarse pancreas, and left a
/// load unconverged after 30 iterations that 1e-5 solves).
const NEWTON_TOLERANCE: f64 = 1e-5;

/// Load increments of the Newton path from rest, when the step before's response is no start.
const NEWTON_PATH_STEPS: usize = 4;

/// Loads Newton solves at a time (in parallel) before it checks its budget again: as many
/// as a 16-core machine runs at once, and few enough that a step Newton cannot afford costs
/// little before it is given up.
const NEWTON_BATCH: usize = 16;

/// A fixed-point iteration's nonlinear force in triangular solves with the rest factor, the
/// unit Newton's budget counts in ([`KrylovStatistics::cost_in_solves`]): 3.1 ms against
/// 13.3 ms on the liver-sized box of `pgd bench fem`.
const NONLINEAR_FORCE_SOLVES: f64 = 0.25;

/// What [`Responses::solve_by_newton`] did with the loads it was given.
#[derive(Default)]
struct NewtonOutcome {
    /// The loads it solved (sorted).
    solved: Vec<usize>,
    /// What its linear solves cost.
    solves: KrylovStatistics,
    /// Loads it did not try, their estimated cost being over its budget.
    left: usize,
}

/// Free-dof columns of the responses, column-major (`free_count` rows).
#[derive(Clone)]
pub struct Responses {
    pub rows: usize,
    pub columns: Vec<f64>,
}

impl Responses {
    pub fn count(&self) -> usize {
        self.columns.len() / self.rows
    }

    pub fn column(&self, p: usize) -> &[f64] {
        &self.columns[p * self.rows..(p + 1) * self.rows]
    }

    /// Solves `K u_p = f_p` for every unit load of `patches`, blocks in parallel; `progress` gets
    /// the number of columns done.
    pub fn linear(
        stiffness: &RestStiffness,
        patches: &LoadPatches,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Self {
        Self::solve(stiffness, patches, patches.parameter_count(), progress)
    }

    /// Solves `K u_p = f_p` for the first `count` unit loads of `loads`, blocks of
    /// [`BLOCK_COLUMNS`] in parallel; `progress` gets the number of columns done.
    pub fn solve(
        stiffness: &RestStiffness,
        loads: &impl UnitLoads,
        count: usize,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Self {
        let rows = stiffness.free_count();
        let mut columns = vec![0.0; rows * count];
        columns
            .par_chunks_mut(rows * BLOCK_COLUMNS)
            .enumerate()
            .for_each(|(block, chunk)| {
                for (j, column) in chunk.chunks_exact_mut(rows).enumerate() {
                    add_unit_load(stiffness, loads, block * BLOCK_COLUMNS + j, column);
                }
                stiffness.solve_block(chunk);
                progress(chunk.len() / rows);
            });
        Self { rows, columns }
    }

    /// Responses of `rows` rows side by side, in the order given: a whole step's columns from
    /// its shards'.
    pub fn joined<'a>(rows: usize, parts: impl Iterator<Item = &'a Responses>) -> Self {
        let mut columns = Vec::new();
        for part in parts {
            columns.extend_from_slice(&part.columns);
        }
        Self { rows, columns }
    }

    /// `self += sign · other`, column by column: a step's secant responses to and from their
    /// nonlinear corrections.
    pub fn add_scaled(&mut self, other: &Self, sign: f64) {
        self.columns
            .par_iter_mut()
            .zip(&other.columns)
            .for_each(|(a, b)| *a += sign * b);
    }

    /// Turns linear (or previous-step) responses into the secant responses of a KSV load step:
    /// per unit force, the response to a force of `magnitudes_n[p]` along parameter `p`,
    /// `ũ = u / λ` with `K u = λ e_p − N(u)`. The nonlinear terms `N` of the previous iterate
    /// go to the right-hand side (paper 000), so every iteration reuses the factorization of
    /// the rest stiffness. `self` is the step before's responses, which an unconverged load
    /// keeps; the iteration starts from `self + trend`. Also returns the loads left
    /// unconverged (sorted). A load of zero magnitude is not iterated and keeps its column.
    pub fn secant(
        mut self,
        stiffness: &RestStiffness,
        loads: ScaledLoads<'_, impl UnitLoads>,
        start: StepStart<'_>,
        settings: &SecantSettings,
        progress: &(dyn Fn(usize) + Sync),
    ) -> (Self, SecantReport, Vec<usize>) {
        let (patches, magnitudes_n) = (loads.unit, loads.magnitudes_n);
        let (trend, fraction_before) = (start.trend, start.fraction_before);
        let rows = self.rows;
        let (mut report, mut unconverged) = self
            .columns
            .par_chunks_mut(rows * BLOCK_COLUMNS)
            .enumerate()
            .map(|(block, chunk)| {
                let first = block * BLOCK_COLUMNS;
                let trend = trend.map(|t| t.block(block, chunk.len()));
                let magnitudes_n = &magnitudes_n[first..];
                let done = secant_block(
                    stiffness,
                    patches,
                    first,
                    magnitudes_n,
                    chunk,
                    trend,
                    settings,
                );
                progress(chunk.len() / rows);
                done
            })
            .reduce(
                || (SecantReport::default(), Vec::new()),
                |(a, mut failed), (b, more)| {
                    failed.extend(more);
                    (a.merge(b), failed)
                },
            );
        let rescued =
            self.continue_in_substeps(stiffness, loads, &unconverged, fraction_before, settings);
        report.substep_solved = rescued.len();
        report.unconverged -= rescued.len();
        unconverged.retain(|p| rescued.binary_search(p).is_err());
        if settings.newton_budget > 0.0 && !unconverged.is_empty() {
            let start = Instant::now();
            let budget = settings.newton_budget * report.fixed_point_solves();
            let newton =
                self.solve_by_newton(stiffness, loads, &unconverged, fraction_before, budget);
            report.newton_seconds = start.elapsed().as_secs_f64();
            report.newton_solved = newton.solved.len();
            report.newton_solves = newton.solves;
            report.newton_over_budget = newton.left;
            report.unconverged -= newton.solved.len();
            unconverged.retain(|p| newton.solved.binary_search(p).is_err());
        }
        (self, report, unconverged)
    }

    /// Takes the loads `failed` (sorted) that diverged on the step's whole increment through
    /// [`SUBSTEPS`] smaller ones, each fixed point started from the one before: from
    /// `fraction_before` of the step's magnitude (the step before's level; those loads hold
    /// its response) to the whole. The fixed point with the rest stiffness diverges where the
    /// tangent has moved far from it over one increment; a shorter increment starts it nearer
    /// its solution, for a few fixed points' cost where Newton would factorize the tangent at
    /// every iteration. Returns the loads so solved (sorted); the others keep their start.
    fn continue_in_substeps(
        &mut self,
        stiffness: &RestStiffness,
        step: ScaledLoads<'_, impl UnitLoads>,
        failed: &[usize],
        fraction_before: f64,
        settings: &SecantSettings,
    ) -> Vec<usize> {
        let (loads, magnitudes_n) = (step.unit, step.magnitudes_n);
        let rows = self.rows;
        let solved: Vec<(usize, Vec<f64>)> = failed
            .par_chunks(BLOCK_COLUMNS)
            .flat_map_iter(|parameters| {
                let subset = Subset { loads, parameters };
                let mut chunk: Vec<f64> = parameters
                    .iter()
                    .flat_map(|&p| self.column(p).iter().copied())
                    .collect();
                let mut alive = vec![true; parameters.len()];
                for i in 1..=SUBSTEPS {
                    let t = fraction_before + (1.0 - fraction_before) * i as f64 / SUBSTEPS as f64;
                    let magnitudes: Vec<f64> = parameters
                        .iter()
                        .zip(&alive)
                        .map(|(&p, &a)| if a { t * magnitudes_n[p] } else { 0.0 })
                        .collect();
                    let (_, diverged) = secant_block(
                        stiffness,
                        &subset,
                        0,
                        &magnitudes,
                        &mut chunk,
                        None,
                        settings,
                    );
                    diverged.into_iter().for_each(|j| alive[j] = false);
                }
                let columns: Vec<Vec<f64>> =
                    chunk.chunks_exact(rows).map(<[f64]>::to_vec).collect();
                parameters
                    .iter()
                    .copied()
                    .zip(columns)
                    .zip(alive)
                    .filter_map(|(solved, alive)| alive.then_some(solved))
                    .collect::<Vec<_>>()
            })
            .collect();
        for (p, column) in &solved {
            self.columns[p * rows..(p + 1) * rows].copy_from_slice(column);
        }
        solved.into_iter().map(|(p, _)| p).collect()
    }

    /// Solves the loads `parameters` by Newton, one full nonlinear solve each (in parallel),
    /// from the step before's equilibrium: the response they hold at `fraction_before` of the
    /// step's magnitude (from rest, in increments, if that start turns an element inside
    /// out): for the few that the fixed point with the rest stiffness cannot carry. Newton's
    /// first direction from there is the tangent's prediction of the increment; the step
    /// before's response at the whole magnitude, the secant's prediction, presses a stiffening
    /// law too deep (a residual as large as the load, and a dozen iterations to recover). A
    /// load Newton fails on too keeps that response, as does one whose equilibrium turns an
    /// element inside out (the KSV law has such equilibria past its stability). Its linear
    /// systems are solved by conjugate gradients preconditioned with the rest stiffness's
    /// factor ([`RestStiffness::newton_solver`]).
    ///
    /// The loads go [`NEWTON_BATCH`] at a time, and Newton stops before a batch when what
    /// it has spent, plus the rest at the mean cost so far, would pass `budget_solves`
    /// (triangular solves with the rest factor): a step whose leftovers Newton cannot
    /// afford is then left out having cost at most one batch. The batches are fixed, so
    /// the outcome does not depend on the machine.
    fn solve_by_newton(
        &mut self,
        stiffness: &RestStiffness,
        step: ScaledLoads<'_, impl UnitLoads>,
        parameters: &[usize],
        fraction_before: f64,
        budget_solves: f64,
    ) -> NewtonOutcome {
        let mut outcome = NewtonOutcome::default();
        for (batch, loads) in parameters.chunks(NEWTON_BATCH).enumerate() {
            let done = batch * NEWTON_BATCH;
            let spent = outcome.solves.cost_in_solves();
            if done > 0 && spent * parameters.len() as f64 / done as f64 > budget_solves {
                outcome.left = parameters.len() - done;
                break;
            }
            let (solved, solves) = self.newton_batch(stiffness, step, loads, fraction_before);
            outcome.solved.extend(solved);
            outcome.solves = outcome.solves.merge(solves);
        }
        outcome.solved.sort_unstable();
        outcome
    }

    /// One batch of [`Self::solve_by_newton`], in parallel: the loads solved and what their
    /// linear solves cost.
    fn newton_batch(
        &mut self,
        stiffness: &RestStiffness,
        step: ScaledLoads<'_, impl UnitLoads>,
        parameters: &[usize],
        fraction_before: f64,
    ) -> (Vec<usize>, KrylovStatistics) {
        let (patches, magnitudes_n) = (step.unit, step.magnitudes_n);
        let model = stiffness.model;
        let settings = NewtonSettings {
            relative_tolerance: NEWTON_TOLERANCE,
            ..NewtonSettings::default()
        };
        let solved: Vec<(usize, Vec<f64>, KrylovStatistics)> = parameters
            .par_iter()
            .filter_map(|&p| {
                let lambda = magnitudes_n[p];
                let start = stiffness
                    .extend(self.column(p))
                    .iter()
                    .map(|u| u * fraction_before * lambda)
                    .collect();
                let shares = patches.nodal_shares(p);
                let direction = patches.direction(p);
                let loads =
                    parameter_load(model.mesh().node_count(), shares, direction, lambda).ok()?;
                // A start that turns an element inside out: a load path from rest instead.
                let path = NewtonSettings {
                    load_steps: NEWTON_PATH_STEPS,
                    ..settings
                };
                let mut solver = stiffness.newton_solver();
                let solution = model
                    .solve_static_from(start, &loads, &settings, &mut solver)
                    .or_else(|_| model.solve_static_with(&mut solver, &loads, &path))
                    .ok()
                    .filter(|s| !model.turns_an_element_inside_out(&s.displacement_m))?;
                let secant = stiffness.restrict(&solution.displacement_m);
                let column = secant.iter().map(|u| u / lambda).collect();
                Some((p, column, solver.statistics()))
            })
            .collect();
        let mut statistics = KrylovStatistics::default();
        for (p, column, solves) in &solved {
            self.columns[p * self.rows..(p + 1) * self.rows].copy_from_slice(column);
            statistics = statistics.merge(*solves);
        }
        (solved.into_iter().map(|(p, ..)| p).collect(), statistics)
    }

    /// The energy Gram `Uᵀ K U` (column-major) of responses that need not satisfy `K U = F`
    /// for unit loads `F` (the secant responses of a KSV step): a sparse product and a dense
    /// one.
    pub fn energy_gram(&self, stiffness: &RestStiffness) -> Vec<f64> {
        let n = self.count();
        let mut stiff = vec![0.0; self.columns.len()];
        stiff
            .par_chunks_mut(self.rows)
            .enumerate()
            .for_each(|(p, out)| stiffness.mul(self.column(p), out));
        let u = MatRef::from_column_major_slice(&self.columns, self.rows, n);
        let ku = MatRef::from_column_major_slice(&stiff, self.rows, n);
        let gram = u.transpose() * ku;
        (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| gram[(i, j)])
            .collect()
    }

    /// The compliance between all pairs of loads, `G = Fᵀ U` (parameters × parameters,
    /// column-major): the energy Gram matrix of the responses, since `Uᵀ K U = Fᵀ U`.
    pub fn gram(&self, stiffness: &RestStiffness, loads: &(dyn LoadOperator + Sync)) -> Vec<f64> {
        let n = self.count();
        let mut gram = vec![0.0; n * n];
        gram.par_chunks_mut(n).enumerate().for_each(|(p, out)| {
            loads.apply_transpose(&stiffness.extend(self.column(p)), out);
        });
        gram
    }
}

/// How the secant responses moved over the last step, scaled to the next one: `r (Ũ_k − Ũ_{k−1})`
/// with `r` the ratio of the steps' widths. Added to `Ũ_k`, it starts the next step's fixed
/// point on the line through the last two steps (a secant predictor in the load), closer to
/// its solution than `Ũ_k` where the response changes steadily with depth.
pub struct Trend {
    rows: usize,
    columns: Vec<f64>,
}

impl Trend {
    /// From `before` to `after` (levels `from_m` and `at_m`), extended to `to_m`.
    pub fn new(before: &Responses, after: &Responses, from_m: f64, at_m: f64, to_m: f64) -> Self {
        let ratio = (to_m - at_m) / (at_m - from_m);
        let columns = after
            .columns
            .par_iter()
            .zip(&before.columns)
            .map(|(a, b)| ratio * (a - b))
            .collect();
        Self {
            rows: after.rows,
            columns,
        }
    }

    /// The part of block `block` (`len` values) of the responses.
    fn block(&self, block: usize, len: usize) -> &[f64] {
        let start = block * BLOCK_COLUMNS * self.rows;
        &self.columns[start..start + len]
    }
}

/// The fixed point of a KSV load step, per response.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SecantSettings {
    /// Converged when the fixed point's residual `G(ũ) − ũ` is less than this, relative to
    /// `G(ũ)`.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Differences remembered by each response's Anderson acceleration (0: plain iteration).
    /// A setting missing from a file's header reads as what files were built with before it
    /// existed (here the plain iteration; undamped and no Newton below), so such a file is
    /// seen as built otherwise than the current defaults would build it.
    #[serde(default)]
    pub anderson_depth: usize,
    /// The fraction β of the fixed point's residual each step takes at first (1: paper 000's
    /// iteration), halved while the residual keeps growing. Under a stiffening law the full
    /// step overshoots: the elements under a nodal load are pressed so far on the first step
    /// that the exponential law's modulus explodes.
    #[serde(default = "undamped")]
    pub mixing: f64,
    /// Loads failing to converge at a step, up to this fraction of them, keep the previous
    /// step's secant response (reported, never silent) and their positions' range goes on;
    /// past it the failed positions' range ends at the step before.
    pub max_unconverged_fraction: f64,
    /// A step after the first nonlinear one is kept while the positions whose range reaches
    /// it are at least this share of the loaded ones. Beside a clamped attachment the tissue
    /// is squeezed between the tool and the clamp, and the loads there fail steps before the
    /// others: their range ends sooner, the rest go deeper.
    #[serde(default = "every_position")]
    pub min_reached_share: f64,
    /// The loads a step's fixed point leaves are solved by Newton while its linear solves
    /// cost at most this many times the step's fixed point (both counted in triangular
    /// solves with the rest factor); a step whose leftovers would cost more is left out, so
    /// Newton at most multiplies a build's time by one plus this. 0: never.
    #[serde(default)]
    pub newton_budget: f64,
}

impl Default for SecantSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_iterations: 40,
            anderson_depth: 5,
            mixing: 0.5,
            max_unconverged_fraction: 0.005,
            min_reached_share: 0.25,
            newton_budget: 12.0,
        }
    }
}

/// The mixing of a file built before the setting existed: the full step.
fn undamped() -> f64 {
    1.0
}

/// The reached share of a file built before the setting existed: a step reached every
/// position (but the tolerated failures).
fn every_position() -> f64 {
    1.0
}

/// How the fixed points of one load step went.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SecantReport {
    pub responses: usize,
    pub total_iterations: usize,
    pub max_iterations: usize,
    /// Responses whose last change stayed above the tolerance (or became non-finite): there
    /// the load step is beyond what the fixed point (and, usually, the KSV law) can carry.
    /// They keep their starting iterate, the previous step's secant response.
    pub unconverged: usize,
    /// Responses that diverged over the step's whole increment and converged through smaller
    /// ones (not counted as unconverged).
    pub substep_solved: usize,
    /// Responses the fixed point left that Newton then solved (not counted as unconverged).
    pub newton_solved: usize,
    /// What Newton's linear solves for them cost.
    pub newton_solves: KrylovStatistics,
    /// Loads Newton left unsolved because they would have cost more than its budget.
    pub newton_over_budget: usize,
    /// Time spent in those Newton solves (s).
    pub newton_seconds: f64,
    /// The largest final relative residual over all responses.
    pub worst_change: f64,
}

impl SecantReport {
    pub fn merge(self, other: Self) -> Self {
        Self {
            responses: self.responses + other.responses,
            total_iterations: self.total_iterations + other.total_iterations,
            max_iterations: self.max_iterations.max(other.max_iterations),
            unconverged: self.unconverged + other.unconverged,
            substep_solved: self.substep_solved + other.substep_solved,
            newton_solved: self.newton_solved + other.newton_solved,
            newton_solves: self.newton_solves.merge(other.newton_solves),
            newton_over_budget: self.newton_over_budget + other.newton_over_budget,
            newton_seconds: self.newton_seconds + other.newton_seconds,
            worst_change: self.worst_change.max(other.worst_change),
        }
    }

    /// Whether the step may be kept: few enough responses failed.
    pub fn acceptable(&self, settings: &SecantSettings) -> bool {
        self.unconverged as f64 <= settings.max_unconverged_fraction * self.responses as f64
    }

    /// What the step's fixed point cost in triangular solves with the rest factor: one per
    /// iteration of each load, and its nonlinear force.
    pub fn fixed_point_solves(&self) -> f64 {
        (1.0 + NONLINEAR_FORCE_SOLVES) * self.total_iterations as f64
    }

    pub fn mean_iterations(&self) -> f64 {
        self.total_iterations as f64 / self.responses.max(1) as f64
    }
}

/// Adds the unit load of parameter `p` to `column` (free dofs).
fn add_unit_load(stiffness: &RestStiffness, loads: &impl UnitLoads, p: usize, column: &mut [f64]) {
    let free_index = &stiffness.model.dofs().free_index;
    let direction = loads.direction(p);
    for (node, share) in loads.nodal_shares(p) {
        for (c, component) in direction.iter().enumerate() {
            let free = free_index[3 * node + c];
            if free != crate::fem::PRESCRIBED {
                column[free] += share * component;
            }
        }
    }
}

/// The fixed point for the columns of one block (`first` is the first column's parameter,
/// `magnitudes_n` from it on), iterating only the columns still moving. Each column is accelerated by Anderson's method
/// ([`Anderson`]): where the law stiffens or softens, the plain iteration with the rest
/// stiffness overshoots or crawls.
fn secant_block(
    stiffness: &RestStiffness,
    patches: &impl UnitLoads,
    first: usize,
    magnitudes_n: &[f64],
    chunk: &mut [f64],
    trend: Option<&[f64]>,
    settings: &SecantSettings,
) -> (SecantReport, Vec<usize>) {
    let rows = stiffness.free_count();
    let columns = chunk.len() / rows;
    // A load on a clamped node, or past its position's range, has no magnitude: nothing to
    // iterate.
    let mut active: Vec<usize> = (0..columns).filter(|&j| magnitudes_n[j] != 0.0).collect();
    let mut change = vec![0.0; columns];
    let mut growing = vec![0usize; columns];
    let mut accelerators: Vec<Anderson> = (0..columns)
        .map(|_| Anderson::new(settings.anderson_depth, settings.mixing))
        .collect();
    let mut report = SecantReport {
        responses: columns,
        ..SecantReport::default()
    };
    let start = chunk.to_vec();
    if let Some(trend) = trend {
        chunk.iter_mut().zip(trend).for_each(|(u, t)| *u += t);
    }
    let mut previous = chunk.to_vec();
    let mut work = NonlinearWork::new(stiffness);
    for iteration in 1..=settings.max_iterations {
        let mut rhs = Vec::with_capacity(active.len() * rows);
        for &j in &active {
            let span = j * rows..(j + 1) * rows;
            let begin = rhs.len();
            match work.finite_right_hand_side(
                &mut chunk[span.clone()],
                &previous[span],
                magnitudes_n[j],
                &mut rhs,
            ) {
                // No iterate between the last two keeps every element's volume positive.
                None => {
                    change[j] = f64::NAN;
                    rhs.truncate(begin);
                    rhs.extend(std::iter::repeat_n(0.0, rows));
                }
                Some(0) => {}
                Some(_) => accelerators[j].reset(),
            }
            add_unit_load(stiffness, patches, first + j, &mut rhs[begin..]);
        }
        for &j in &active {
            previous[j * rows..(j + 1) * rows].copy_from_slice(&chunk[j * rows..(j + 1) * rows]);
        }
        stiffness.solve_block(&mut rhs);
        for (&j, target) in active.iter().zip(rhs.chunks_exact(rows)) {
            if change[j].is_nan() {
                continue;
            }
            let span = j * rows..(j + 1) * rows;
            // The fixed point's own residual `G(x) − x`, whatever step the acceleration and
            // damping then take.
            let norm = target.iter().map(|u| u * u).sum::<f64>();
            let residual = target
                .iter()
                .zip(&previous[span.clone()])
                .map(|(g, x)| (g - x) * (g - x))
                .sum::<f64>();
            accelerators[j].advance(&mut chunk[span], target.to_vec());
            let before = change[j];
            change[j] = (residual / norm).sqrt();
            if overshoots(&mut growing[j], before, change[j]) {
                accelerators[j].damp();
            }
        }
        report.total_iterations += active.len();
        report.max_iterations = iteration;
        // A non-finite change is a divergence: stop iterating it, it stays unconverged.
        active.retain(|&j| change[j].is_finite() && change[j] >= settings.tolerance);
        if active.is_empty() {
            break;
        }
    }
    let unconverged: Vec<usize> = (0..columns)
        .filter(|&j| change[j].is_nan() || change[j] >= settings.tolerance)
        .collect();
    // Unconverged and unloaded columns keep their start, without the trend.
    let unloaded = (0..columns).filter(|&j| magnitudes_n[j] == 0.0);
    for j in unconverged.iter().copied().chain(unloaded) {
        chunk[j * rows..(j + 1) * rows].copy_from_slice(&start[j * rows..(j + 1) * rows]);
    }
    report.unconverged = unconverged.len();
    report.worst_change = change
        .iter()
        .map(|c| if c.is_finite() { *c } else { f64::INFINITY })
        .fold(0.0, f64::max);
    (report, unconverged.iter().map(|j| first + j).collect())
}

/// Whether an iteration is overshooting: its residual grew [`GROWING_STEPS`] times running
/// (`growing` counts them). A stiffening law's iteration with the rest stiffness grows by the
/// stiffening less one each step; Anderson's history makes single growths common otherwise.
fn overshoots(growing: &mut usize, before: f64, after: f64) -> bool {
    *growing = if after > before && before > 0.0 {
        *growing + 1
    } else {
        0
    };
    let overshooting = *growing >= GROWING_STEPS;
    if overshooting {
        *growing = 0;
    }
    overshooting
}

/// Consecutive growths of a fixed point's residual that make it damp its steps.
const GROWING_STEPS: usize = 2;

/// Buffers for evaluating the nonlinear terms of one response at a time.
struct NonlinearWork<'a> {
    stiffness: &'a RestStiffness<'a>,
    full: Vec<f64>,
    force: Vec<f64>,
}

impl<'a> NonlinearWork<'a> {
    fn new(stiffness: &'a RestStiffness<'a>) -> Self {
        Self {
            stiffness,
            full: vec![0.0; stiffness.full_count()],
            force: vec![0.0; stiffness.full_count()],
        }
    }

    /// Appends `−N(λ ũ) / λ` to `rhs` for the iterate `ũ` (`column`); where the iterate turns
    /// an element inside out (the neo-Hookean force is then not finite), it is first moved
    /// halfway back towards `previous`, up to [`MAX_HALVINGS`] times, as Newton's line search
    /// does. The starting iterate (equal to `previous`), the step before's response at this
    /// step's larger force, is moved towards the rest state instead. Returns the halvings
    /// taken, `None` if none gave a finite force.
    fn finite_right_hand_side(
        &mut self,
        column: &mut [f64],
        previous: &[f64],
        lambda: f64,
        rhs: &mut Vec<f64>,
    ) -> Option<usize> {
        let begin = rhs.len();
        let towards_rest = column == previous;
        for halvings in 0..=MAX_HALVINGS {
            rhs.truncate(begin);
            rhs.extend(self.right_hand_side(column, lambda));
            if rhs[begin..].iter().all(|v| v.is_finite()) {
                return Some(halvings);
            }
            for (u, p) in column.iter_mut().zip(previous) {
                *u = if towards_rest {
                    0.5 * *u
                } else {
                    0.5 * (*u + p)
                };
            }
        }
        None
    }

    /// `−N(λ ũ) / λ` over free dofs, for a secant response `ũ` at force magnitude `λ`.
    fn right_hand_side(&mut self, secant: &[f64], lambda: f64) -> impl Iterator<Item = f64> {
        let free_dofs = &self.stiffness.model.dofs().free_dofs;
        self.full.fill(0.0);
        for (&d, &v) in free_dofs.iter().zip(secant) {
            self.full[d] = lambda * v;
        }
        self.force.fill(0.0);
        self.stiffness
            .model
            .add_nonlinear_force(&self.full, &mut self.force);
        free_dofs.iter().map(move |&d| -self.force[d] / lambda)
    }
}
