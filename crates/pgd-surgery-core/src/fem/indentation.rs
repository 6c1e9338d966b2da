//! Displacement-controlled indentation by a rigid sphere: the full nonlinear reference for the
//! force a trainee feels, `F(δ)` at any surface point and depth.
//!
//! Contact is frictionless, between the sphere and points sampled over the surface triangles
//! (a few per sphere radius, so that a sphere smaller than the triangles cannot slip between
//! their nodes), enforced by an augmented Lagrangian: within one Newton solve each point in
//! contact is pushed out along the sphere's normal by the pressure `p = max(0, λ − κ g)` over
//! the area it stands for (`g` its signed distance to the sphere, `κ` a penalty), shared among
//! its triangle's nodes by its barycentric weights; between solves the multipliers take the
//! converged pressures, `λ ← p`, until no point is deeper inside than the stated tolerance. The
//! penalty alone would leave a penetration of `p / κ`; the multipliers remove it without the
//! ill-conditioning of a huge `κ`. The pushes derive from the potential `Σ a p² / 2κ`, so
//! Newton's energy line search applies unchanged.

use nalgebra::{Matrix3, Point3, Vector3};

use super::newton::ExtraForce;
use super::tangent_solver::TangentSolver;
use super::{FemError, FemModel, NewtonSettings};

/// A rigid sphere pressed into a body along a straight line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereIndenter {
    pub radius_m: f64,
    /// Where the sphere first touches the undeformed surface.
    pub contact_point: Point3<f64>,
    /// Unit direction of travel, into the body.
    pub direction: Vector3<f64>,
}

impl SphereIndenter {
    /// The sphere touching the surface at `contact_point`, moving along `direction` (any
    /// length; normalized here). Refuses a radius or direction that is not positive and finite.
    pub fn new(
        radius_m: f64,
        contact_point: Point3<f64>,
        direction: Vector3<f64>,
    ) -> Result<Self, FemError> {
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return Err(FemError::InvalidInput {
                what: "indenter radius_m",
                value: radius_m,
                problem: "not a positive, finite length",
            });
        }
        let length = direction.norm();
        if !(length.is_finite() && length > 0.0) {
            return Err(FemError::InvalidInput {
                what: "indentation direction length",
                value: length,
                problem: "not a positive, finite length",
            });
        }
        Ok(Self {
            radius_m,
            contact_point,
            direction: direction / length,
        })
    }

    /// The sphere's centre at indentation depth `depth_m`.
    pub fn center(&self, depth_m: f64) -> Point3<f64> {
        self.contact_point + self.direction * (depth_m - self.radius_m)
    }
}

/// How an indentation is solved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndentationSettings {
    /// Penalty `κ = factor · E / h` (Pa/m; E the material's Young's modulus, h the square root
    /// of the triangle's area): the pressure a layer of tissue one element thick answers a
    /// unit penetration with, times the factor.
    pub penalty_factor: f64,
    /// Contact points per sphere radius along a triangle's edges (at least one per triangle).
    pub samples_per_radius: f64,
    /// Multiplier updates stop once no node is inside the sphere deeper than this fraction of
    /// the depth.
    pub penetration_tolerance: f64,
    pub max_augmentations: usize,
    /// Times a depth step without equilibrium is halved before the curve stops there.
    pub max_bisections: usize,
    /// Newton's settings for each solve (`load_steps` is unused: the depths are the steps).
    pub newton: NewtonSettings,
}

impl Default for IndentationSettings {
    fn default() -> Self {
        Self {
            penalty_factor: 10.0,
            samples_per_radius: 6.0,
            penetration_tolerance: 1e-3,
            max_augmentations: 20,
            max_bisections: 4,
            newton: NewtonSettings {
                relative_tolerance: 1e-8,
                max_iterations: 40,
                ..NewtonSettings::default()
            },
        }
    }
}

