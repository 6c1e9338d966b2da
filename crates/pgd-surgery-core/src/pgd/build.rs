//! `pgd build`: from an organ model to its vademecum, with the brute-force baseline measured
//! alongside.
//!
//! Every load step: the exact responses to every unit load are computed in blocks with the
//! rest stiffness factorized once (they give the local part and the baseline), the global part
//! is built by PGD enrichment, and the error estimator (the L2 error of the whole vademecum,
//! exact here) picks the number of modes. The linear step is step 0; a nonlinear law adds one
//! step per indentation level, whose loads are the tool's patch centred on each position and
//! whose secant responses are found by the fixed point of paper 000 (nonlinear terms of the
//! previous iterate on the right-hand side), starting from the step before; the step keeps
//! their correction to the linear response.

use std::ops::Range;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::baseline::NewtonBaseline;
use super::enrichment::enrich;
use super::error_curve::{EnergyError, ErrorCurve, FieldError, optimal_errors};
use super::load_patches::{LoadOperator, LoadPatches, UnitLoads};
use super::local::{
    AlongDirections, LocalPart, ParameterResponses, distance_neighbours, near_nodes,
};
use super::region::{CutHeader, RegionReport, RegionResponse, RegionSettings};
use super::responses::{
    Offset, Responses, ScaledLoads, SecantReport, SecantSettings, StepStart, Trend,
};
use super::separated::SeparatedField;
use super::settings::BuildSettings;
use super::snapshot_modes::SnapshotModes;
use super::stiffness::RestStiffness;
use super::tool_patch::{PatchGeometry, ToolPatchLoads};
use super::vademecum::{Header, Step, StepLoads, Vademecum};
use super::{Progress, mesh_hash};
use crate::fem::{FemError, FemModel, Law, PatchKernel, on_pressed_side};
use crate::mesh::Surface;
use nalgebra::Vector3;

/// What the model is, beyond its mesh: the names written into the header.
pub struct OrganModel<'a> {
    pub source: String,
    pub model: &'a FemModel,
    pub clamped_region: String,
    pub accessible_region: String,
}

/// Per load step: the error curves, the PGD's modes and where the time went.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StepReport {
    pub indentation_m: f64,
    pub curve: ErrorCurve,
    pub modes_kept: usize,
    pub fixed_point_iterations: Vec<usize>,
    pub pgd_seconds: f64,
    /// Exact responses, their Gram and its eigenvalues: the brute-force baseline.
    pub brute_force_seconds: f64,
    pub local_seconds: f64,
    /// KSV steps: how the fixed point of the secant responses went.
    pub fixed_point: Option<SecantReport>,
    /// Nonlinear steps: the positions whose range reaches this step (the loads that
    /// converged here and at every step before).
    pub positions_reached: usize,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BuildReport {
    pub positions: usize,
    pub parameters: usize,
    pub free_dofs: usize,
    pub steps: Vec<StepReport>,
    /// KSV load steps left out because their fixed point did not converge: the vademecum's
    /// valid range stops before them.
    pub failed_step: Option<StepReport>,
    /// Nonlinear laws: the positions the load steps press (all but those a clamp holds);
    /// what each step's `positions_reached` counts out of. Zero for the linear law.
    pub positions_loaded: usize,
    /// The share of the organ's nodes in a load's near field, on average: near 1, every load
    /// keeps its exact response everywhere (a large file, few modes).
    pub near_field_share: f64,
    /// The cut section, when one was asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cuts: Option<RegionReport>,
    /// Nonlinear laws, when asked for: the brute-force alternative (a Newton path per load)
    /// timed on a sample, not counted in `total_seconds`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub newton_baseline: Option<NewtonBaseline>,
    pub total_seconds: f64,
    /// The file's size (bytes), once written.
    pub file_bytes: u64,
}

/// Above this [`BuildReport::near_field_share`] the build warns that the near field is too
/// wide for the organ.
pub const WIDE_NEAR_FIELD_SHARE: f64 = 0.5;

