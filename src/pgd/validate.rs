//! `pgd validate`: the vademecum against full FEM on the same mesh, at loads the builder never
//! used exactly — random points inside accessible triangles, directions tilted off the inward
//! normal, and forces giving the indentations a trainee makes.
//!
//! For each sample the reference force `F` is spread over the tool's contact patch centred on
//! the point (not on nodes) and solved by full FEM (Newton for KSV). The indentation the
//! reference makes under the tool is handed to the vademecum, which returns the force it
//! would render and the field it would show; both are compared with the reference.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::Progress;
use super::organ::tool_radii_m;
use super::statistics::Statistics;
use super::vademecum::{SurfacePoint, Vademecum};
use crate::fem::{FemError, FemModel, Loads, NewtonSettings, PatchKernel};
use crate::mesh::organs::Organ;
use crate::mesh::{Surface, area_vector};

#[derive(Clone, Debug, PartialEq)]
pub struct ValidationSettings {
    pub samples: usize,
    pub seed: u64,
    /// Indentations are drawn uniformly in this range (m).
    pub indentation_range_m: (f64, f64),
    /// Directions deviate from the inward normal by up to this angle.
    pub max_tilt_deg: f64,
    /// The "field near the tool" is measured on nodes within this distance (m).
    pub near_radius_m: f64,
    /// Load steps of the reference Newton solve (KSV).
    pub newton_load_steps: usize,
}

impl Default for ValidationSettings {
    /// The abdominal organs' settings.
    fn default() -> Self {
        Self::for_organ(None)
    }
}

impl ValidationSettings {
    /// Loads sized to `organ`'s tool ([`tool_radii_m`]): indentations up to ten thirds of the
    /// tool radius (20 mm under the abdominal 6 mm tool, what a trainee makes), and the field
    /// "near the tool" measured over the region the trainee watches (2 cm for the abdominal
    /// organs, as the targets say).
    pub fn for_organ(organ: Option<Organ>) -> Self {
        let radii = tool_radii_m(organ);
        Self {
            samples: 60,
            seed: 7,
            indentation_range_m: up_to(radii.tool_tip_m * 10.0 / 3.0),
            max_tilt_deg: 45.0,
            near_radius_m: radii.watched_m,
            newton_load_steps: 4,
        }
    }

    /// These settings with indentations up to `deepest_m` instead.
    pub fn deepest_indentation(self, deepest_m: f64) -> Self {
        Self {
            indentation_range_m: up_to(deepest_m),
            ..self
        }
    }
}

