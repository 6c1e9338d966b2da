//! The vademecum benchmark: build time and peak memory of an organ's vademecum (linear and
//! KSV), and the online evaluations the haptic loop makes — the displacement under the tool,
//! the felt force for an indentation, and one organ's whole displacement field.
//!
//! Online figures are medians over batches of random surface points, each also given as a
//! ratio to the full-FEM answer to the same question measured in the same run: one solve with
//! the stiffness already factorized (the cheapest any direct method can be online).

use std::time::Instant;

use nalgebra::Vector3;
use serde::Serialize;

use super::fem::{Timing, median_ms};
use crate::fem::{FemError, FemModel, Law};
use crate::mesh::organs::{self, Organ, OrganSettings, region};
use crate::pgd::{self, BuildSettings, OrganModel, RestStiffness, Silent, SurfacePoint, Vademecum};

/// Evaluations per timed batch: enough to rise well above the clock's resolution.
const BATCH: usize = 200;

#[derive(Clone, Debug, Serialize)]
pub struct BuildFigures {
    pub law: Law,
    pub build_seconds: f64,
    pub brute_force_seconds: f64,
    pub pgd_seconds: f64,
    /// PGD time over brute-force time (exact responses + their SVD), summed over load steps.
    pub pgd_to_brute_force: f64,
    /// Peak resident memory of the process once this build is done (MB).
    pub peak_resident_mb: Option<f64>,
    pub modes_per_step: Vec<usize>,
    pub valid_indentation_mm: f64,
    pub file_megabytes: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct VademecumBenchReport {
    pub organ: &'static str,
    pub nodes: usize,
    pub tets: usize,
    pub positions: usize,
    pub builds: Vec<BuildFigures>,
    pub repeats: usize,
    pub baseline: &'static str,
    /// Per call (ms), median over batches of random surface points.
    pub online: Vec<Timing>,
}

/// Builds `organ`'s vademecum with each of `laws` (once each: a build takes minutes), then
/// times the online evaluations on the first.
pub fn run(organ: Organ, laws: &[Law], repeats: usize) -> Result<VademecumBenchReport, FemError> {
    let mesh = organs::generate(organ, &OrganSettings::default())?;
    let (nodes, tets) = (mesh.node_count(), mesh.tet_count());
    let mut builds = Vec::new();
    let mut first: Option<(Vademecum, FemModel)> = None;
    for &law in laws {
        let model = pgd::organ::clamped_model(mesh.clone(), pgd::organ::material(organ, law))?;
        let organ_model = OrganModel {
            source: organ.name().into(),
            model: &model,
            clamped_region: region::CLAMPED.into(),
            accessible_region: region::ACCESSIBLE.into(),
        };
        let started = Instant::now();
        let (vademecum, report) = pgd::build(
            &organ_model,
            &BuildSettings::for_organ_law(Some(organ), law),
            &Silent,
        )?;
        let build_seconds = started.elapsed().as_secs_f64();
        let sum = |f: fn(&pgd::StepReport) -> f64| report.steps.iter().map(f).sum::<f64>();
        let (brute, pgd_s) = (sum(|s| s.brute_force_seconds), sum(|s| s.pgd_seconds));
        builds.push(BuildFigures {
            law,
            build_seconds,
            brute_force_seconds: brute,
            pgd_seconds: pgd_s,
            pgd_to_brute_force: pgd_s / brute,
            peak_resident_mb: peak_resident_mb(),
            modes_per_step: vademecum.header.modes_per_step.clone(),
            valid_indentation_mm: vademecum.valid_indentation_m() * 1e3,
            file_megabytes: pgd::encode(&vademecum).len() as f64 / 1e6,
        });
        if first.is_none() {
            first = Some((vademecum, model));
        }
    }
    let (vademecum, model) = first.expect("at least one law");
    let online = online_timings(&vademecum, &model, repeats.max(1))?;
    Ok(VademecumBenchReport {
        organ: organ.name(),
        nodes,
        tets,
        positions: vademecum.positions.len(),
        builds,
        repeats: repeats.max(1),
        baseline: "one full-FEM solve, stiffness already factorized",
        online,
    })
}

fn online_timings(
    vademecum: &Vademecum,
    model: &FemModel,
    repeats: usize,
) -> Result<Vec<Timing>, FemError> {
    let stiffness = RestStiffness::new(model)?;
    let mut rng = fastrand::Rng::with_seed(11);
    let points: Vec<SurfacePoint> = (0..BATCH)
        .map(|_| random_point(&mut rng, vademecum))
        .collect();
    let force_n = Vector3::new(0.0, 0.0, -0.05);
    let indentation_m = Vector3::new(0.0, 0.0, -5e-3);
    let mut rhs = vec![0.0; stiffness.free_count()];
    let mut medians: Vec<(&'static str, f64)> = Vec::new();
    let mut time = |name: &'static str, f: &mut dyn FnMut(&SurfacePoint)| {
        let batch = median_ms(repeats, &mut || points.iter().for_each(&mut *f));
        medians.push((name, batch / BATCH as f64));
    };
    time("full FEM solve (baseline)", &mut |_| {
        rhs.iter_mut().for_each(|v| *v = 0.0);
        rhs[0] = 1.0;
        stiffness.solve_block(&mut rhs);
    });
    time("displacement under the tool", &mut |at| {
        std::hint::black_box(vademecum.tool_displacement(at, &force_n));
    });
    time("felt force for an indentation", &mut |at| {
        std::hint::black_box(vademecum.force_for_indentation(at, &indentation_m));
    });
    time("whole displacement field", &mut |at| {
        std::hint::black_box(vademecum.field(at, &force_n));
    });
    let bytes = pgd::encode(vademecum);
    let load_ms = median_ms(repeats, &mut || {
        pgd::decode(std::path::Path::new("benchmark"), &bytes).expect("encoded above");
    });
    medians.push(("load the file (decode + checksum)", load_ms));
    let baseline = medians[0].1;
    Ok(medians
        .into_iter()
        .map(|(name, median_ms)| Timing {
            name,
            median_ms,
            ratio_to_baseline: median_ms / baseline,
        })
        .collect())
}

/// A random point inside a random accessible triangle.
fn random_point(rng: &mut fastrand::Rng, vademecum: &Vademecum) -> SurfacePoint {
    let (mut a, mut b) = (rng.f64(), rng.f64());
    if a + b > 1.0 {
        (a, b) = (1.0 - a, 1.0 - b);
    }
    SurfacePoint {
        triangle: rng.usize(..vademecum.triangles.len()),
        barycentric: [1.0 - a - b, a, b],
    }
}

/// The process's peak resident memory (MB), where the system reports it (Linux).
fn peak_resident_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1e3)
}

