//! The cut state against the full X-FEM solve of the same cut, on patterns drawn at random:
//! radial keratotomies of the cornea (random angles, optical zones and depths) under the
//! intraocular pressure, or straight incisions into an organ's accessible face (the liver's)
//! under the tool. Each incision is made online in lengthening segments, then the field and
//! the force felt by a tool beside an incision are compared with the reference.

use std::time::Instant;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::enrichment::Enrichment;
use super::incision::CutFace;
use super::keratotomy::{ANTERIOR_RADIUS_M, Cornea, INCISION_END_M, anterior_nodes, incision};
use super::response::{ExactResponse, UncutResponse, sparse_load};
use super::state::CutState;
use super::{CutError, xfem};
use crate::fem::{FemModel, Loads, patch_weight};
use crate::mesh::organs::{CORNEA_CURVATURE_M, region};
use crate::mesh::{Surface, TetMesh};
use crate::pgd::Statistics;

/// The patterns drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CutPattern {
    /// N radial incisions of the cornea.
    Radial(usize),
    /// N straight incisions into the accessible face.
    Straight(usize),
}

impl std::fmt::Display for CutPattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CutPattern::Radial(n) => write!(f, "radial:{n}"),
            CutPattern::Straight(n) => write!(f, "straight:{n}"),
        }
    }
}

/// What to cut and how often.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutValidationSettings {
    pub pattern: CutPattern,
    /// Patterns drawn.
    pub samples: usize,
    pub seed: u64,
    /// Segments each incision is made in.
    pub segments: usize,
    /// How far a compressed response's patches reach (m); `None` for the cut state's default.
    pub patch_radius_m: Option<f64>,
}

impl Default for CutValidationSettings {
    fn default() -> Self {
        Self {
            pattern: CutPattern::Radial(4),
            samples: 5,
            seed: 1,
            segments: 3,
            patch_radius_m: None,
        }
    }
}

/// One random pattern and how the cut state did on it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CutCase {
    /// What was cut, in words.
    pub pattern: String,
    /// Enriched unknowns of the finished pattern.
    pub unknowns: usize,
    /// Relative L2 error of the displacement field under the pattern's load.
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

/// A drawn pattern, ready to cut: each incision as its face after every segment, the load
/// and the tool beside the first incision.
struct Plan {
    description: String,
    incisions: Vec<Vec<CutFace>>,
    loads: Loads,
    patch: Vec<(usize, f64)>,
    press_m: Vector3<f64>,
}

/// The cornea's tool: a 0.5 mm spatula 0.3 mm off the incision's plane, pressed 20 µm.
const CORNEA_TOOL_M: (f64, f64, f64) = (0.5e-3, 0.3e-3, 20e-6);
/// An organ's: a 6 mm tip 5 mm beside the incision, pressed 2 mm (its field loaded by 1 N);
/// incisions 20 mm long and 10 mm deep.
const ORGAN_TOOL_M: (f64, f64, f64) = (6e-3, 5e-3, 2e-3);
const INCISION_LENGTH_M: f64 = 20e-3;
const INCISION_DEPTH_M: f64 = 10e-3;

/// Draws radial keratotomies (`settings.pattern` must be radial) and compares `response`'s
/// cut state with the full X-FEM solve of each, under the intraocular pressure.
pub fn validate_keratotomy(
    cornea: &Cornea,
    response: &impl UncutResponse,
    settings: &CutValidationSettings,
) -> Result<CutValidationReport, CutError> {
    let CutPattern::Radial(incisions) = settings.pattern else {
        return Err(CutError::Degenerate(format!(
            "{}: the cornea is cut by radial:N patterns",
            settings.pattern
        )));
    };
    check(incisions, settings)?;
    let mut rng = fastrand::Rng::with_seed(settings.seed);
    let plans = (0..settings.samples)
        .map(|_| radial_plan(cornea, &mut rng, incisions, settings.segments))
        .collect();
    validate(cornea.model(), response, settings, plans)
}

