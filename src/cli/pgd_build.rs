//! `pgd build`: an organ's vademecum built, saved with its convergence curves (and its
//! distance field if asked), and its report printed.

use std::path::{Path, PathBuf};

use crate::contact::{ContactSurface, DistanceField, DistanceSettings};
use crate::pgd::{self, BuildReport};
use crate::report;
use crate::store::{self, BuildJob};
use serde::Serialize;

/// Builds `job`'s vademecum with progress bars and saves it at `out` with its convergence
/// curves beside it (named on stderr, so that `--json` output stays parseable), and its
/// distance field (`out` with `.vdf`) if asked.
pub fn build_vademecum(
    job: BuildJob,
    out: &Path,
    distance_field: bool,
) -> Result<BuildReport, String> {
    saved(store::build_and_save(job, out)?, out, distance_field)
}

/// What a build or a merge saved at `out`: its curves named, its distance field written if
/// asked; its report.
fn saved(
    (vademecum, report, curves): (pgd::Vademecum, BuildReport, [PathBuf; 2]),
    out: &Path,
    distance_field: bool,
) -> Result<BuildReport, String> {
    print_curves(curves);
    if distance_field {
        write_distance_field(&vademecum, &out.with_extension("vdf"))?;
    }
    Ok(report)
}

/// Joins the `parts` of `job`'s build into its vademecum at `out`, as [`build_vademecum`]
/// saves a whole build.
pub fn merge_vademecum(
    job: BuildJob,
    parts: Vec<pgd::PartFile>,
    out: &Path,
    distance_field: bool,
) -> Result<BuildReport, String> {
    let shards: f64 = parts.iter().map(|p| p.part.header.seconds).sum();
    let merged = store::merge_and_save(job, parts, out)?;
    eprintln!(
        "merged: the shards took {shards:.1} s together, the merge {:.1} s",
        merged.1.total_seconds
    );
    saved(merged, out, distance_field)
}

/// What `pgd build --shard` did.
#[derive(Serialize)]
pub struct PartReport {
    pub shard: String,
    pub file: PathBuf,
    /// The part's load positions, from and to (exclusive), of `total_positions`.
    pub positions: [usize; 2],
    pub total_positions: usize,
    pub nonlinear_steps: usize,
    pub seconds: f64,
    pub file_bytes: u64,
}

impl std::fmt::Display for PartReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "shard {}: load positions {} to {} of {} ({} nonlinear steps), {:.1} s; wrote {} \
             ({:.1} MB)",
            self.shard,
            self.positions[0],
            self.positions[1],
            self.total_positions,
            self.nonlinear_steps,
            self.seconds,
            self.file.display(),
            self.file_bytes as f64 / 1e6
        )?;
        writeln!(
            f,
            "join every shard's part with `pgd merge PART.vdp...` once all are written"
        )
    }
}

/// Computes shard `shard` of `job`'s build and writes its part: at `out` if it names a part
/// (`.vdp`), else beside the vademecum `out` ([`default_part`]).
pub fn build_part(
    job: BuildJob,
    shard: pgd::Shard,
    command: Vec<String>,
    out: &Path,
) -> Result<PartReport, String> {
    let file = match out.extension().is_some_and(|e| e == "vdp") {
        true => out.to_path_buf(),
        false => default_part(out, shard),
    };
    let header = store::build_part(job, shard, command, &file)?;
    Ok(PartReport {
        shard: shard.to_string(),
        positions: [header.positions.start, header.positions.end],
        total_positions: header.total_positions,
        nonlinear_steps: header.steps.len(),
        seconds: header.seconds,
        file_bytes: std::fs::metadata(&file).map_or(0, |m| m.len()),
        file,
    })
}

/// Where shard `shard` of the vademecum `out` is written unless named: `liver.vdm` gives
/// `liver.part-2-of-4.vdp`.
fn default_part(out: &Path, shard: pgd::Shard) -> PathBuf {
    out.with_extension(format!("part-{}-of-{}.vdp", shard.index, shard.count))
}

/// Writes the build's convergence curves beside the vademecum and names them on stderr.
pub fn write_convergence(vademecum: &Path, header: &pgd::Header) -> Result<(), String> {
    report::write_convergence_of(vademecum, header).map(print_curves)
}

fn print_curves([csv, png]: [PathBuf; 2]) {
    eprintln!(
        "convergence curves: {} and {}",
        csv.display(),
        png.display()
    );
}

/// Precomputes the distance field of `vademecum` on the default lattice and writes it.
pub fn write_distance_field(vademecum: &pgd::Vademecum, path: &Path) -> Result<(), String> {
    let started = std::time::Instant::now();
    let surface = ContactSurface::new(vademecum).map_err(|e| e.to_string())?;
    let field = DistanceField::build(vademecum, &surface, &DistanceSettings::default());
    field.save(path).map_err(|e| e.to_string())?;
    eprintln!(
        "distance field: {} lattice nodes, {} modes, built in {:.1} s, written to {}",
        field.node_count(),
        vademecum.total_modes(),
        started.elapsed().as_secs_f64(),
        path.display()
    );
    Ok(())
}

