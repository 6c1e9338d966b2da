//! The cutting benchmark: incisions added online to the cut state, segment by segment, against
//! the full X-FEM solve of the same cut after each segment, timed in the same run.
//!
//! The block is the cut-state test's (40 × 40 × 10 mm, clamped on one side): four incisions
//! of three segments each around a centre, one turning. Medians over the segments; each
//! figure also as a ratio to the full X-FEM re-solve.

use std::time::Instant;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::fem::median;
use crate::cutting::{CutError, CutState, Enrichment, ExactResponse, xfem};
use crate::fem::{Dirichlet, FemModel, Law, Loads, Material, TISSUE_DENSITY_KG_M3};
use crate::mesh::box_mesh;

const MM: f64 = 1e-3;

#[derive(Clone, Debug, Serialize)]
pub struct CuttingBenchReport {
    pub nodes: usize,
    pub segments: usize,
    /// Enriched unknowns of the condensed system at the end.
    pub unknowns: usize,
    /// Per segment, medians (ms): the cut state's growth, its solve for the whole field,
    /// and the full X-FEM solve of the same cut (the baseline).
    pub add_segment_ms: f64,
    pub online_solve_ms: f64,
    pub full_xfem_ms: f64,
    /// The largest relative L2 difference of the two fields over the segments.
    pub worst_difference: f64,
}

/// Cuts the block `cells` fine (cubes along x, y, z) and times every segment.
pub fn run(cells: [usize; 3]) -> Result<CuttingBenchReport, String> {
    let mesh = box_mesh([40.0 * MM, 40.0 * MM, 10.0 * MM], cells).map_err(|e| e.to_string())?;
    let clamped = mesh.node_set("x0").map_err(|e| e.to_string())?.to_vec();
    let top = mesh.node_set("z1").map_err(|e| e.to_string())?.to_vec();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(&clamped).map_err(|e| e.to_string())?;
    let material =
        Material::new(Law::Linear, 1.6e3, 0.45, TISSUE_DENSITY_KG_M3).map_err(|e| e.to_string())?;
    let model = FemModel::new(mesh, material, dirichlet).map_err(|e| e.to_string())?;
    let mut loads = Loads::new(model.mesh().node_count());
    for &n in &top {
        loads
            .add_nodal_force(n, [1e-7, 0.0, -2e-7])
            .map_err(|e| e.to_string())?;
    }
    let response = ExactResponse::new(&model).map_err(|e| e.to_string())?;
    let mut state = CutState::new(&model, response);
    let (mut add, mut online, mut full) = (vec![], vec![], vec![]);
    let mut worst: f64 = 0.0;
    let ms = |since: Instant| since.elapsed().as_secs_f64() * 1e3;
    for (cut, path) in incisions().into_iter().enumerate() {
        state.start(path[0], -Vector3::z(), 5.0 * MM);
        for &to in &path[1..] {
            let started = Instant::now();
            state
                .advance(cut, to)
                .map_err(|e: CutError| e.to_string())?;
            add.push(ms(started));
            let started = Instant::now();
            let fast = state.solve(loads.as_slice()).map_err(|e| e.to_string())?;
            online.push(ms(started));
            let started = Instant::now();
            let enrichment = Enrichment::new(model.mesh(), state.faces());
            let exact = xfem::solve(&model, &enrichment, &loads).map_err(|e| e.to_string())?;
            full.push(ms(started));
            worst = worst.max(relative_l2(&fast.nodes_m, &exact.nodes_m));
        }
    }
    Ok(CuttingBenchReport {
        nodes: model.mesh().node_count(),
        segments: add.len(),
        unknowns: state.unknowns(),
        add_segment_ms: median(add),
        online_solve_ms: median(online),
        full_xfem_ms: median(full),
        worst_difference: worst,
    })
}

/// Four radial incisions from 4 to 13 mm around the block's top centre, three segments each;
/// the last turns on its way out.
fn incisions() -> Vec<Vec<Point3<f64>>> {
    let centre = Point3::new(24.0 * MM, 20.0 * MM, 10.0 * MM);
    (0..4)
        .map(|k| {
            let theta = std::f64::consts::FRAC_PI_2 * (k as f64 + 0.3);
            let radial = Vector3::new(theta.cos(), theta.sin(), 0.0);
            let at = |r_mm: f64| centre + radial * (r_mm * MM);
            let last = match k {
                3 => at(10.0) + Vector3::new(-radial.y, radial.x, 0.0) * (3.0 * MM),
                _ => at(13.0),
            };
            vec![at(4.0), at(7.0), at(10.0), last]
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
            "cutting benchmark: {} nodes, {} segments, {} enriched unknowns at the end; medians per segment",
            self.nodes, self.segments, self.unknowns
        )?;
        let ratio = |ms: f64| ms / self.full_xfem_ms;
        for (name, ms) in [
            ("add a segment (cut state)", self.add_segment_ms),
            ("solve the cut field (cut state)", self.online_solve_ms),
            ("full X-FEM solve (baseline)", self.full_xfem_ms),
        ] {
            writeln!(f, "{name:<34} {ms:>10.3} ms {:>8.3} × baseline", ratio(ms))?;
        }
        writeln!(
            f,
            "largest relative L2 difference of the fields: {:.1e}",
            self.worst_difference
        )
    }
}
