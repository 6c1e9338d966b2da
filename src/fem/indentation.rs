//! Displacement-controlled indentation by a rigid sphere: the full nonlinear reference for the
//! force a trainee feels, `F(δ)` at any surface point and depth.
//!
//! Contact is frictionless, between the sphere and the surface nodes, enforced by an augmented
//! Lagrangian: within one Newton solve each node in contact is pushed out along the sphere's
//! normal by `p = max(0, λ − k g)` (`g` its signed distance to the sphere, `k` a penalty), and
//! between solves the multipliers take the converged pushes, `λ ← p`, until no node is deeper
//! inside than the stated tolerance. The penalty alone would leave a penetration of `p / k`;
//! the multipliers remove it without the ill-conditioning of a huge `k`. The pushes derive from
//! the potential `Σ p² / 2k`, so Newton's energy line search applies unchanged.

use nalgebra::{Matrix3, Point3, Vector3};

use super::linear_solver::DirectSolver;
use super::newton::ExtraForce;
use super::{FemError, FemModel, NewtonSettings, StepReport};

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
    /// Penalty per node, `k = factor · E · √A` (E the material's Young's modulus, A the node's
    /// lumped surface area): a node's own stiffness scales as `E h`.
    pub penalty_factor: f64,
    /// Multiplier updates stop once no node is inside the sphere deeper than this fraction of
    /// the depth.
    pub penetration_tolerance: f64,
    pub max_augmentations: usize,
    /// Newton's settings for each solve (`load_steps` is unused: the depths are the steps).
    pub newton: NewtonSettings,
}

impl Default for IndentationSettings {
    fn default() -> Self {
        Self {
            penalty_factor: 10.0,
            penetration_tolerance: 1e-3,
            max_augmentations: 20,
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
    /// Nodes pushed by the sphere.
    pub contact_nodes: usize,
    /// The deepest node inside the sphere (m), after the last multiplier update.
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
}

impl FemModel {
    /// Presses `indenter` into the body to each of `depths_m` in turn (increasing, positive),
    /// against the surface nodes `surface_nodes` with lumped areas `areas_m2`, and reports the
    /// equilibrium at each depth. The depths are the load steps: space them finely enough for
    /// Newton (a tenth of the sphere's radius is safe).
    pub fn indent(
        &self,
        (surface_nodes, areas_m2): (&[usize], &[f64]),
        indenter: &SphereIndenter,
        depths_m: &[f64],
        settings: &IndentationSettings,
    ) -> Result<Indentation, FemError> {
        check_depths(depths_m)?;
        let young_pa = self.material().young_pa;
        let mut contact = SphereContact {
            nodes: surface_nodes.to_vec(),
            penalty: areas_m2
                .iter()
                .map(|a| settings.penalty_factor * young_pa * a.sqrt())
                .collect(),
            multipliers: vec![0.0; surface_nodes.len()],
            center: indenter.center(0.0),
            radius_m: indenter.radius_m,
        };
        let mut solver = DirectSolver::new(self.pattern())?;
        let mut u = self.dirichlet().scaled_values(1.0);
        let f_ext = vec![0.0; u.len()];
        let mut curve = Vec::with_capacity(depths_m.len());
        // The last equilibrium, and the step that led to it: the predictor of the next one.
        let mut converged = (0.0, u.clone());
        let mut increment: Option<(f64, Vec<f64>)> = None;
        for (index, &depth_m) in depths_m.iter().enumerate() {
            contact.center = indenter.center(depth_m);
            // Extrapolating the last step starts Newton with the surface near the sphere rather
            // than deep inside it, where the first iterations would crush the elements there.
            if let Some((step_m, du)) = &increment {
                let scale = (depth_m - converged.0) / step_m;
                for (value, change) in u.iter_mut().zip(du) {
                    *value += change * scale;
                }
            }
            let step = (index + 1, depths_m.len());
            let mut point = ForceDepthPoint {
                depth_m,
                force_n: 0.0,
                contact_nodes: 0,
                penetration_m: f64::INFINITY,
                augmentations: 0,
                newton_iterations: 0,
            };
            while point.penetration_m > settings.penetration_tolerance * depth_m
                && point.augmentations < settings.max_augmentations
            {
                let report: StepReport = self.equilibrate(
                    &mut solver,
                    &mut u,
                    &f_ext,
                    &contact,
                    step,
                    &settings.newton,
                )?;
                point.newton_iterations += report.step_lengths.len();
                point.augmentations += 1;
                point.penetration_m = contact.update_multipliers(self, &u);
            }
            (point.force_n, point.contact_nodes) =
                contact.total_push(self, &u, &indenter.direction);
            curve.push(point);
            let du = u.iter().zip(&converged.1).map(|(a, b)| a - b).collect();
            increment = Some((depth_m - converged.0, du));
            converged = (depth_m, u.clone());
        }
        Ok(Indentation {
            curve,
            displacement_m: u,
        })
    }
}

/// The sphere's frictionless push on the surface nodes at one depth.
struct SphereContact {
    nodes: Vec<usize>,
    penalty: Vec<f64>,
    multipliers: Vec<f64>,
    center: Point3<f64>,
    radius_m: f64,
}

impl SphereContact {
    /// For each node the sphere pushes: its index in `nodes`, the outward normal from the
    /// centre, its distance from the centre and the push `p > 0` (N).
    fn pushes<'a>(
        &'a self,
        model: &'a FemModel,
        u_m: &'a [f64],
    ) -> impl Iterator<Item = (usize, Vector3<f64>, f64, f64)> + 'a {
        self.nodes.iter().enumerate().filter_map(move |(i, &n)| {
            let x =
                model.mesh().nodes()[n] + Vector3::new(u_m[3 * n], u_m[3 * n + 1], u_m[3 * n + 2]);
            let offset = x - self.center;
            let distance = offset.norm();
            let push = self.multipliers[i] - self.penalty[i] * (distance - self.radius_m);
            (push > 0.0 && distance > 0.0).then(|| (i, offset / distance, distance, push))
        })
    }