/// Where the tool may press, in load-position numbering.
struct Accessible {
    /// Every surface node a tool patch on the accessible faces can load: within the patch's
    /// reach of a face and on its side of the wall.
    positions: Vec<usize>,
    /// Outward unit normal of each position.
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    longest_edge_m: f64,
}

fn accessible(
    organ: &OrganModel,
    surface: &Surface,
    radius_m: f64,
) -> Result<Accessible, FemError> {
    let mesh = organ.model.mesh();
    let faces = mesh.face_set(&organ.accessible_region)?;
    let longest_edge_m = faces
        .iter()
        .flat_map(|f| {
            (0..3).map(move |k| (mesh.nodes()[f[k]] - mesh.nodes()[f[(k + 1) % 3]]).norm())
        })
        .fold(0.0, f64::max);
    let normals = surface.vertex_normals(mesh);
    let normal_of = |n: usize| normals[surface.surface_index_of[n]];
    let facings: Vec<Vector3<f64>> = faces
        .iter()
        .map(|f| f.iter().map(|&n| normal_of(n)).sum())
        .collect();
    // A patch centred on a face reaches at most `radius + longest edge` from its first corner.
    let reach = radius_m + longest_edge_m;
    let positions: Vec<usize> = surface
        .nodes
        .par_iter()
        .copied()
        .filter(|&n| {
            faces.iter().zip(&facings).any(|(f, facing)| {
                (mesh.nodes()[f[0]] - mesh.nodes()[n]).norm() <= reach
                    && on_pressed_side(&normal_of(n), facing)
            })
        })
        .collect();
    let mut index = vec![u32::MAX; mesh.node_count()];
    for (m, &n) in positions.iter().enumerate() {
        index[n] = m as u32;
    }
    let triangles = faces.iter().map(|f| f.map(|n| index[n])).collect();
    Ok(Accessible {
        normals: positions
            .iter()
            .map(|&n| normal_of(n).map(|c| c as f32).into())
            .collect(),
        positions,
        triangles,
        longest_edge_m,
    })
}

/// Builds the vademecum of `organ`: every position's responses, separated step by step.
pub fn build(
    organ: &OrganModel,
    settings: &BuildSettings,
    progress: &dyn Progress,
) -> Result<(Vademecum, BuildReport), FemError> {
    let started = Instant::now();
    with_context(organ, settings, progress, |context| {
        let mut separating = Separating::new(context);
        let all = 0..context.patches.positions.len();
        let ranges = position_work(context, all, &mut separating)?;
        Ok(separating.finish(organ, ranges, started))
    })
}

/// Runs `then` with the context every build of `organ` works in: its load positions, their
/// patches and neighbours, the tool's patch loads (nonlinear laws) and the rest stiffness
/// factorized.
pub(super) fn with_context<R, E: From<FemError>>(
    organ: &OrganModel,
    settings: &BuildSettings,
    progress: &dyn Progress,
    then: impl FnOnce(&StepContext) -> Result<R, E>,
) -> Result<R, E> {
    let model = organ.model;
    let mesh = model.mesh();
    let surface = Surface::extract(mesh);
    let kernel = PatchKernel::new(mesh, &surface, settings.tool_tip_radius_m)?;
    let radius_m = settings.tool_tip_radius_m;
    let Accessible {
        positions,
        normals,
        triangles,
        longest_edge_m,
    } = accessible(organ, &surface, radius_m)?;
    let patches = LoadPatches::new(&surface, &kernel, positions)?;
    let coords: Vec<[f32; 3]> = patches
        .positions
        .iter()
        .map(|&n| mesh.nodes()[n].coords.map(|c| c as f32).into())
        .collect();
    // Wide enough to couple any two nodes of one patch, and to find a patch's nodes from the
    // corners of the triangle it is centred in.
    let neighbours = distance_neighbours(&coords, 2.0 * radius_m + longest_edge_m);
    let areas: Vec<f32> = patches.weights.iter().map(|&a| a as f32).collect();
    progress.message("factorizing the stiffness");
    let stiffness = RestStiffness::new(model)?;
    let geometry = PatchGeometry {
        coords_m: &coords,
        areas_m2: &areas,
        normals: &normals,
        radius_m,
    };
    let tool = (model.material().law != Law::Linear)
        .then(|| ToolPatchLoads::new(patches.positions.clone(), &geometry, &neighbours));
    then(&StepContext {
        geometry,
        triangles: &triangles,
        stiffness: &stiffness,
        patches: &patches,
        neighbours: &neighbours,
        tool: tool.as_ref(),
        settings,
        progress,
    })
}