/// Indentations from a tenth of `deepest_m` to it.
fn up_to(deepest_m: f64) -> (f64, f64) {
    (0.1 * deepest_m, deepest_m)
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sample {
    pub point_m: [f64; 3],
    pub force_n: [f64; 3],
    pub indentation_m: f64,
    /// `|F_vademecum − F_fem| / |F_fem|` for the same indentation.
    pub force_error: f64,
    /// Relative L2 error of the displacement over the whole organ.
    pub field_error: f64,
    /// Relative L2 error over the nodes near the tool.
    pub near_field_error: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ValidationReport {
    /// The radius (m) of the "near the tool" region `near_field_error` is measured over.
    pub near_radius_m: f64,
    pub force_error: Statistics,
    pub field_error: Statistics,
    pub near_field_error: Statistics,
    pub samples: Vec<Sample>,
}

/// Compares `vademecum` with full FEM on `model` (the mesh it was built for).
pub fn validate(
    model: &FemModel,
    vademecum: &Vademecum,
    settings: &ValidationSettings,
    progress: &dyn Progress,
) -> Result<ValidationReport, FemError> {
    let mesh = model.mesh();
    let surface = Surface::extract(mesh);
    let kernel = PatchKernel::new(mesh, &surface, vademecum.header.settings.tool_tip_radius_m)?;
    let mut rng = fastrand::Rng::with_seed(settings.seed);
    let areas: Vec<f64> = vademecum
        .triangles
        .iter()
        .map(|t| {
            area_vector(
                mesh.nodes(),
                &t.map(|m| vademecum.positions[m as usize] as usize),
            )
            .norm()
        })
        .collect();
    let total_area: f64 = areas.iter().sum();
    progress.start("full FEM references", settings.samples as u64);
    let mut samples = Vec::with_capacity(settings.samples);
    for _ in 0..settings.samples {
        let at = random_point(&mut rng, &areas, total_area);
        samples.push(sample(model, vademecum, &kernel, &at, &mut rng, settings)?);
        progress.advance(1);
    }
    Ok(ValidationReport {
        near_radius_m: settings.near_radius_m,
        force_error: Statistics::of(samples.iter().map(|s| s.force_error)),
        field_error: Statistics::of(samples.iter().map(|s| s.field_error)),
        near_field_error: Statistics::of(samples.iter().map(|s| s.near_field_error)),
        samples,
    })
}

/// A uniformly distributed point of the accessible surface.
fn random_point(rng: &mut fastrand::Rng, areas: &[f64], total: f64) -> SurfacePoint {
    let mut target = rng.f64() * total;
    let triangle = areas
        .iter()
        .position(|&a| {
            target -= a;
            target <= 0.0
        })
        .unwrap_or(areas.len() - 1);
    let (mut a, mut b) = (rng.f64(), rng.f64());
    if a + b > 1.0 {
        (a, b) = (1.0 - a, 1.0 - b);
    }
    SurfacePoint {
        triangle,
        barycentric: [1.0 - a - b, a, b],
    }
}

fn sample(
    model: &FemModel,
    vademecum: &Vademecum,
    kernel: &PatchKernel,
    at: &SurfacePoint,
    rng: &mut fastrand::Rng,
    settings: &ValidationSettings,
) -> Result<Sample, FemError> {
    let mesh = model.mesh();
    let corners =
        vademecum.triangles[at.triangle].map(|m| vademecum.positions[m as usize] as usize);
    let point = corners
        .iter()
        .zip(at.barycentric)
        .fold(Point3::origin(), |p, (&n, l)| {
            p + mesh.nodes()[n].coords * l
        });
    let direction = tilted_inward(
        rng,
        -area_vector(mesh.nodes(), &corners).normalize(),
        settings,
    );
    let (low, high) = settings.indentation_range_m;
    let indentation_m = low + (high - low) * rng.f64();
    // The linear compliance along the direction sets the force for the wanted indentation.
    let stiffness =
        direction.dot(&(vademecum.step_compliance(0, &vademecum.patch(at)) * direction));
    let force = direction * (indentation_m / stiffness);

    let shares = kernel.shares(point, &vademecum.triangle_facing(at.triangle))?;
    let mut loads = Loads::new(mesh.node_count());
    for &(node, share) in &shares {
        loads.add_nodal_force(node, (force * share).into())?;
    }
    let newton = NewtonSettings {
        load_steps: settings.newton_load_steps,
        ..NewtonSettings::default()
    };
    let reference = model.solve_static(&loads, &newton)?.displacement_m;
    let under_tool = shares.iter().fold(Vector3::zeros(), |acc, &(n, share)| {
        acc + Vector3::new(reference[3 * n], reference[3 * n + 1], reference[3 * n + 2]) * share
    });

    let rendered = vademecum.force_for_indentation(at, &under_tool);
    let field = vademecum.field(at, &rendered);
    let near = |n: usize| (mesh.nodes()[n] - point).norm() <= settings.near_radius_m;
    Ok(Sample {
        point_m: point.coords.into(),
        force_n: force.into(),
        indentation_m: under_tool.norm(),
        force_error: (rendered - force).norm() / force.norm(),
        field_error: relative_error(&field, &reference, |_| true),
        near_field_error: relative_error(&field, &reference, near),
    })
}

/// A unit vector within `max_tilt_deg` of `inward`, uniformly spread in azimuth.
fn tilted_inward(
    rng: &mut fastrand::Rng,
    inward: Vector3<f64>,
    settings: &ValidationSettings,
) -> Vector3<f64> {
    let helper = if inward.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = inward.cross(&helper).normalize();
    let e2 = inward.cross(&e1);
    let tilt = settings.max_tilt_deg.to_radians() * rng.f64();
    let azimuth = std::f64::consts::TAU * rng.f64();
    inward * tilt.cos() + (e1 * azimuth.cos() + e2 * azimuth.sin()) * tilt.sin()
}

/// `‖a − b‖ / ‖b‖` over the nodes `keep` selects.
fn relative_error(a: &[f64], b: &[f64], keep: impl Fn(usize) -> bool) -> f64 {
    let (mut diff, mut norm) = (0.0, 0.0);
    for n in (0..b.len() / 3).filter(|&n| keep(n)) {
        for c in 3 * n..3 * n + 3 {
            diff += (a[c] - b[c]).powi(2);
            norm += b[c] * b[c];
        }
    }
    if norm > 0.0 {
        (diff / norm).sqrt()
    } else {
        0.0
    }
}
