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
use crate::mesh::{Surface, TetMesh, area_vector};

#[derive(Clone, Debug, PartialEq)]
pub struct ValidationSettings {
    pub samples: usize,
    pub seed: u64,
    /// Indentations are drawn uniformly in this range (m) of the tool's linear depth, cut
    /// at the vademecum's range at each point (where the trainer starts holding the force).
    pub indentation_range_m: (f64, f64),
    /// Directions deviate from the inward normal by up to this angle.
    pub max_tilt_deg: f64,
    /// The "field near the tool" is measured on nodes within this distance (m).
    pub near_radius_m: f64,
    /// Load steps of the reference Newton solve (KSV).
    pub newton_load_steps: usize,
    /// Presses along the inward normal drawn as force–depth curves, each at its own random
    /// point, after the samples.
    pub curves: usize,
    /// Force levels per curve, up to the deepest indentation of the range (linear), or the
    /// vademecum's range at the curve's point if shallower.
    pub curve_levels: usize,
    /// Press beyond the vademecum's range instead: each load's linear depth drawn between
    /// its point's range edge and the deepest indentation (at points whose edge lies
    /// shallower), the curves drawn to the deepest indentation. What the trainer
    /// extrapolates past its load steps is measured so.
    pub beyond_range: bool,
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
            curves: 2,
            curve_levels: 8,
            beyond_range: false,
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
    /// How far (degrees) the press is tilted off the inward normal.
    pub tilt_deg: f64,
    /// The felt force's error along the inward normal, signed, over `|F_fem|`: below zero
    /// the vademecum feels softer than full FEM there.
    pub along_normal_error: f64,
    /// The error of the felt force's magnitude across the normal, signed, over `|F_fem|`:
    /// below zero the vademecum feels softer than full FEM sideways.
    pub across_normal_error: f64,
    /// Relative L2 error of the displacement over the whole organ.
    pub field_error: f64,
    /// Relative L2 error over the nodes near the tool.
    pub near_field_error: f64,
    /// How deep (m) the tool's patch at the point is pressed along the inward normal,
    /// linearly, at the edge of the range its load steps answer (infinite for a linear
    /// vademecum).
    pub range_edge_m: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ValidationReport {
    /// Whether the loads pressed beyond the vademecum's range
    /// ([`ValidationSettings::beyond_range`]) rather than within it.
    pub beyond_range: bool,
    /// The radius (m) of the "near the tool" region `near_field_error` is measured over.
    pub near_radius_m: f64,
    pub force_error: Statistics,
    pub field_error: Statistics,
    pub near_field_error: Statistics,
    /// The samples' range edges (m; a nonlinear vademecum only): how deep the steps answer
    /// across the surface, in the tool's own linear depth.
    pub range_edge_m: Option<Statistics>,
    pub samples: Vec<Sample>,
    pub curves: Vec<ForceDepthCurve>,
}

/// A press along the inward normal at one point: the force levels full FEM was loaded with,
/// the indentation it made under the tool at each, and the force the vademecum renders for
/// that indentation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ForceDepthCurve {
    pub point_m: [f64; 3],
    /// Full FEM's indentation under the tool along the press (m), per force level.
    pub depth_m: Vec<f64>,
    /// Full FEM's whole displacement under the tool (m), per force level: the indentation
    /// the vademecum answers (sideways too).
    pub indentation_m: Vec<[f64; 3]>,
    pub fem_force_n: Vec<f64>,
    /// The vademecum's force along the press (N) for full FEM's indentation.
    pub vademecum_force_n: Vec<f64>,
    /// Why full FEM stopped before the last force level (a law that loses stability, as
    /// KSV does under compression), if it did.
    pub stopped: Option<String>,
}

impl ForceDepthCurve {
    /// The largest `|F_vademecum − F_fem| / F_fem` along the curve.
    pub fn max_force_error(&self) -> f64 {
        self.fem_force_n
            .iter()
            .zip(&self.vademecum_force_n)
            .map(|(f, v)| (v - f).abs() / f)
            .fold(0.0, f64::max)
    }
}