/// The equilibrium at one depth.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceDepthPoint {
    pub depth_m: f64,
    /// The force the sphere needs along its direction of travel (N).
    pub force_n: f64,
    /// Surface points pushed by the sphere.
    pub contact_points: usize,
    /// The deepest surface point inside the sphere (m), after the last multiplier update.
    pub penetration_m: f64,
    /// Multiplier updates and Newton iterations it took.
    pub augmentations: usize,
    pub newton_iterations: usize,
}

/// A force–depth curve and the displacement (m, every dof) at its deepest point.
#[derive(Clone, Debug, PartialEq)]
pub struct Indentation {
    pub curve: Vec<ForceDepthPoint>,
    pub displacement_m: Vec<f64>,
    /// The depth (m) where no equilibrium was found, and why: the curve stops before it (a
    /// law that loses stability under compression, such as Kirchhoff–Saint Venant, does).
    pub stopped: Option<(f64, FemError)>,
}

impl FemModel {
    /// Presses `indenter` into the body to each of `depths_m` in turn (increasing, positive),
    /// against the surface triangles `triangles` (volume numbering), and reports the
    /// equilibrium at each depth to `on_depth` and in the result. The depths are the load
    /// steps (a tenth of the sphere's radius apart is safe); one without equilibrium is
    /// reached through halfway depths, up to `max_bisections` halvings, and then ends the
    /// curve (see [`Indentation::stopped`]). Bad input is an error.
    pub fn indent(
        &self,
        triangles: &[[usize; 3]],
        indenter: &SphereIndenter,
        depths_m: &[f64],
        settings: &IndentationSettings,
        on_depth: &mut dyn FnMut(&ForceDepthPoint),
    ) -> Result<Indentation, FemError> {
        check_depths(depths_m)?;
        let spacing_m = indenter.radius_m / settings.samples_per_radius;
        let samples = sample_triangles(self.mesh(), triangles, spacing_m);
        let young_pa = self.material().young_pa;
        let contact = SphereContact {
            penalty_pa_per_m: samples
                .iter()
                .map(|s| settings.penalty_factor * young_pa / s.face_size_m)
                .collect(),
            multipliers_pa: vec![0.0; samples.len()],
            samples,
            center: indenter.center(0.0),
            radius_m: indenter.radius_m,
        };
        let mut press = Press {
            solver: TangentSolver::direct(self.pattern())?,
            u: self.dirichlet().scaled_values(1.0),
            contact,
            settings,
        };
        let mut curve = Vec::with_capacity(depths_m.len());
        // The last equilibrium (depth, displacement, multipliers), and the step that led to it:
        // the predictor of the next one.
        let mut converged = (0.0, press.u.clone(), press.contact.multipliers_pa.clone());
        let mut increment: Option<(f64, Vec<f64>)> = None;
        for (index, &target_m) in depths_m.iter().enumerate() {
            // Depths still to reach on the way to the target, the nearest last: a depth
            // without equilibrium is retried after one halfway to it.
            let mut pending = vec![target_m];
            while let Some(&depth_m) = pending.last() {
                press.contact.center = indenter.center(depth_m);
                // Extrapolating the last step starts Newton with the surface near the sphere
                // rather than deep inside it, where the first iterations would crush the
                // elements there.
                if let Some((step_m, du)) = &increment {
                    let scale = (depth_m - converged.0) / step_m;
                    for (value, change) in press.u.iter_mut().zip(du) {
                        *value += change * scale;
                    }
                }
                let step = (index + 1, depths_m.len());
                match press.settle(self, depth_m, step) {
                    Ok(mut point) => {
                        pending.pop();
                        (point.force_n, point.contact_points) =
                            press
                                .contact
                                .total_push(self, &press.u, &indenter.direction);
                        let du = press
                            .u
                            .iter()
                            .zip(&converged.1)
                            .map(|(a, b)| a - b)
                            .collect();
                        increment = Some((depth_m - converged.0, du));
                        converged = (
                            depth_m,
                            press.u.clone(),
                            press.contact.multipliers_pa.clone(),
                        );
                        if pending.is_empty() {
                            on_depth(&point);
                            curve.push(point);
                        }
                    }
                    Err(error) if pending.len() > settings.max_bisections => {
                        return Ok(Indentation {
                            curve,
                            displacement_m: converged.1,
                            stopped: Some((target_m, error)),
                        });
                    }
                    Err(_) => {
                        press.u.clone_from(&converged.1);
                        press.contact.multipliers_pa.clone_from(&converged.2);
                        pending.push(0.5 * (converged.0 + depth_m));
                    }
                }
            }
        }
        Ok(Indentation {
            curve,
            displacement_m: press.u,
            stopped: None,
        })
    }
}