/// The warning for a near field holding `share` of the organ's nodes for an average load.
fn wide_near_field(settings: &BuildSettings, share: f64) -> String {
    format!(
        "the near field ({:.1} mm) holds {:.0} % of the organ's nodes for an average load: the \
         file is large and the modes carry little; an organ this size wants a smaller \
         --local-radius-mm (and a tool to match, --tool-radius-mm)",
        settings.local_radius_m * 1e3,
        100.0 * share
    )
}

/// The vademecum's header: what it was built from and with, and its steps' figures.
fn header(
    organ: &OrganModel,
    settings: &BuildSettings,
    reports: &[StepReport],
    started: Instant,
) -> Header {
    let (model, mesh) = (organ.model, organ.model.mesh());
    Header {
        source: organ.source.clone(),
        mesh_hash: mesh_hash(mesh),
        node_count: mesh.node_count(),
        tet_count: mesh.tet_count(),
        material: *model.material(),
        inclusions: model.inclusions().to_vec(),
        clamped_region: organ.clamped_region.clone(),
        accessible_region: organ.accessible_region.clone(),
        load_directions: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        settings: settings.clone(),
        indentation_levels_m: reports.iter().map(|r| r.indentation_m).collect(),
        step_loads: StepLoads::InwardToolPatch,
        modes_per_step: reports.iter().map(|r| r.modes_kept).collect(),
        convergence: reports.iter().map(|r| r.curve.clone()).collect(),
        build_seconds: started.elapsed().as_secs_f64(),
        cuts: None,
    }
}

/// What every load step is built with.
pub(super) struct StepContext<'a> {
    /// The load positions, for the tool's patch centred on each.
    geometry: PatchGeometry<'a>,
    /// The accessible faces, in position numbering.
    triangles: &'a [[u32; 3]],
    stiffness: &'a RestStiffness<'a>,
    pub(super) patches: &'a LoadPatches,
    neighbours: &'a [Vec<u32>],
    /// Nonlinear laws: the tool's patch centred on each position, what their steps load.
    tool: Option<&'a ToolPatchLoads>,
    pub(super) settings: &'a BuildSettings,
    pub(super) progress: &'a dyn Progress,
}

impl StepContext<'_> {
    /// The rows of every response: the free dofs.
    pub(super) fn rows(&self) -> usize {
        self.stiffness.free_count()
    }
}

/// Where the per-position work of the load steps goes, step by step: separated into the
/// vademecum's steps at once (a whole build), or kept for a merge (a shard).
pub(super) trait StepSink {
    /// The exact responses to the unit loads of the positions worked on (step 0), which took
    /// `seconds`.
    fn linear(&mut self, exact: Responses, seconds: f64) -> Result<(), FemError>;

    /// A nonlinear step's outcome; returns whether the steps go on.
    fn nonlinear(&mut self, step: NonlinearStep) -> Result<bool, FemError>;
}

/// What a nonlinear load step's per-position work gives.
pub(super) struct NonlinearStep<'a> {
    pub level_m: f64,
    /// The corrections `Ũ − U_lin` its secant responses make to the linear ones, one column
    /// per position worked on.
    pub corrections: &'a Responses,
    /// The positions it reaches (organ numbering, sorted).
    pub reached: Vec<usize>,
    /// The positions (all but those a clamp holds) the nonlinear steps load.
    pub loaded: usize,
    pub fixed_point: SecantReport,
    /// The time its fixed points took.
    pub seconds: f64,
}

/// Per position worked on: the reference compliance that turns a force into the level
/// picking load steps (nonlinear laws) and the level its range reaches.
#[derive(Default)]
pub(super) struct PositionRanges {
    pub reference: Vec<f32>,
    pub range_level_m: Vec<f32>,
}

