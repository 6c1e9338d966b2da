//! The cutting benchmark: incisions added online to the cut state, segment by segment, against
//! the full X-FEM solve of the same cut after each segment, timed in the same run.
//!
//! The block is the cut-state test's (40 × 40 × 10 mm, clamped on one side): four incisions
//! of four segments each around a centre, one turning, made once over the exact uncut
//! response (the stiffness factorized) and once over a cut vademecum; the tool's felt force
//! (the haptic tick's cutting work) timed with 0, 4 and 16 segments present. Medians and p99;
//! each figure also as a ratio to the full X-FEM re-solve.

use std::time::Instant;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::fem::{median, quantile};
use crate::cutting::{CutState, Enrichment, ExactResponse, UncutResponse, tool_patch, xfem};
use crate::fem::{Dirichlet, FemModel, Law, Loads, Material, TISSUE_DENSITY_KG_M3};
use crate::mesh::box_mesh;
use crate::pgd::{RegionResponse, RegionSettings, RestStiffness, Silent};

const MM: f64 = 1e-3;

/// How one uncut response serves the cut state.
#[derive(Clone, Debug, Serialize)]
pub struct ResponseFigures {
    pub response: &'static str,
    /// Per segment (ms): the cut state's growth, median and p99.
    pub add_segment_ms: [f64; 2],
    /// Per segment (ms): its solve for the whole field, median.
    pub online_solve_ms: f64,
    /// The tool's felt force with 0, 4 and 16 segments present (µs): median and p99.
    pub tick_us: Vec<(usize, [f64; 2])>,
    /// The largest relative L2 difference from full X-FEM over the segments made.
    pub worst_difference: f64,
    /// The segment the cut state refused, and why (the figures are over those before it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failed: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct CuttingBenchReport {
    pub nodes: usize,
    pub segments: usize,
    /// Enriched unknowns of the condensed system at the end.
    pub unknowns: usize,
    /// The full X-FEM solve of the same cut after each segment (the baseline), median (ms).
    pub full_xfem_ms: f64,
    /// The cut vademecum's build (s): 20 mm deep under the top face, 6 mm near field.
    pub vademecum_build_s: f64,
    /// The exact response (the stiffness factorized), then the cut vademecum.
    pub responses: Vec<ResponseFigures>,
}

/// Felt-force evaluations timed per figure.
const TICKS: usize = 500;

/// Cuts the block `cells` fine (cubes along x, y, z) and times every segment, with the exact
/// uncut response and with a cut vademecum.
pub fn run(cells: [usize; 3]) -> Result<CuttingBenchReport, String> {
    let text = |e: &dyn std::fmt::Display| e.to_string();
    let mesh = box_mesh([40.0 * MM, 40.0 * MM, 10.0 * MM], cells).map_err(|e| text(&e))?;
    let clamped = mesh.node_set("x0").map_err(|e| text(&e))?.to_vec();
    let top = mesh.node_set("z1").map_err(|e| text(&e))?.to_vec();
    let top_faces = mesh.face_set("z1").map_err(|e| text(&e))?.to_vec();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(&clamped).map_err(|e| text(&e))?;
    let material =
        Material::new(Law::Linear, 1.6e3, 0.45, TISSUE_DENSITY_KG_M3).map_err(|e| text(&e))?;
    let model = FemModel::new(mesh, material, dirichlet).map_err(|e| text(&e))?;
    let mut loads = Loads::new(model.mesh().node_count());
    for &n in &top {
        loads
            .add_nodal_force(n, [1e-7, 0.0, -2e-7])
            .map_err(|e| text(&e))?;
    }
    let started = Instant::now();
    let stiffness = RestStiffness::new(&model).map_err(|e| text(&e))?;
    let settings = RegionSettings {
        depth_m: 20.0 * MM,
        near_radius_m: 6.0 * MM,
        modes: 40,
        patch_radius_m: None,
    };
    let region = RegionResponse::region_nodes(&stiffness, &top_faces, settings.depth_m);
    let (vademecum, _) =
        RegionResponse::build(&stiffness, &region, &settings, &Silent).map_err(|e| text(&e))?;
    let vademecum_build_s = started.elapsed().as_secs_f64();
    let exact = ExactResponse::new(&model).map_err(|e| text(&e))?;
    let patch = beside_the_incisions(&model, &top);
    let (exact, full, unknowns) = cut_with(&model, &loads, &patch, exact, "exact")?;
    let (vademecum, _, _) = cut_with(&model, &loads, &patch, vademecum, "cut vademecum")?;
    Ok(CuttingBenchReport {
        nodes: model.mesh().node_count(),
        segments: full.len(),
        unknowns,
        full_xfem_ms: median(full),
        vademecum_build_s,
        responses: vec![exact, vademecum],
    })
}

