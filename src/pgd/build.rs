//! `pgd build`: from an organ model to its vademecum, with the brute-force baseline measured
//! alongside.
//!
//! Linear step: the exact responses to every unit load are computed in blocks with the
//! stiffness factorized once (they give the local part and the baseline), the global part is
//! built by PGD enrichment, and the error estimator (the energy error of the separated part,
//! exact here) picks the number of modes.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::enrichment::{ModeReport, PgdSettings, enrich};
use super::error_curve::{EnergyError, ErrorCurve, FieldError, optimal_errors};
use super::load_patches::{LoadOperator, LoadPatches};
use super::local::{LocalPart, distance_neighbours, near_nodes};
use super::responses::Responses;
use super::separated::SeparatedField;
use super::stiffness::RestStiffness;
use super::vademecum::{Header, Step, Vademecum};
use super::{Progress, mesh_hash};
use crate::fem::{FemError, FemModel, PatchKernel};
use crate::mesh::Surface;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BuildSettings {
    /// Radius (m) of the tool tip's contact patch: every load is spread over it.
    pub tool_tip_radius_m: f64,
    /// Nodes within this distance (m) of a load get its exact response (the local correction).
    pub local_radius_m: f64,
    /// Target relative L2 error of the vademecum's field over all node-centred loads (the
    /// estimator); enrichment stops there or at the cap.
    pub target_error: f64,
    pub pgd: PgdSettings,
}

impl Default for BuildSettings {
    fn default() -> Self {
        Self {
            tool_tip_radius_m: 6e-3,
            local_radius_m: 0.02,
            target_error: 0.05,
            pgd: PgdSettings::default(),
        }
    }
}

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
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BuildReport {
    pub positions: usize,
    pub parameters: usize,
    pub free_dofs: usize,
    pub steps: Vec<StepReport>,
    pub total_seconds: f64,
}

/// Where the tool may press, in load-position numbering.
struct Accessible {
    /// The nodes of the accessible faces plus every surface node a tool patch on them reaches.
    positions: Vec<usize>,
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
    let mut core: Vec<usize> = faces.iter().flatten().copied().collect();
    core.sort_unstable();
    core.dedup();
    let reach = radius_m + longest_edge_m;
    let positions: Vec<usize> = surface
        .nodes
        .iter()
        .copied()
        .filter(|&n| {
            core.iter()
                .any(|&c| (mesh.nodes()[c] - mesh.nodes()[n]).norm() <= reach)
        })
        .collect();
    let mut index = vec![u32::MAX; mesh.node_count()];
    for (m, &n) in positions.iter().enumerate() {
        index[n] = m as u32;
    }
    let triangles = faces.iter().map(|f| f.map(|n| index[n])).collect();
    Ok(Accessible {
        positions,
        triangles,
        longest_edge_m,
    })
}

/// Builds the linear vademecum of `organ`.
pub fn build(
    organ: &OrganModel,
    settings: &BuildSettings,
    progress: &dyn Progress,
) -> Result<(Vademecum, BuildReport), FemError> {
    let started = Instant::now();
    let model = organ.model;
    let mesh = model.mesh();
    let surface = Surface::extract(mesh);
    let kernel = PatchKernel::new(mesh, &surface, settings.tool_tip_radius_m)?;
    let radius_m = settings.tool_tip_radius_m;
    let Accessible {
        positions,
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
    progress.message("factorizing the stiffness");
    let stiffness = RestStiffness::new(model)?;

    let (step, report) = linear_step(&stiffness, &patches, &neighbours, settings, progress)?;
    let reference_compliance_m_per_n = self_compliances(&step.local);
    let header = Header {
        source: organ.source.clone(),
        mesh_hash: mesh_hash(mesh),
        node_count: mesh.node_count(),
        tet_count: mesh.tet_count(),
        material: *model.material(),
        clamped_region: organ.clamped_region.clone(),
        accessible_region: organ.accessible_region.clone(),
        load_directions: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        settings: settings.clone(),
        indentation_levels_m: vec![0.0],
        modes_per_step: vec![report.modes_kept],
        build_seconds: started.elapsed().as_secs_f64(),
    };
    let vademecum = Vademecum {
        header,
        positions: patches.positions.iter().map(|&n| n as u32).collect(),
        position_coords_m: coords,
        position_areas_m2: patches.areas_m2.iter().map(|&a| a as f32).collect(),
        triangles,
        reference_compliance_m_per_n,
        steps: vec![step],
    };
    let report = BuildReport {
        positions: patches.positions.len(),
        parameters: patches.parameter_count(),
        free_dofs: stiffness.free_count(),
        steps: vec![report],
        total_seconds: started.elapsed().as_secs_f64(),
    };
    Ok((vademecum, report))
}

/// The linear step: exact responses, baseline, PGD global part, local part.
fn linear_step(
    stiffness: &RestStiffness,
    patches: &LoadPatches,
    neighbours: &[Vec<u32>],
    settings: &BuildSettings,
    progress: &dyn Progress,
) -> Result<(Step, StepReport), FemError> {
    let clock = Instant::now();
    progress.start("exact responses", patches.parameter_count() as u64);
    let responses = Responses::linear(stiffness, patches, &|n| progress.advance(n as u64));
    let gram = responses.gram(stiffness, patches);
    let weights = patches.weights();
    let optimal = optimal_errors(&gram, &weights, settings.pgd.max_modes);
    let brute_force_seconds = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    progress.message("local compliances");
    let mut local = LocalPart::with_compliances(stiffness, patches, &responses, neighbours);
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
    let mut residual = responses;
    let (field, modes, mut curve) = separated_part(
        stiffness,
        patches,
        (&weights, &self_compliance, &near),
        &mut residual,
        settings,
        progress,
    )?;
    curve.optimal = optimal[..curve.separated.len().min(optimal.len())].to_vec();
    let pgd_seconds = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    local.set_corrections(stiffness, &residual, &near);
    local_seconds += clock.elapsed().as_secs_f64();
    let report = StepReport {
        indentation_m: 0.0,
        curve,
        modes_kept: field.modes(),
        fixed_point_iterations: modes.iter().map(|m| m.fixed_point_iterations).collect(),
        pgd_seconds,
        brute_force_seconds,
        local_seconds,
    };
    Ok((step_of(&field, local), report))
}

/// PGD enrichment until the error estimator reaches the target or the cap. `residual` enters
/// as the exact responses and leaves as what the separated sum misses.
fn separated_part(
    stiffness: &RestStiffness,
    loads: &dyn LoadOperator,
    (weights, self_compliance, near): (&[f64], &[f64], &[Vec<u32>]),
    residual: &mut Responses,
    settings: &BuildSettings,
    progress: &dyn Progress,
) -> Result<(SeparatedField, Vec<ModeReport>, ErrorCurve), FemError> {
    progress.start("PGD modes", settings.pgd.max_modes as u64);
    let mut energy = EnergyError::new(weights, self_compliance);
    let estimator = FieldError::new(stiffness, residual, weights, near);
    let mut curve = ErrorCurve::default();
    let (field, modes) = enrich(stiffness, loads, weights, &settings.pgd, &mut |field, _| {
        curve
            .separated
            .push(energy.add_mode(field, stiffness, loads));
        let k = field.modes() - 1;
        let error = estimator.subtract_mode(residual, &field.spatial[k], &field.parametric[k]);
        curve.field.push(error);
        progress.advance(1);
        progress.message(&format!(
            "mode {}: error {:.2} %",
            field.modes(),
            100.0 * error
        ));
        error > settings.target_error
    })?;
    Ok((field, modes, curve))
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