/// The build report as the terminal shows it.
pub fn print_build_report(report: &BuildReport, out: &Path) {
    println!(
        "{} load positions x 3 directions = {} parameters, {} free dofs; a load's near field \
         holds {:.1} % of the nodes on average",
        report.positions,
        report.parameters,
        report.free_dofs,
        100.0 * report.near_field_share
    );
    let loaded = report.positions_loaded;
    for (k, step) in report.steps.iter().enumerate() {
        let n = step.modes_kept;
        let pgd_error = step.curve.separated.last().copied().unwrap_or(f64::NAN);
        let optimal = step
            .curve
            .optimal
            .get(n.wrapping_sub(1))
            .copied()
            .unwrap_or(f64::NAN);
        println!(
            "step {k} (indentation {:.1} mm): {n} modes, global-part energy error {:.1} % \
             (optimal rank-{n}: {:.1} %, ratio {:.2})",
            step.indentation_m * 1e3,
            100.0 * pgd_error,
            100.0 * optimal,
            pgd_error / optimal
        );
        let field = |curve: &[f64]| curve.last().map_or(f64::NAN, |e| 100.0 * e);
        println!(
            "  vademecum field error (global + near field) of each node-centred load: {:.1} % \
             rms, {:.1} % p95",
            field(&step.curve.field),
            field(&step.curve.field_p95)
        );
        println!(
            "  time: PGD {:.1} s, brute force (solves + SVD) {:.1} s (PGD/brute force {:.2}), local part {:.1} s",
            step.pgd_seconds,
            step.brute_force_seconds,
            step.pgd_seconds / step.brute_force_seconds,
            step.local_seconds
        );
        if let Some(fixed_point) = &step.fixed_point {
            print_fixed_point(fixed_point);
            print_reached(step, loaded);
        }
    }
    if let Some(failed) = &report.failed_step {
        println!(
            "load step {:.1} mm left out: it reached too few positions (--min-reached-share), \
             the others' loads failing to converge even with Newton within --newton-budget \
             (the law loses stability under the tool, or the step is too far from the one \
             before); the load steps stop at {:.1} mm (the depth of one position's load \
             alone: the tissue stiffens no more once a position under the tool goes past its \
             range)",
            failed.indentation_m * 1e3,
            report.steps.last().map_or(0.0, |s| s.indentation_m * 1e3)
        );
        print_reached(failed, loaded);
        if let Some(fixed_point) = &failed.fixed_point {
            print_fixed_point(fixed_point);
        }
    }
    if let Some(baseline) = &report.newton_baseline {
        print_newton_baseline(baseline, report.total_seconds);
    }
    if let Some(cuts) = &report.cuts {
        print_cut_report(cuts);
    }
    println!(
        "wrote {} ({:.1} MB) in {:.1} s",
        out.display(),
        report.file_bytes as f64 / 1e6,
        report.total_seconds
    );
}

fn print_cut_report(cuts: &pgd::RegionReport) {
    println!(
        "cut section: {} load positions, {} modes, {:.0} near-field nodes per position; \
         field error of a unit load (modes + near field) {:.1} % mean, {:.1} % p95 over a \
         sample; built in {:.1} s (PGD {:.1} s, near field {:.1} s)",
        cuts.positions,
        cuts.modes,
        cuts.near_nodes_per_position,
        100.0 * cuts.sampled_error.mean,
        100.0 * cuts.sampled_error.p95,
        cuts.total_seconds,
        cuts.pgd_seconds,
        cuts.near_field_seconds
    );
}

fn print_newton_baseline(baseline: &pgd::NewtonBaseline, build_seconds: f64) {
    println!(
        "brute force: a Newton path per load to {:.1} mm (increments: {}) takes {:.1} s \
         (mean of {}, {} failed), so {:.0} s for all {} loads: {:.0}x this build's {:.0} s",
        baseline.deepest_m * 1e3,
        baseline.increments,
        baseline.seconds_per_load,
        baseline.samples,
        baseline.failed,
        baseline.estimated_seconds,
        baseline.loads,
        baseline.estimated_seconds / build_seconds,
        build_seconds
    );
}

/// How many of the `loaded` positions (all but those a clamp holds) reach `step`.
fn print_reached(step: &pgd::StepReport, loaded: usize) {
    if loaded == 0 {
        return; // a linear vademecum: no step presses any position
    }
    println!(
        "  range: {} of the {} loaded positions reach this step ({:.0} %)",
        step.positions_reached,
        loaded,
        100.0 * step.positions_reached as f64 / loaded as f64
    );
}

fn print_fixed_point(report: &pgd::SecantReport) {
    println!(
        "  secant fixed point: {:.1} iterations per load on average, at most {}; \
         {} loads solved through smaller increments, {} by Newton instead ({} left \
         over its budget), {} of {} unconverged (largest last residual {:.1e})",
        report.mean_iterations(),
        report.max_iterations,
        report.substep_solved,
        report.newton_solved,
        report.newton_over_budget,
        report.unconverged,
        report.responses,
        report.worst_change
    );
    let solves = &report.newton_solves;
    if report.newton_solved > 0 {
        println!(
            "  Newton: {:.1} s, {:.2} times the fixed point's cost in triangular solves; {} \
             directions by preconditioned conjugate gradients ({:.0} iterations each, {} cut \
             short at negative curvature), {} tangents factorized",
            report.newton_seconds,
            solves.cost_in_solves() / report.fixed_point_solves(),
            solves.directions,
            solves.iterations_per_direction(),
            solves.truncated,
            solves.factorizations
        );
    }
}