/// The per-position work over the positions `range`: the exact responses to their unit loads,
/// then (nonlinear laws) one step per indentation level while `sink` wants more. A nonlinear
/// step loads the tool's patch centred on each position, pushing along its inward normal,
/// sized so that its linear response is the level deep, and hands on the nonlinear correction
/// to the linear response of that patch: the trainer adds it to the exact linear response of
/// the patch where the tool is. A position whose load fails past the first step is not
/// loaded deeper: its range ends at the step before. Every column is computed in the same
/// blocks whatever the range, as long as it starts on a block ([`super::Shard`]).
pub(super) fn position_work(
    context: &StepContext,
    range: Range<usize>,
    sink: &mut dyn StepSink,
) -> Result<PositionRanges, FemError> {
    let (stiffness, patches, progress) = (context.stiffness, context.patches, context.progress);
    let clock = Instant::now();
    let count = range.len();
    progress.start("exact responses", 3 * count as u64);
    let unit = Offset {
        loads: patches,
        first: 3 * range.start,
    };
    let exact = Responses::solve(stiffness, &unit, 3 * count, &|n| progress.advance(n as u64));
    sink.linear(exact, clock.elapsed().as_secs_f64())?;
    let Some(tool) = context.tool else {
        return Ok(PositionRanges::default());
    };
    let clock = Instant::now();
    let tool = Offset {
        loads: tool,
        first: range.start,
    };
    progress.start("linear responses to the tool's patch", count as u64);
    let linear = Responses::solve(stiffness, &tool, count, &|n| progress.advance(n as u64));
    let reference = patch_depths(stiffness, &tool, &linear);
    let mut secant = linear.clone();
    // The step before the last, and its level: with the last they give the next start's trend.
    let mut before: Option<(Responses, f64)> = None;
    let mut last_level_m = 0.0;
    let mut range_level_m = vec![0.0f32; count];
    let loaded = reference.iter().filter(|&&per_n| per_n > 0.0).count();
    let mut seconds_before = clock.elapsed().as_secs_f64();
    for &level_m in &context.settings.load_steps_m {
        let clock = Instant::now();
        let magnitudes = step_magnitudes(&reference, &range_level_m, last_level_m, level_m);
        let law = stiffness.model.material().law.name();
        progress.start(&format!("{law} step {:.1} mm", level_m * 1e3), count as u64);
        let trend = before.take().map(|(responses, from_m)| {
            Trend::new(&responses, &secant, from_m, last_level_m, level_m)
        });
        before = Some((secant.clone(), last_level_m));
        let last_level_before = last_level_m;
        last_level_m = level_m;
        let (fixed_point, unconverged);
        (secant, fixed_point, unconverged) = secant.secant(
            stiffness,
            ScaledLoads {
                unit: &tool,
                magnitudes_n: &magnitudes,
            },
            StepStart {
                trend: trend.as_ref(),
                fraction_before: last_level_before / level_m,
            },
            &context.settings.secant,
            &|n| progress.advance(n as u64),
        );
        drop(trend); // a full copy of the responses: freed before the step's PGD
        let secant_settings = &context.settings.secant;
        let reached = reached_positions(&magnitudes, &unconverged, &fixed_point, secant_settings);
        secant.add_scaled(&linear, -1.0);
        let go_on = sink.nonlinear(NonlinearStep {
            level_m,
            corrections: &secant,
            reached: reached.iter().map(|m| range.start + m).collect(),
            loaded,
            fixed_point,
            seconds: seconds_before + clock.elapsed().as_secs_f64(),
        })?;
        secant.add_scaled(&linear, 1.0);
        seconds_before = 0.0;
        if !go_on {
            break;
        }
        reached
            .iter()
            .for_each(|&m| range_level_m[m] = level_m as f32);
    }
    Ok(PositionRanges {
        reference,
        range_level_m,
    })
}

/// The sink of a whole build: each step separated into the vademecum's as it comes.
pub(super) struct Separating<'a> {
    context: &'a StepContext<'a>,
    steps: Vec<Step>,
    reports: Vec<StepReport>,
    /// A nonlinear step left out: the steps stop before it.
    failed: Option<StepReport>,
    /// The positions the nonlinear steps load.
    loaded: usize,
}