/// The state of one indentation between depths.
struct Press<'a> {
    solver: TangentSolver<'static>,
    u: Vec<f64>,
    contact: SphereContact,
    settings: &'a IndentationSettings,
}

impl Press<'_> {
    /// Newton solves and multiplier updates at one depth (the contact's centre already there)
    /// until no surface point is deeper inside the sphere than the tolerance. The force is
    /// left for the caller.
    fn settle(
        &mut self,
        model: &FemModel,
        depth_m: f64,
        step: (usize, usize),
    ) -> Result<ForceDepthPoint, FemError> {
        let f_ext = vec![0.0; self.u.len()];
        let mut point = ForceDepthPoint {
            depth_m,
            force_n: 0.0,
            contact_points: 0,
            penetration_m: f64::INFINITY,
            augmentations: 0,
            newton_iterations: 0,
        };
        while point.penetration_m > self.settings.penetration_tolerance * depth_m
            && point.augmentations < self.settings.max_augmentations
        {
            // Each solve starts from an equilibrium or near one: a tangent that was indefinite
            // on an earlier solve's first iterations says nothing of this one's.
            self.solver.expect_definite();
            let report = model.equilibrate(
                &mut self.solver,
                &mut self.u,
                &f_ext,
                &self.contact,
                step,
                &self.settings.newton,
            )?;
            point.newton_iterations += report.step_lengths.len();
            point.augmentations += 1;
            point.penetration_m = self.contact.update_multipliers(model, &self.u);
        }
        Ok(point)
    }
}

/// A point of a surface triangle the sphere may push.
struct Sample {
    nodes: [usize; 3],
    /// Barycentric weights of the point in its triangle.
    weights: [f64; 3],
    /// The share of the triangle's area the point stands for (m²).
    area_m2: f64,
    /// The square root of its triangle's area (m).
    face_size_m: f64,
}

/// Points over each triangle, no farther apart than `spacing_m`: the vertices of its regular
/// subdivision into `m²` triangles, each standing for a third of the small triangles around it.
/// With `m = 1` these are the triangle's corners with a third of its area each, the lumped
/// nodal areas; a node shared by several triangles gets a point from each.
fn sample_triangles(
    mesh: &crate::mesh::TetMesh,
    triangles: &[[usize; 3]],
    spacing_m: f64,
) -> Vec<Sample> {
    let mut samples = Vec::new();
    for &nodes in triangles {
        let p = nodes.map(|n| mesh.nodes()[n]);
        let longest = [(0, 1), (1, 2), (2, 0)]
            .iter()
            .map(|&(a, b)| (p[a] - p[b]).norm())
            .fold(0.0, f64::max);
        let area_m2 = 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
        let m = (longest / spacing_m).ceil().max(1.0) as usize;
        let third = area_m2 / (3 * m * m) as f64;
        for i in 0..=m {
            for j in 0..=m - i {
                let on_edges = [i == 0, j == 0, i + j == m].iter().filter(|&&e| e).count();
                let around = [6, 3, 1][on_edges];
                let (u, v) = (i as f64 / m as f64, j as f64 / m as f64);
                samples.push(Sample {
                    nodes,
                    weights: [1.0 - u - v, u, v],
                    area_m2: around as f64 * third,
                    face_size_m: area_m2.sqrt(),
                });
            }
        }
    }
    samples
}

/// The sphere's frictionless push on the surface points at one depth.
struct SphereContact {
    samples: Vec<Sample>,
    penalty_pa_per_m: Vec<f64>,
    multipliers_pa: Vec<f64>,
    center: Point3<f64>,
    radius_m: f64,
}