    /// Sets each multiplier to its node's converged push; returns the deepest penetration (m).
    fn update_multipliers(&mut self, model: &FemModel, u_m: &[f64]) -> f64 {
        let pushes: Vec<(usize, f64, f64)> = self
            .pushes(model, u_m)
            .map(|(i, _, distance, push)| (i, distance, push))
            .collect();
        self.multipliers.fill(0.0);
        let mut deepest: f64 = 0.0;
        for (i, distance, push) in pushes {
            self.multipliers[i] = push;
            deepest = deepest.max(self.radius_m - distance);
        }
        deepest
    }

    /// The total push along `direction` (N) and the number of nodes pushed.
    fn total_push(&self, model: &FemModel, u_m: &[f64], direction: &Vector3<f64>) -> (f64, usize) {
        self.pushes(model, u_m)
            .fold((0.0, 0), |(force, count), (_, normal, _, push)| {
                (force + push * normal.dot(direction), count + 1)
            })
    }
}

impl ExtraForce for SphereContact {
    /// The push `p n` on a node resists as `−p n`; its derivative is
    /// `k n nᵀ − (p / r)(I − n nᵀ)` (the second term: the sphere's surface turns away
    /// from a node that slides around it).
    fn add(
        &self,
        model: &FemModel,
        u_m: &[f64],
        force: &mut [f64],
        mut tangent: Option<&mut [f64]>,
    ) {
        for (i, normal, distance, push) in self.pushes(model, u_m) {
            let n = self.nodes[i];
            for c in 0..3 {
                force[3 * n + c] -= push * normal[c];
            }
            if let Some(values) = tangent.as_deref_mut() {
                let outer = normal * normal.transpose();
                let block =
                    outer * self.penalty[i] - (Matrix3::identity() - outer) * (push / distance);
                model
                    .pattern()
                    .add_node_block(model.dofs(), n, &block, values);
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