impl<'a> Separating<'a> {
    pub(super) fn new(context: &'a StepContext<'a>) -> Self {
        Self {
            context,
            steps: Vec::new(),
            reports: Vec::new(),
            failed: None,
            loaded: 0,
        }
    }

    /// The vademecum of the steps separated, with every position's `ranges`.
    pub(super) fn finish(
        self,
        organ: &OrganModel,
        ranges: PositionRanges,
        started: Instant,
    ) -> (Vademecum, BuildReport) {
        let context = self.context;
        let (patches, settings) = (context.patches, context.settings);
        let node_count = organ.model.mesh().node_count();
        let near_field_share = self.steps[0].local.correction_nodes.len() as f64
            / (patches.positions.len() * node_count) as f64;
        if near_field_share > WIDE_NEAR_FIELD_SHARE {
            context
                .progress
                .message(&wide_near_field(settings, near_field_share));
        }
        let PositionRanges {
            reference,
            range_level_m,
        } = match context.tool {
            Some(_) => ranges,
            None => {
                let reference = self_compliances(&self.steps[0].local);
                PositionRanges {
                    range_level_m: vec![0.0; reference.len()],
                    reference,
                }
            }
        };
        let geometry = &context.geometry;
        let vademecum = Vademecum {
            header: header(organ, settings, &self.reports, started),
            positions: patches.positions.iter().map(|&n| n as u32).collect(),
            position_coords_m: geometry.coords_m.to_vec(),
            position_areas_m2: geometry.areas_m2.to_vec(),
            position_normals: geometry.normals.to_vec(),
            triangles: context.triangles.to_vec(),
            reference_compliance_m_per_n: reference,
            range_level_m,
            steps: self.steps,
            cuts: None,
        };
        let report = BuildReport {
            positions: patches.positions.len(),
            parameters: patches.parameter_count(),
            free_dofs: context.rows(),
            steps: self.reports,
            failed_step: self.failed,
            positions_loaded: self.loaded,
            near_field_share,
            cuts: None,
            newton_baseline: None,
            total_seconds: started.elapsed().as_secs_f64(),
            file_bytes: 0,
        };
        (vademecum, report)
    }
}

impl StepSink for Separating<'_> {
    fn linear(&mut self, exact: Responses, seconds: f64) -> Result<(), FemError> {
        let (stiffness, patches) = (self.context.stiffness, self.context.patches);
        let clock = Instant::now();
        let gram = exact.gram(stiffness, patches);
        let brute_force_seconds = seconds + clock.elapsed().as_secs_f64();
        let separation = Separation::Enrichment(patches);
        let (step, report) =
            separated_step(self.context, &exact, separation, gram, brute_force_seconds)?;
        self.steps.push(step);
        self.reports.push(report);
        Ok(())
    }

    /// Separates the step unless it reaches too few positions ([`kept`]): then it is
    /// reported as left out, and the steps stop.
    fn nonlinear(&mut self, step: NonlinearStep) -> Result<bool, FemError> {
        let context = self.context;
        let law = context.stiffness.model.material().law.name();
        let (level_m, fixed_point) = (step.level_m, step.fixed_point);
        context
            .progress
            .message(&fixed_point_words(law, level_m, &fixed_point, step.seconds));
        self.loaded = step.loaded;
        if !kept(step.reached.len(), step.loaded, &context.settings.secant) {
            context.progress.message(&format!(
                "{law} step {:.1} mm: the fixed point did not converge for {} of {} loads; \
                 the vademecum stops at the step before",
                level_m * 1e3,
                fixed_point.unconverged,
                fixed_point.responses
            ));
            self.failed = Some(StepReport {
                indentation_m: level_m,
                brute_force_seconds: step.seconds,
                fixed_point: Some(fixed_point),
                positions_reached: step.reached.len(),
                ..StepReport::default()
            });
            return Ok(false);
        }
        let (separated, mut report) = correction_step(context, step.corrections, step.seconds)?;
        report.indentation_m = level_m;
        report.fixed_point = Some(fixed_point);
        report.positions_reached = step.reached.len();
        self.steps.push(separated);
        self.reports.push(report);
        Ok(true)
    }
}