impl SphereContact {
    /// For each point the sphere pushes: its index in `samples`, the outward normal from the
    /// centre, its distance from the centre and the push `p > 0` (N).
    fn pushes<'a>(
        &'a self,
        model: &'a FemModel,
        u_m: &'a [f64],
    ) -> impl Iterator<Item = (usize, Vector3<f64>, f64, f64)> + 'a {
        let position = |n: usize| {
            model.mesh().nodes()[n].coords
                + Vector3::new(u_m[3 * n], u_m[3 * n + 1], u_m[3 * n + 2])
        };
        self.samples.iter().enumerate().filter_map(move |(i, s)| {
            let x: Vector3<f64> = (0..3).map(|k| position(s.nodes[k]) * s.weights[k]).sum();
            let offset = x - self.center.coords;
            let distance = offset.norm();
            let pressure =
                self.multipliers_pa[i] - self.penalty_pa_per_m[i] * (distance - self.radius_m);
            (pressure > 0.0 && distance > 0.0)
                .then(|| (i, offset / distance, distance, pressure * s.area_m2))
        })
    }

    /// Sets each multiplier to its point's converged pressure; returns the deepest
    /// penetration (m).
    fn update_multipliers(&mut self, model: &FemModel, u_m: &[f64]) -> f64 {
        let pushes: Vec<(usize, f64, f64)> = self
            .pushes(model, u_m)
            .map(|(i, _, distance, push)| (i, distance, push))
            .collect();
        self.multipliers_pa.fill(0.0);
        let mut deepest: f64 = 0.0;
        for (i, distance, push) in pushes {
            self.multipliers_pa[i] = push / self.samples[i].area_m2;
            deepest = deepest.max(self.radius_m - distance);
        }
        deepest
    }

    /// The total push along `direction` (N) and the number of points pushed.
    fn total_push(&self, model: &FemModel, u_m: &[f64], direction: &Vector3<f64>) -> (f64, usize) {
        self.pushes(model, u_m)
            .fold((0.0, 0), |(force, count), (_, normal, _, push)| {
                (force + push * normal.dot(direction), count + 1)
            })
    }
}

impl ExtraForce for SphereContact {
    /// The push `p n` at a point resists as `−w_a p n` on its triangle's node `a`; its
    /// derivative with respect to node `b` is `w_a w_b [a κ n nᵀ − (p / r)(I − n nᵀ)]` (the
    /// second term: the sphere's surface turns away from a point that slides around it).
    fn add(
        &self,
        model: &FemModel,
        u_m: &[f64],
        force: &mut [f64],
        mut tangent: Option<&mut [f64]>,
    ) {
        for (i, normal, distance, push) in self.pushes(model, u_m) {
            let sample = &self.samples[i];
            for (&n, w) in sample.nodes.iter().zip(sample.weights) {
                for c in 0..3 {
                    force[3 * n + c] -= w * push * normal[c];
                }
            }
            let Some(values) = tangent.as_deref_mut() else {
                continue;
            };
            let outer = normal * normal.transpose();
            let block = outer * (sample.area_m2 * self.penalty_pa_per_m[i])
                - (Matrix3::identity() - outer) * (push / distance);
            for (&a, wa) in sample.nodes.iter().zip(sample.weights) {
                for (&b, wb) in sample.nodes.iter().zip(sample.weights) {
                    model.pattern().add_node_block(
                        model.dofs(),
                        (a, b),
                        &(block * (wa * wb)),
                        values,
                    );
                }
            }
        }
    }
}

fn check_depths(depths_m: &[f64]) -> Result<(), FemError> {
    let mut previous = 0.0;
    for &depth in depths_m {
        if !(depth.is_finite() && depth > previous) {
            return Err(FemError::InvalidInput {
                what: "indentation depth_m",
                value: depth,
                problem: "not positive, finite and deeper than the depth before it",
            });
        }
        previous = depth;
    }
    Ok(())
}
