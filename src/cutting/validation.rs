//! A cut vademecum against the full X-FEM solve of the same cut, on the cornea: radial
//! incisions at random angles, optical zones and depths the builder never saw, added online
//! segment by segment, then the displacement under the intraocular pressure and the force felt
//! by a tool beside an incision compared with the reference.

use std::time::Instant;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::enrichment::Enrichment;
use super::keratotomy::{Cornea, INCISION_END_M, anterior_nodes, incision};
use super::response::{ExactResponse, Response, UncutResponse};
use super::state::CutState;
use super::{CutError, xfem};
use crate::mesh::organs::{CORNEA_CURVATURE_M, CORNEA_THICKNESS_M};
use crate::pgd::Statistics;

/// What to cut and how often.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutValidationSettings {
    /// Radial incisions per pattern.
    pub incisions: usize,
    /// Patterns drawn.
    pub samples: usize,
    pub seed: u64,
    /// Segments each incision is made in, from the optical zone outwards.
    pub segments: usize,
}

impl Default for CutValidationSettings {
    fn default() -> Self {
        Self {
            incisions: 4,
            samples: 5,
            seed: 1,
            segments: 3,
        }
    }
}

/// One random pattern and how the cut vademecum did on it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CutCase {
    pub angles_deg: Vec<f64>,
    pub optical_zone_mm: f64,
    pub depth_fraction: f64,
    /// Enriched unknowns of the finished pattern.
    pub unknowns: usize,
    /// Relative L2 error of the displacement field under the intraocular pressure.
    pub cut_l2_error: f64,
    /// Relative error of the force felt by a tool pressing beside an incision.
    pub force_error: f64,
    /// Why the cut state could not serve the pattern (its errors are then not counted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failed: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CutValidationReport {
    pub pattern: String,
    pub nodes: usize,
    /// Patterns the cut state refused (a clean error each, named in its case).
    pub failed: usize,
    /// Over the patterns served.
    pub cut_l2_error: Statistics,
    pub force_error: Statistics,
    /// Time to add one incision segment online (ms).
    pub segment_ms: Statistics,
    /// Time of the full X-FEM solve of a finished pattern (ms): the baseline.
    pub full_xfem_ms: Statistics,
    pub cases: Vec<CutCase>,
}

/// The tool pressing beside an incision: the cornea's 0.5 mm spatula, 0.3 mm off the cut's
/// plane, pressed 20 µm in.
const TOOL_RADIUS_M: f64 = 0.5e-3;
const TOOL_OFFSET_M: f64 = 0.3e-3;
const PRESS_M: f64 = 20e-6;

/// Draws `settings.samples` radial keratotomies and compares `response`'s cut state with the
/// full X-FEM solve of each.
pub fn validate_keratotomy(
    cornea: &Cornea,
    response: &impl UncutResponse,
    settings: &CutValidationSettings,
) -> Result<CutValidationReport, CutError> {
    if settings.incisions == 0 || settings.segments == 0 {
        return Err(CutError::Degenerate(
            "a pattern of no incision, or incisions of no segment".into(),
        ));
    }
    let pressure = standing_response(cornea)?;
    let mut rng = fastrand::Rng::with_seed(settings.seed);
    let (mut cases, mut segment_ms, mut full_ms) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..settings.samples {
        let plan = draw(&mut rng, settings.incisions);
        let mut timings = (&mut segment_ms, &mut full_ms);
        cases.push(
            run_case(
                cornea,
                (response, &pressure),
                &plan,
                settings.segments,
                &mut timings,
            )
            .unwrap_or_else(|why| CutCase {
                failed: Some(why.to_string()),
                ..plan
            }),
        );
    }
    let served = || cases.iter().filter(|c| c.failed.is_none());
    Ok(CutValidationReport {
        pattern: format!("radial:{}", settings.incisions),
        nodes: cornea.model().mesh().node_count(),
        failed: cases.len() - served().count(),
        cut_l2_error: Statistics::of(served().map(|c| c.cut_l2_error)),
        force_error: Statistics::of(served().map(|c| c.force_error)),
        segment_ms: Statistics::of(segment_ms.into_iter()),
        full_xfem_ms: Statistics::of(full_ms.into_iter()),
        cases,
    })
}

/// The uncut cornea's displacement under the intraocular pressure, exactly: a standing load
/// is solved once, offline, not composed from unit responses.
fn standing_response(cornea: &Cornea) -> Result<Response, CutError> {
    let exact = ExactResponse::new(cornea.model()).map_err(|e| CutError::Solve(e.to_string()))?;
    let load: Vec<(usize, f64)> = cornea
        .pressure()
        .as_slice()
        .iter()
        .enumerate()
        .filter(|(_, f)| **f != 0.0)
        .map(|(d, &f)| (d, f))
        .collect();
    Ok(exact.respond(&[load])?.remove(0))
}