/// Each patch's push at the step to `level_m`, sized so that its linear displacement
/// (`reference` m/N) is `level_m` long; a position whose range ended (short of the last
/// step's level, stored as the same f32) is not pushed.
fn step_magnitudes(
    reference: &[f32],
    range_level_m: &[f32],
    last_level_m: f64,
    level_m: f64,
) -> Vec<f64> {
    (reference.iter().zip(range_level_m))
        .map(|(&per_n, &range_m)| {
            let reaching = per_n > 0.0 && range_m == last_level_m as f32;
            if reaching {
                level_m / f64::from(per_n)
            } else {
                0.0
            }
        })
        .collect()
}

/// What a step's fixed point did, in words for the build's progress.
fn fixed_point_words(law: &str, level_m: f64, fixed_point: &SecantReport, seconds: f64) -> String {
    format!(
        "{law} step {:.1} mm: {} loads, {:.1} fixed-point iterations each on average, \
         {} through substeps, {} by Newton, {} left ({:.0} s)",
        level_m * 1e3,
        fixed_point.responses,
        fixed_point.mean_iterations(),
        fixed_point.substep_solved,
        fixed_point.newton_solved,
        fixed_point.unconverged,
        seconds
    )
}

/// The step of a nonlinear level: the PGD of the `corrections` `Ũ − U_lin` its secant
/// responses make to the linear ones, whose fixed points took `seconds`.
fn correction_step(
    context: &StepContext,
    corrections: &Responses,
    seconds: f64,
) -> Result<(Step, StepReport), FemError> {
    let clock = Instant::now();
    let stiffness = context.stiffness;
    let gram = corrections.energy_gram(stiffness);
    context.progress.message("modes of the corrections");
    let max_modes = context.settings.pgd.max_modes;
    let weights = &context.patches.weights;
    let best = SnapshotModes::new(stiffness, corrections, &gram, weights, max_modes);
    let tool = context
        .tool
        .expect("a nonlinear step has the tool's patch loads");
    let separation = Separation::Snapshots {
        directions: &tool.inward,
        best,
    };
    let brute_force_seconds = seconds + clock.elapsed().as_secs_f64();
    separated_step(context, corrections, separation, gram, brute_force_seconds)
}

/// The positions a step reaches: those pushed at it whose load converged, or all those
/// pushed when no more than the tolerated share of loads failed (the failed ones keep the
/// step before's response, as counted in the step's report).
fn reached_positions(
    magnitudes_n: &[f64],
    unconverged: &[usize],
    fixed_point: &SecantReport,
    settings: &SecantSettings,
) -> Vec<usize> {
    let tolerated = fixed_point.acceptable(settings);
    (0..magnitudes_n.len())
        .filter(|&m| magnitudes_n[m] > 0.0)
        .filter(|m| tolerated || unconverged.binary_search(m).is_err())
        .collect()
}

/// Whether a nonlinear step that reaches `reached` of the `loaded` positions (those no
/// clamp holds) is kept: while it reaches [`SecantSettings::min_reached_share`] of them.
/// A position the first nonlinear step leaves has no range: a patch of such positions alone
/// answers linearly, and the trainer says it is beyond the range.
fn kept(reached: usize, loaded: usize, settings: &SecantSettings) -> bool {
    reached as f64 >= settings.min_reached_share * loaded as f64
}

/// Per position, how deep (m) a unit force along its inward normal presses the patch centred
/// on it, linearly (the patch's mean displacement, from the `linear` responses of `tool`'s
/// loads): what turns a force into the level that picks a step.
fn patch_depths(stiffness: &RestStiffness, tool: &impl UnitLoads, linear: &Responses) -> Vec<f32> {
    let free_index = &stiffness.model.dofs().free_index;
    (0..linear.count())
        .map(|m| {
            let column = linear.column(m);
            let depth = Vector3::from_fn(|c, _| {
                tool.nodal_shares(m)
                    .map(|(node, share)| match free_index[3 * node + c] {
                        crate::fem::PRESCRIBED => 0.0,
                        free => share * column[free],
                    })
                    .sum::<f64>()
            });
            depth.norm() as f32
        })
        .collect()
}