impl std::fmt::Display for VademecumBenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "Vademecum benchmark: {} ({} nodes, {} tets, {} load positions)",
            self.organ, self.nodes, self.tets, self.positions
        )?;
        for b in &self.builds {
            writeln!(
                f,
                "build {:?}: {:.1} s (brute force {:.1} s, PGD {:.1} s, PGD/brute force {:.2}), \
                 peak memory {}, modes per step {:?}, steps to {:.1} mm, {:.1} MB",
                b.law,
                b.build_seconds,
                b.brute_force_seconds,
                b.pgd_seconds,
                b.pgd_to_brute_force,
                b.peak_resident_mb
                    .map_or_else(|| "n/a".into(), |m| format!("{m:.0} MB")),
                b.modes_per_step,
                b.valid_indentation_mm,
                b.file_megabytes
            )?;
        }
        writeln!(
            f,
            "online, per call (medians of {} batches of {BATCH} random points):",
            self.repeats
        )?;
        writeln!(
            f,
            "{:<32} {:>12} {:>14}",
            "evaluation", "median (µs)", "× FEM solve"
        )?;
        for t in &self.online {
            writeln!(
                f,
                "{:<32} {:>12.2} {:>14.4}",
                t.name,
                t.median_ms * 1e3,
                t.ratio_to_baseline
            )?;
        }
        Ok(())
    }
}