/// A random pattern: angles spread round the axis with a random turn and jitter (a quarter
/// of their spacing, so that no two incisions share an element), an optical zone of 3–5 mm,
/// a depth of 60–95 % of the thickness.
fn draw(rng: &mut fastrand::Rng, incisions: usize) -> CutCase {
    let spacing = std::f64::consts::TAU / incisions as f64;
    let turn = rng.f64() * spacing;
    CutCase {
        angles_deg: (0..incisions)
            .map(|k| (turn + spacing * (k as f64 + 0.25 * (rng.f64() - 0.5))).to_degrees())
            .collect(),
        optical_zone_mm: 3.0 + 2.0 * rng.f64(),
        depth_fraction: 0.6 + 0.35 * rng.f64(),
        unknowns: 0,
        cut_l2_error: 0.0,
        force_error: 0.0,
        failed: None,
    }
}

/// Cuts `plan` segment by segment, timing each, and compares the finished cut.
fn run_case(
    cornea: &Cornea,
    (response, pressure): (&impl UncutResponse, &Response),
    plan: &CutCase,
    segments: usize,
    (segment_ms, full_ms): &mut (&mut Vec<f64>, &mut Vec<f64>),
) -> Result<CutCase, CutError> {
    let model = cornea.model();
    let mut state = CutState::new(model, response);
    let from = plan.optical_zone_mm * 0.5e-3;
    for &angle in &plan.angles_deg {
        let reach = |k: usize| {
            (
                from,
                from + (INCISION_END_M - from) * k as f64 / segments as f64,
            )
        };
        let face = |k| incision(angle.to_radians(), reach(k), plan.depth_fraction);
        let clock = Instant::now();
        let id = state.add_face(face(1)?)?;
        segment_ms.push(clock.elapsed().as_secs_f64() * 1e3);
        for k in 2..=segments {
            let clock = Instant::now();
            state.lengthen(id, face(k)?)?;
            segment_ms.push(clock.elapsed().as_secs_f64() * 1e3);
        }
    }
    let enrichment = Enrichment::new(model.mesh(), state.faces());
    let clock = Instant::now();
    let full = xfem::solve(model, &enrichment, cornea.pressure())?;
    full_ms.push(clock.elapsed().as_secs_f64() * 1e3);
    let online = state.solve_from(pressure.clone());
    let (patch, press) = tool_beside(cornea, plan.angles_deg[0].to_radians(), from);
    let felt = state.felt_force(&patch, press)?;
    let reference = xfem::felt_force(model, &enrichment, &patch, press)?;
    let force_error = match (felt, reference) {
        (Some(felt), Some(reference)) => (felt - reference).norm() / reference.norm(),
        _ => f64::INFINITY,
    };
    Ok(CutCase {
        unknowns: state.unknowns(),
        cut_l2_error: relative_l2(&online.nodes_m, &full.nodes_m),
        force_error,
        ..plan.clone()
    })
}

/// The tool's patch beside the incision at `angle_rad` (halfway along it, `TOOL_OFFSET_M`
/// off its plane) on the anterior face, with shares falling smoothly to zero at its rim, and
/// its press along the inward normal.
fn tool_beside(cornea: &Cornea, angle_rad: f64, from_m: f64) -> (Vec<(usize, f64)>, Vector3<f64>) {
    let mesh = cornea.model().mesh();
    let r = 0.5 * (from_m + INCISION_END_M);
    let turned = angle_rad + TOOL_OFFSET_M / r;
    let centre = Point3::new(0.0, 0.0, -CORNEA_CURVATURE_M);
    let anterior = CORNEA_CURVATURE_M + CORNEA_THICKNESS_M / 2.0;
    let z = (anterior * anterior - r * r).sqrt() - CORNEA_CURVATURE_M;
    let tool = Point3::new(r * turned.cos(), r * turned.sin(), z);
    let mut patch: Vec<(usize, f64)> = anterior_nodes(mesh)
        .into_iter()
        .map(|n| (n, (mesh.nodes()[n] - tool).norm() / TOOL_RADIUS_M))
        .filter(|&(_, d)| d < 1.0)
        .map(|(n, d)| (n, (1.0 - d * d).powi(2)))
        .collect();
    let total: f64 = patch.iter().map(|p| p.1).sum();
    patch.iter_mut().for_each(|p| p.1 /= total);
    let inward = (centre - tool).normalize();
    (patch, inward * PRESS_M)
}

/// `‖a − b‖ / ‖b‖`.
fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm.max(f64::MIN_POSITIVE)).sqrt()
}