/// How a step's global part is separated from its exact responses.
enum Separation<'a> {
    /// Greedy PGD enrichment against the step's loads, one response per parameter (the
    /// linear step: its loads are sparse and a mode costs a few solves).
    Enrichment(&'a (dyn LoadOperator + Sync)),
    /// The responses' own best modes, from their Gram's eigenvectors (see [`SnapshotModes`]):
    /// a nonlinear step's corrections, one per position along its direction, whose
    /// right-hand side `K D` is dense.
    Snapshots {
        directions: &'a [Vector3<f64>],
        best: SnapshotModes,
    },
}

impl Separation<'_> {
    /// `responses` (in this separation's layout) by load parameter.
    fn per_parameter<'r>(&self, responses: &'r Responses) -> Box<dyn ParameterResponses + 'r>
    where
        Self: 'r,
    {
        match *self {
            Separation::Enrichment(_) => Box::new(responses),
            Separation::Snapshots { directions, .. } => Box::new(AlongDirections {
                responses,
                directions,
            }),
        }
    }
}

/// One load step from its exact responses: baseline, global part, local part. `gram` is the
/// responses' energy Gram; they and it took `brute_force_seconds`.
fn separated_step(
    context: &StepContext,
    exact: &Responses,
    separation: Separation,
    gram: Vec<f64>,
    brute_force_seconds: f64,
) -> Result<(Step, StepReport), FemError> {
    let StepContext {
        stiffness,
        patches,
        neighbours,
        settings,
        progress,
        ..
    } = *context;
    let max_modes = settings.pgd.max_modes;
    let (weights, optimal) = match &separation {
        Separation::Enrichment(_) => {
            let weights = patches.parameter_weights();
            let optimal = optimal_errors(&gram, &weights, max_modes);
            (weights, optimal)
        }
        Separation::Snapshots { best, .. } => (patches.weights.clone(), best.optimal.clone()),
    };

    let clock = Instant::now();
    progress.message("local compliances");
    let exact_per_parameter = separation.per_parameter(exact);
    let mut local =
        LocalPart::with_compliances(stiffness, patches, &*exact_per_parameter, neighbours);
    let near = near_nodes(
        stiffness.model.mesh(),
        &patches.positions,
        settings.local_radius_m,
    );
    let mut local_seconds = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    let self_compliance: Vec<f64> = (0..weights.len())
        .map(|p| gram[p * weights.len() + p])
        .collect();
    drop(gram);
    let mut residual = exact.clone();
    let mut estimator = ModeErrors {
        energy: EnergyError::new(&weights, &self_compliance),
        field: FieldError::new(stiffness, &residual, &weights, &near),
        curve: ErrorCurve::default(),
        target: settings.target_error,
        progress,
    };
    progress.start("PGD modes", max_modes as u64);
    let (field, modes) = match &separation {
        Separation::Enrichment(loads) => enrich(
            stiffness,
            *loads,
            &weights,
            &settings.pgd,
            &mut |field, _| {
                estimator.energy_error(field, stiffness, *loads);
                estimator.go_on(field, &mut residual)
            },
        )?,
        Separation::Snapshots { best, .. } => {
            let mut field = SeparatedField::default();
            for (x, y) in best.field.spatial.iter().zip(&best.field.parametric) {
                field.push(x.clone(), y.clone());
                estimator.curve.separated.push(optimal[field.modes() - 1]);
                if !estimator.go_on(&field, &mut residual) {
                    break;
                }
            }
            (field, Vec::new())
        }
    };
    let mut curve = estimator.curve;
    curve.optimal = optimal[..curve.separated.len().min(optimal.len())].to_vec();
    let pgd_seconds = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    local.set_corrections(stiffness, &*separation.per_parameter(&residual), &near);
    local_seconds += clock.elapsed().as_secs_f64();
    let report = StepReport {
        indentation_m: 0.0,
        curve,
        modes_kept: field.modes(),
        fixed_point_iterations: modes.iter().map(|m| m.fixed_point_iterations).collect(),
        pgd_seconds,
        brute_force_seconds,
        local_seconds,
        fixed_point: None,
        positions_reached: 0,
    };
    let field = match separation {
        Separation::Enrichment(_) => field,
        Separation::Snapshots { directions, .. } => per_axis(field, directions),
    };
    Ok((step_of(&field, local), report))
}