/// Draws straight incisions into `model`'s accessible face and compares `response`'s cut
/// state with the full X-FEM solve of each, under the tool pressing beside the first.
pub fn validate_incisions(
    model: &FemModel,
    response: &impl UncutResponse,
    settings: &CutValidationSettings,
) -> Result<CutValidationReport, CutError> {
    let CutPattern::Straight(incisions) = settings.pattern else {
        return Err(CutError::Degenerate(format!(
            "{}: an organ is cut by straight:N patterns",
            settings.pattern
        )));
    };
    check(incisions, settings)?;
    let site = AccessibleFace::new(model.mesh())?;
    let mut rng = fastrand::Rng::with_seed(settings.seed);
    let plans = (0..settings.samples)
        .map(|_| site.plan(&mut rng, incisions, settings.segments))
        .collect();
    validate(model, response, settings, plans)
}

fn check(incisions: usize, settings: &CutValidationSettings) -> Result<(), CutError> {
    if incisions == 0 || settings.segments == 0 {
        return Err(CutError::Degenerate(
            "a pattern of no incision, or incisions of no segment".into(),
        ));
    }
    Ok(())
}

/// Runs every plan; a plan the cut state refuses is a failed case, not an error.
fn validate(
    model: &FemModel,
    response: &impl UncutResponse,
    settings: &CutValidationSettings,
    plans: Vec<Result<Plan, CutError>>,
) -> Result<CutValidationReport, CutError> {
    let exact = ExactResponse::new(model).map_err(|e| CutError::Solve(e.to_string()))?;
    let (mut cases, mut segment_ms, mut full_ms) = (Vec::new(), Vec::new(), Vec::new());
    for plan in plans {
        let plan = plan?;
        let mut timings = (&mut segment_ms, &mut full_ms);
        let outcome = run_case(model, (response, &exact), settings, &plan, &mut timings);
        cases.push(outcome.unwrap_or_else(|why| CutCase {
            pattern: plan.description.clone(),
            unknowns: 0,
            cut_l2_error: 0.0,
            force_error: 0.0,
            failed: Some(why.to_string()),
        }));
    }
    let served = || cases.iter().filter(|c| c.failed.is_none());
    Ok(CutValidationReport {
        pattern: settings.pattern.to_string(),
        nodes: model.mesh().node_count(),
        failed: cases.len() - served().count(),
        cut_l2_error: Statistics::of(served().map(|c| c.cut_l2_error)),
        force_error: Statistics::of(served().map(|c| c.force_error)),
        segment_ms: Statistics::of(segment_ms.into_iter()),
        full_xfem_ms: Statistics::of(full_ms.into_iter()),
        cases,
    })
}

/// Cuts `plan` segment by segment, timing each, and compares the finished cut. The uncut
/// parts come exact, as the trainer has them (the intraocular pressure's field solved once,
/// the tool's patch compliance from its vademecum's exact local part): the errors are the
/// cut's alone, whatever `response` is.
fn run_case(
    model: &FemModel,
    (response, exact): (&impl UncutResponse, &ExactResponse),
    settings: &CutValidationSettings,
    plan: &Plan,
    (segment_ms, full_ms): &mut (&mut Vec<f64>, &mut Vec<f64>),
) -> Result<CutCase, CutError> {
    let mut state = CutState::new(model, response);
    if let Some(radius_m) = settings.patch_radius_m {
        state = state.with_patch_radius(radius_m);
    }
    for faces in &plan.incisions {
        let clock = Instant::now();
        let id = state.add_face(faces[0])?;
        segment_ms.push(clock.elapsed().as_secs_f64() * 1e3);
        for &face in &faces[1..] {
            let clock = Instant::now();
            state.lengthen(id, face)?;
            segment_ms.push(clock.elapsed().as_secs_f64() * 1e3);
        }
    }
    let enrichment = Enrichment::new(model.mesh(), state.faces());
    let clock = Instant::now();
    let full = xfem::solve(model, &enrichment, &plan.loads)?;
    full_ms.push(clock.elapsed().as_secs_f64() * 1e3);
    let uncut = exact
        .respond(&[sparse_load(plan.loads.as_slice())])?
        .remove(0);
    let online = state.solve_from(uncut);
    let compliance = CutState::new(model, exact).uncut_compliance(&plan.patch)?;
    let felt = state.felt_force_over(&plan.patch, compliance, plan.press_m);
    let reference = xfem::felt_force(model, &enrichment, &plan.patch, plan.press_m)?;
    let force_error = match (felt, reference) {
        (Some(felt), Some(reference)) => (felt - reference).norm() / reference.norm(),
        _ => f64::INFINITY,
    };
    Ok(CutCase {
        pattern: plan.description.clone(),
        unknowns: state.unknowns(),
        cut_l2_error: relative_l2(&online.nodes_m, &full.nodes_m),
        force_error,
        failed: None,
    })
}