/// The incisions cut with `response`: its figures, the full X-FEM times and the unknowns.
fn cut_with<R: UncutResponse>(
    model: &FemModel,
    loads: &Loads,
    patch: &[(usize, f64)],
    response: R,
    name: &'static str,
) -> Result<(ResponseFigures, Vec<f64>, usize), String> {
    let mut state = CutState::new(model, response);
    let (mut add, mut online, mut full) = (vec![], vec![], vec![]);
    let mut tick_us = vec![(0, time_ticks(&state, patch)?)];
    let mut worst: f64 = 0.0;
    let mut failed = None;
    let ms = |since: Instant| since.elapsed().as_secs_f64() * 1e3;
    'cutting: for (cut, path) in incisions().into_iter().enumerate() {
        state.start(path[0], -Vector3::z(), 5.0 * MM);
        for &to in &path[1..] {
            let started = Instant::now();
            if let Err(why) = state.advance(cut, to) {
                failed = Some(format!("segment {}: {why}", add.len() + 1));
                break 'cutting;
            }
            add.push(ms(started));
            let started = Instant::now();
            let fast = state.solve(loads.as_slice()).map_err(|e| e.to_string())?;
            online.push(ms(started));
            let started = Instant::now();
            let enrichment = Enrichment::new(model.mesh(), state.faces());
            let exact = xfem::solve(model, &enrichment, loads).map_err(|e| e.to_string())?;
            full.push(ms(started));
            worst = worst.max(relative_l2(&fast.nodes_m, &exact.nodes_m));
            if add.len() == 4 || add.len() == 16 {
                tick_us.push((add.len(), time_ticks(&state, patch)?));
            }
        }
    }
    let figures = ResponseFigures {
        response: name,
        add_segment_ms: [quantile(&add, 0.5), quantile(&add, 0.99)],
        online_solve_ms: median(online),
        tick_us,
        worst_difference: worst,
        failed,
    };
    Ok((figures, full, state.unknowns()))
}

/// The felt force for a 1 mm press as the tick computes it, timed `TICKS` times (µs): median
/// and p99.
fn time_ticks<R: UncutResponse>(
    state: &CutState<&FemModel, R>,
    patch: &[(usize, f64)],
) -> Result<[f64; 2], String> {
    // The tick has the uncut compliance from the tool's vademecum: computed once here.
    let uncut = state.uncut_compliance(patch).map_err(|e| e.to_string())?;
    let mut samples = Vec::with_capacity(TICKS);
    for _ in 0..TICKS {
        let started = Instant::now();
        let force = state.felt_force_over(patch, uncut, Vector3::new(0.0, 0.0, -MM));
        samples.push(started.elapsed().as_secs_f64() * 1e6);
        std::hint::black_box(force);
    }
    Ok([quantile(&samples, 0.5), quantile(&samples, 0.99)])
}

/// The tool's patch: top nodes within 4 mm of a point beside the incisions' centre, weighted
/// as the trainer's kernel weighs them.
fn beside_the_incisions(model: &FemModel, top: &[usize]) -> Vec<(usize, f64)> {
    let positions: Vec<Point3<f64>> = top.iter().map(|&n| model.mesh().nodes()[n]).collect();
    let tool = Point3::new(24.0 * MM, 21.5 * MM, 10.0 * MM);
    tool_patch(top, &positions, tool, 4.0 * MM)
}

/// Four radial incisions from 4 to 13 mm around the block's top centre, four segments each;
/// the last turns on its way out.
fn incisions() -> Vec<Vec<Point3<f64>>> {
    let centre = Point3::new(24.0 * MM, 20.0 * MM, 10.0 * MM);
    (0..4)
        .map(|k| {
            let theta = std::f64::consts::FRAC_PI_2 * (k as f64 + 0.3);
            let radial = Vector3::new(theta.cos(), theta.sin(), 0.0);
            let at = |r_mm: f64| centre + radial * (r_mm * MM);
            let last = match k {
                3 => at(10.75) + Vector3::new(-radial.y, radial.x, 0.0) * (3.0 * MM),
                _ => at(13.0),
            };
            vec![at(4.0), at(6.25), at(8.5), at(10.75), last]
        })
        .collect()
}

fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm).sqrt()
}

impl std::fmt::Display for CuttingBenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "cutting benchmark: {} nodes, {} segments, {} enriched unknowns at the end; \
             full X-FEM solve per segment (baseline) {:.1} ms median; cut vademecum built in {:.1} s",
            self.nodes, self.segments, self.unknowns, self.full_xfem_ms, self.vademecum_build_s
        )?;
        writeln!(
            f,
            "{:<14} {:>22} {:>16} {:>36} {:>12}",
            "response",
            "add a segment (ms)",
            "cut field (ms)",
            "felt force, 0 / 4 / 16 segments (µs)",
            "vs X-FEM"
        )?;
        for r in &self.responses {
            let ticks: Vec<String> = r
                .tick_us
                .iter()
                .map(|(_, [p50, p99])| format!("{p50:.0} (p99 {p99:.0})"))
                .collect();
            writeln!(
                f,
                "{:<14} {:>8.3} (p99 {:>6.3}) {:>16.3} {:>36} {:>12.1e}",
                r.response,
                r.add_segment_ms[0],
                r.add_segment_ms[1],
                r.online_solve_ms,
                ticks.join(" / "),
                r.worst_difference
            )?;
            if let Some(why) = &r.failed {
                writeln!(f, "{:<14} refused {why}", r.response)?;
            }
        }
        writeln!(
            f,
            "ratios to the baseline: add a segment {}",
            self.responses
                .iter()
                .map(|r| format!(
                    "{} {:.3}×",
                    r.response,
                    r.add_segment_ms[0] / self.full_xfem_ms
                ))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}