/// Modes whose parametric part is per position along `directions`, turned into modes over the
/// parameters `3m + d`: a unit force along axis `d` is answered by its component along the
/// position's direction.
fn per_axis(field: SeparatedField, directions: &[Vector3<f64>]) -> SeparatedField {
    let parametric = field
        .parametric
        .iter()
        .map(|y| {
            y.iter()
                .zip(directions)
                .flat_map(|(v, w)| w.iter().map(move |c| v * c))
                .collect()
        })
        .collect();
    SeparatedField {
        spatial: field.spatial,
        parametric,
    }
}

/// The error curve of a step's global part as modes are added, and when to stop adding them.
struct ModeErrors<'a> {
    energy: EnergyError,
    field: FieldError<'a>,
    curve: ErrorCurve,
    target: f64,
    progress: &'a dyn Progress,
}

impl ModeErrors<'_> {
    /// Records the energy error of `field`'s newest mode (the enrichment's own estimate).
    fn energy_error(
        &mut self,
        field: &SeparatedField,
        stiffness: &RestStiffness,
        loads: &dyn LoadOperator,
    ) {
        let error = self.energy.add_mode(field, stiffness, loads);
        self.curve.separated.push(error);
    }

    /// Takes `field`'s newest mode out of `residual` (the exact responses less the modes so
    /// far), records the field errors and says whether another mode is wanted.
    fn go_on(&mut self, field: &SeparatedField, residual: &mut Responses) -> bool {
        let k = field.modes() - 1;
        let errors = self
            .field
            .subtract_mode(residual, &field.spatial[k], &field.parametric[k]);
        self.curve.field.push(errors.rms);
        self.curve.field_p95.push(errors.p95);
        self.progress.advance(1);
        self.progress.message(&format!(
            "mode {}: error {:.2} % rms, {:.2} % p95 over the loads",
            field.modes(),
            100.0 * errors.rms,
            100.0 * errors.p95
        ));
        errors.rms > self.target
    }
}

fn step_of(field: &SeparatedField, local: LocalPart) -> Step {
    Step {
        spatial: field.spatial.iter().flatten().map(|&v| v as f32).collect(),
        parametric: field
            .parametric
            .iter()
            .flatten()
            .map(|&v| v as f32)
            .collect(),
        local,
    }
}

/// Per position, the largest diagonal entry of its self-compliance block (m/N).
fn self_compliances(local: &LocalPart) -> Vec<f32> {
    (0..local.neighbour_offsets.len() - 1)
        .map(|m| {
            let e = local.neighbours_of(m).start;
            let block = &local.compliance[9 * e..9 * e + 9];
            block[0].max(block[4]).max(block[8])
        })
        .collect()
}

/// Adds the cut section to `vademecum`, built for `model` (the model it was built for): the
/// responses over the nodes within `settings.depth_m` of its accessible faces.
pub fn add_cuts(
    vademecum: &mut Vademecum,
    model: &FemModel,
    settings: &RegionSettings,
    progress: &dyn Progress,
) -> Result<RegionReport, FemError> {
    let faces = vademecum.header.accessible_region.clone();
    progress.message("factorizing the stiffness for the cut modes");
    let stiffness = RestStiffness::new(model)?;
    let region =
        RegionResponse::region_nodes(&stiffness, model.mesh().face_set(&faces)?, settings.depth_m);
    let (response, report) = RegionResponse::build(&stiffness, &region, settings, progress)?;
    vademecum.header.cuts = Some(CutHeader {
        faces,
        settings: *settings,
        report: report.clone(),
    });
    vademecum.cuts = Some(response);
    Ok(report)
}