/// Compares `vademecum` with full FEM on `model` (the mesh it was built for).
pub fn validate(
    model: &FemModel,
    vademecum: &Vademecum,
    settings: &ValidationSettings,
    progress: &dyn Progress,
) -> Result<ValidationReport, FemError> {
    if settings.beyond_range && vademecum.steps.len() == 1 {
        return Err(FemError::InvalidInput {
            what: "vademecum: nonlinear load steps to press beyond",
            value: 0.0,
            problem: "too few; --beyond-range needs a nonlinear vademecum",
        });
    }
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
    progress.start(
        "full FEM references",
        (settings.samples + settings.curves) as u64,
    );
    let mut samples = Vec::with_capacity(settings.samples);
    let drawn =
        |rng: &mut fastrand::Rng| point_to_press(rng, &areas, total_area, vademecum, settings);
    for _ in 0..settings.samples {
        let at = drawn(&mut rng)?;
        samples.push(sample(model, vademecum, &kernel, &at, &mut rng, settings)?);
        progress.advance(1);
    }
    let mut curves = Vec::with_capacity(settings.curves);
    for _ in 0..settings.curves {
        let at = drawn(&mut rng)?;
        curves.push(force_depth_curve(model, vademecum, &kernel, &at, settings)?);
        progress.advance(1);
    }
    Ok(ValidationReport {
        beyond_range: settings.beyond_range,
        near_radius_m: settings.near_radius_m,
        force_error: Statistics::of(samples.iter().map(|s| s.force_error)),
        field_error: Statistics::of(samples.iter().map(|s| s.field_error)),
        near_field_error: Statistics::of(samples.iter().map(|s| s.near_field_error)),
        range_edge_m: (vademecum.steps.len() > 1)
            .then(|| Statistics::of(samples.iter().map(|s| s.range_edge_m))),
        samples,
        curves,
    })
}

/// The force–depth curve at `at` alone, full FEM against the vademecum, as `validate` draws
/// at random points: for a point that matters, such as the surface over a nodule.
pub fn force_depth_curve_at(
    model: &FemModel,
    vademecum: &Vademecum,
    at: &SurfacePoint,
    settings: &ValidationSettings,
) -> Result<ForceDepthCurve, FemError> {
    let surface = Surface::extract(model.mesh());
    let kernel = PatchKernel::new(
        model.mesh(),
        &surface,
        vademecum.header.settings.tool_tip_radius_m,
    )?;
    force_depth_curve(model, vademecum, &kernel, at, settings)
}

/// Draws of [`point_to_press`] before it gives up.
const MAX_DRAWS: usize = 10_000;