/// A radial keratotomy: angles spread round the axis with a random turn and jitter (a quarter
/// of their spacing, so that no two incisions share an element), an optical zone of 3–5 mm, a
/// depth of 60–95 % of the thickness; each incision lengthening outwards.
fn radial_plan(
    cornea: &Cornea,
    rng: &mut fastrand::Rng,
    incisions: usize,
    segments: usize,
) -> Result<Plan, CutError> {
    let spacing = std::f64::consts::TAU / incisions as f64;
    let turn = rng.f64() * spacing;
    let angles: Vec<f64> = (0..incisions)
        .map(|k| turn + spacing * (k as f64 + 0.25 * (rng.f64() - 0.5)))
        .collect();
    let (zone_m, depth_fraction) = (3e-3 + 2e-3 * rng.f64(), 0.6 + 0.35 * rng.f64());
    let from = zone_m / 2.0;
    let faces = angles
        .iter()
        .map(|&angle| {
            (1..=segments)
                .map(|k| {
                    let to = from + (INCISION_END_M - from) * k as f64 / segments as f64;
                    incision(angle, (from, to), depth_fraction)
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    let (patch, press_m) = cornea_tool(cornea, angles[0], from);
    let degrees: Vec<String> = angles
        .iter()
        .map(|a| format!("{:.0}°", a.to_degrees()))
        .collect();
    Ok(Plan {
        description: format!(
            "incisions at {}, optical zone {:.1} mm, {:.0} % deep",
            degrees.join(", "),
            zone_m * 1e3,
            100.0 * depth_fraction
        ),
        incisions: faces,
        loads: cornea.pressure().clone(),
        patch,
        press_m,
    })
}

/// The spatula beside the incision at `angle_rad`, halfway along it, pressing along the
/// inward normal of the anterior sphere.
fn cornea_tool(cornea: &Cornea, angle_rad: f64, from_m: f64) -> (Vec<(usize, f64)>, Vector3<f64>) {
    let mesh = cornea.model().mesh();
    let (radius_m, offset_m, press_m) = CORNEA_TOOL_M;
    let r = 0.5 * (from_m + INCISION_END_M);
    let turned = angle_rad + offset_m / r;
    let z = (ANTERIOR_RADIUS_M * ANTERIOR_RADIUS_M - r * r).sqrt() - CORNEA_CURVATURE_M;
    let tool = Point3::new(r * turned.cos(), r * turned.sin(), z);
    let centre = Point3::new(0.0, 0.0, -CORNEA_CURVATURE_M);
    let nodes = anterior_nodes(mesh);
    let positions: Vec<Point3<f64>> = nodes.iter().map(|&n| mesh.nodes()[n]).collect();
    let patch = tool_patch(&nodes, &positions, tool, radius_m);
    (patch, (centre - tool).normalize() * press_m)
}

/// An organ's accessible face: its nodes and their outward normals.
struct AccessibleFace {
    nodes: Vec<usize>,
    normals: Vec<Vector3<f64>>,
    positions: Vec<Point3<f64>>,
    node_count: usize,
}

impl AccessibleFace {
    fn new(mesh: &TetMesh) -> Result<Self, CutError> {
        let faces = mesh
            .face_set(region::ACCESSIBLE)
            .map_err(|e| CutError::Degenerate(e.to_string()))?;
        let mut nodes: Vec<usize> = faces.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        if nodes.is_empty() {
            return Err(CutError::Degenerate("no accessible face to cut".into()));
        }
        let surface = Surface::extract(mesh);
        let normals_by_vertex = surface.vertex_normals(mesh);
        let normals = nodes
            .iter()
            .map(|&n| normals_by_vertex[surface.surface_index_of[n]])
            .collect();
        let positions = nodes.iter().map(|&n| mesh.nodes()[n]).collect();
        Ok(Self {
            nodes,
            normals,
            positions,
            node_count: mesh.node_count(),
        })
    }

    /// Straight incisions from random accessible nodes along random tangents, each made
    /// from one end in lengthening segments, blade along the inward normal; the tool beside
    /// the first one's middle, loaded by 1 N into the organ.
    fn plan(
        &self,
        rng: &mut fastrand::Rng,
        incisions: usize,
        segments: usize,
    ) -> Result<Plan, CutError> {
        let mut faces = Vec::new();
        let mut tool = None;
        let mut description = Vec::new();
        for _ in 0..incisions {
            let k = rng.usize(..self.nodes.len());
            let (middle, normal) = (self.positions[k], self.normals[k]);
            let random = Vector3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5);
            let along = (random - normal * random.dot(&normal))
                .try_normalize(1e-9)
                .unwrap_or_else(|| normal.cross(&Vector3::x()).normalize());
            let start = middle - along * (INCISION_LENGTH_M / 2.0);
            faces.push(
                (1..=segments)
                    .map(|s| {
                        let to = start + along * (INCISION_LENGTH_M * s as f64 / segments as f64);
                        CutFace::swept(start, to, -normal, INCISION_DEPTH_M)
                    })
                    .collect::<Result<Vec<_>, _>>()?,
            );
            tool.get_or_insert((middle + normal.cross(&along) * ORGAN_TOOL_M.1, normal));
            description.push(format!(
                "through ({:.0}, {:.0}, {:.0}) mm",
                middle.x * 1e3,
                middle.y * 1e3,
                middle.z * 1e3
            ));
        }
        let (centre, normal) = tool.expect("at least one incision");
        let patch = tool_patch(&self.nodes, &self.positions, centre, ORGAN_TOOL_M.0);
        let mut loads = Loads::new(self.node_count);
        for &(n, share) in &patch {
            let force = -normal * share;
            loads
                .add_nodal_force(n, [force.x, force.y, force.z])
                .map_err(|e| CutError::Degenerate(e.to_string()))?;
        }
        Ok(Plan {
            description: format!(
                "{} incisions {} mm long, {} mm deep, {}",
                incisions,
                INCISION_LENGTH_M * 1e3,
                INCISION_DEPTH_M * 1e3,
                description.join("; ")
            ),
            incisions: faces,
            loads,
            patch,
            press_m: -normal * ORGAN_TOOL_M.2,
        })
    }
}

/// A tool's patch: the `nodes` (at `positions`) within `radius_m` of `centre`, with shares
/// falling smoothly to zero at the rim as the trainer's kernel weighs them
/// ([`patch_weight`]), summing to one.
pub fn tool_patch(
    nodes: &[usize],
    positions: &[Point3<f64>],
    centre: Point3<f64>,
    radius_m: f64,
) -> Vec<(usize, f64)> {
    let mut patch: Vec<(usize, f64)> = nodes
        .iter()
        .zip(positions)
        .map(|(&n, p)| (n, patch_weight(1.0, (p - centre).norm(), radius_m)))
        .filter(|&(_, w)| w > 0.0)
        .collect();
    let total: f64 = patch.iter().map(|p| p.1).sum();
    patch.iter_mut().for_each(|p| p.1 /= total);
    patch
}

/// `‖a − b‖ / ‖b‖`.
fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm.max(f64::MIN_POSITIVE)).sqrt()
}