/// A uniformly distributed point of the accessible surface where the vademecum's range is not
/// empty (every point of a linear one): a patch of positions the first nonlinear step did not
/// reach answers linearly from the start, and there is no nonlinear answer there to check.
/// Pressing beyond the range, the range's edge along the inward normal must also lie
/// shallower than the deepest indentation.
fn point_to_press(
    rng: &mut fastrand::Rng,
    areas: &[f64],
    total: f64,
    vademecum: &Vademecum,
    settings: &ValidationSettings,
) -> Result<SurfacePoint, FemError> {
    let deepest_m = settings.indentation_range_m.1;
    let pressable = |at: &SurfacePoint| {
        let edge_n = vademecum.range_force_n(&vademecum.patch(at));
        edge_n > 0.0
            && (!settings.beyond_range || {
                let inward = -vademecum.triangle_facing(at.triangle).normalize();
                range_edge_m(vademecum, at, &inward) < deepest_m
            })
    };
    for _ in 0..MAX_DRAWS {
        let at = random_point(rng, areas, total);
        if pressable(&at) {
            return Ok(at);
        }
    }
    let (what, problem) = match settings.beyond_range {
        false => (
            "vademecum: surface points in its nonlinear range among those drawn",
            "too few to validate; its first nonlinear step reached almost no position",
        ),
        true => (
            "vademecum: surface points whose range ends shallower than the deepest indentation",
            "too few to press beyond the range; ask for a deeper indentation",
        ),
    };
    Err(FemError::InvalidInput {
        what,
        value: 0.0,
        problem,
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

/// A surface point's rest coordinates and inward normal (of its triangle).
fn point_and_inward(
    mesh: &TetMesh,
    vademecum: &Vademecum,
    at: &SurfacePoint,
) -> (Point3<f64>, Vector3<f64>) {
    let corners =
        vademecum.triangles[at.triangle].map(|m| vademecum.positions[m as usize] as usize);
    let point = corners
        .iter()
        .zip(at.barycentric)
        .fold(Point3::origin(), |p, (&n, l)| {
            p + mesh.nodes()[n].coords * l
        });
    (point, -area_vector(mesh.nodes(), &corners).normalize())
}

/// The force (N) along `direction` whose linear response is `indentation_m` deep at `at`.
fn linear_force(
    vademecum: &Vademecum,
    at: &SurfacePoint,
    direction: &Vector3<f64>,
    indentation_m: f64,
) -> Vector3<f64> {
    direction * (indentation_m / linear_compliance(vademecum, at, direction))
}

/// The tool's linear compliance (m/N) at `at` along `direction`.
fn linear_compliance(vademecum: &Vademecum, at: &SurfacePoint, direction: &Vector3<f64>) -> f64 {
    direction.dot(&(vademecum.step_compliance(0, &vademecum.patch(at)) * direction))
}

/// The deepest linear indentation (m) along `direction` at `at` that the vademecum answers,
/// `wanted_m` or its range's edge there if shallower: beyond it the felt force is
/// extrapolated from the last load-step interval, which the validation measures only when
/// asked to ([`ValidationSettings::beyond_range`]).
fn within_range_m(
    vademecum: &Vademecum,
    at: &SurfacePoint,
    direction: &Vector3<f64>,
    wanted_m: f64,
) -> f64 {
    wanted_m.min(range_edge_m(vademecum, at, direction))
}

/// The shallowest and deepest linear indentations (m) along `direction` at `at` that
/// `settings` press: within the range ([`within_range_m`]), or beyond it, from the range's
/// edge there to the deepest indentation.
fn indentations_m(
    vademecum: &Vademecum,
    at: &SurfacePoint,
    direction: &Vector3<f64>,
    settings: &ValidationSettings,
) -> (f64, f64) {
    let (shallowest_m, deepest_m) = settings.indentation_range_m;
    if settings.beyond_range {
        let edge_m = range_edge_m(vademecum, at, direction);
        return (edge_m, deepest_m.max(edge_m));
    }
    let high = within_range_m(vademecum, at, direction, deepest_m);
    (shallowest_m.min(high), high)
}

/// The linear indentation (m) along `direction` at `at` at the edge of the vademecum's range.
fn range_edge_m(vademecum: &Vademecum, at: &SurfacePoint, direction: &Vector3<f64>) -> f64 {
    vademecum.range_force_n(&vademecum.patch(at)) * linear_compliance(vademecum, at, direction)
}

/// `force` spread over the tool's patch at `point`, and the patch's nodal shares.
fn patch_loads(
    mesh: &TetMesh,
    kernel: &PatchKernel,
    point: Point3<f64>,
    facing: &Vector3<f64>,
    force: &Vector3<f64>,
) -> Result<(Loads, Vec<(usize, f64)>), FemError> {
    let shares = kernel.shares(point, facing)?;
    let mut loads = Loads::new(mesh.node_count());
    for &(node, share) in &shares {
        loads.add_nodal_force(node, (force * share).into())?;
    }
    Ok((loads, shares))
}

/// The displacement under the tool: the patch's share-weighted mean.
fn under_tool(displacement_m: &[f64], shares: &[(usize, f64)]) -> Vector3<f64> {
    shares.iter().fold(Vector3::zeros(), |acc, &(n, share)| {
        acc + Vector3::new(
            displacement_m[3 * n],
            displacement_m[3 * n + 1],
            displacement_m[3 * n + 2],
        ) * share
    })
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
    let (point, inward) = point_and_inward(mesh, vademecum, at);
    let direction = tilted_inward(rng, inward, settings);
    let (low, high) = indentations_m(vademecum, at, &direction, settings);
    let indentation_m = low + (high - low) * rng.f64();
    // The linear compliance along the direction sets the force for the wanted indentation.
    let force = linear_force(vademecum, at, &direction, indentation_m);
    let facing = vademecum.triangle_facing(at.triangle);
    let (loads, shares) = patch_loads(mesh, kernel, point, &facing, &force)?;
    let newton = NewtonSettings {
        load_steps: settings.newton_load_steps,
        ..NewtonSettings::default()
    };
    let reference = model.solve_static(&loads, &newton)?.displacement_m;
    let under_tool = under_tool(&reference, &shares);

    let press = vademecum.patch_press_in_range(&mut vademecum.patch(at), &under_tool);
    let rendered = press.felt_n;
    // The field drawn follows the organ's load (beyond the range, the edge's secant answer).
    let field = vademecum.field(at, &press.force_n);
    let near = |n: usize| (mesh.nodes()[n] - point).norm() <= settings.near_radius_m;
    let (along, across) = normal_and_across(&rendered, &force, &inward);
    Ok(Sample {
        point_m: point.coords.into(),
        force_n: force.into(),
        indentation_m: under_tool.norm(),
        force_error: (rendered - force).norm() / force.norm(),
        tilt_deg: direction.angle(&inward).to_degrees(),
        along_normal_error: along,
        across_normal_error: across,
        field_error: relative_error(&field, &reference, |_| true),
        near_field_error: relative_error(&field, &reference, near),
        range_edge_m: range_edge_m(vademecum, at, &inward),
    })
}

/// The signed errors of `rendered` against `reference` along the unit `normal` and, in
/// magnitude, across it, both over `|reference|`: which way an oblique press is off.
fn normal_and_across(
    rendered: &Vector3<f64>,
    reference: &Vector3<f64>,
    normal: &Vector3<f64>,
) -> (f64, f64) {
    let across = |f: &Vector3<f64>| (f - normal * f.dot(normal)).norm();
    let scale = reference.norm();
    (
        (rendered - reference).dot(normal) / scale,
        (across(rendered) - across(reference)) / scale,
    )
}

/// Full FEM pressed along the inward normal at `at` in `curve_levels` equal force steps up to
/// the deepest indentation's linear force, one Newton path; the vademecum answers each step's
/// indentation.
fn force_depth_curve(
    model: &FemModel,
    vademecum: &Vademecum,
    kernel: &PatchKernel,
    at: &SurfacePoint,
    settings: &ValidationSettings,
) -> Result<ForceDepthCurve, FemError> {
    let mesh = model.mesh();
    let (point, inward) = point_and_inward(mesh, vademecum, at);
    let deepest_m = indentations_m(vademecum, at, &inward, settings).1;
    let force = linear_force(vademecum, at, &inward, deepest_m);
    let facing = vademecum.triangle_facing(at.triangle);
    let (loads, shares) = patch_loads(mesh, kernel, point, &facing, &force)?;
    let newton = NewtonSettings {
        load_steps: settings.curve_levels,
        ..NewtonSettings::default()
    };
    let mut curve = ForceDepthCurve {
        point_m: point.coords.into(),
        depth_m: Vec::new(),
        indentation_m: Vec::new(),
        fem_force_n: Vec::new(),
        vademecum_force_n: Vec::new(),
        stopped: None,
    };
    let path = model.solve_static_path(&loads, &newton, |factor, displacement_m| {
        let indentation = under_tool(displacement_m, &shares);
        let rendered = vademecum.force_for_indentation(at, &indentation);
        curve.depth_m.push(indentation.dot(&inward));
        curve.indentation_m.push(indentation.into());
        curve.fem_force_n.push(factor * force.norm());
        curve.vademecum_force_n.push(rendered.dot(&inward));
    });
    curve.stopped = path.err().map(|e| e.to_string());
    Ok(curve)
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
