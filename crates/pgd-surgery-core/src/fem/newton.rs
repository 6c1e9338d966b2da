//! Static equilibrium `f_int(u) = λ f_ext` by load stepping and Newton–Raphson with an
//! energy line search. The linear law is the special case that converges in one step.
//!
//! The line search works on `G(α) = du · r(u + α du)`, the slope of the potential energy along
//! the Newton direction, not on the residual norm: for bending-dominated bodies a good Newton
//! step briefly raises the stiff axial residuals, and a norm-based search would keep cutting
//! it, stalling far from equilibrium.

use super::tangent_solver::TangentSolver;
use super::{FemError, FemModel, Loads};
use crate::dense_sums::dot;

/// Halvings of a Newton step allowed to keep every element's volume positive (2⁻³⁰ ≈ 1e-9).
const MAX_HALVINGS: usize = 30;

/// The largest residual, relative to its right-hand side, an iterative solve may leave in a
/// Newton direction. Each direction is solved to `min(0.1, √ρ)`, `ρ` Newton's relative
/// residual: loose far from equilibrium, tight near it, which keeps Newton's convergence
/// superlinear (Eisenstat and Walker's forcing terms).
const MAX_FORCING: f64 = 0.1;

/// A conservative force on the body beside its elastic one, such as a rigid tool's contact.
/// It is added to the internal force as the body's resistance (a force pushing the body enters
/// with a minus sign), and its derivative to the tangent over free dofs.
pub(super) trait ExtraForce {
    fn add(&self, model: &FemModel, u_m: &[f64], force: &mut [f64], tangent: Option<&mut [f64]>);
}

/// The plain elastic problem.
struct NoExtraForce;

impl ExtraForce for NoExtraForce {
    fn add(&self, _: &FemModel, _: &[f64], _: &mut [f64], _: Option<&mut [f64]>) {}
}

/// How a static solve proceeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// The load (and prescribed displacement) is applied in this many equal increments.
    pub load_steps: usize,
    /// Newton iterations allowed per load step.
    pub max_iterations: usize,
    /// Converged when ‖r_free‖ ≤ tol · ‖reference force‖ (the reference is the larger of the
    /// external load and the reactions at prescribed dofs).
    pub relative_tolerance: f64,
    /// Secant iterations of the line search, accepting a step once `|G(α)| ≤ ½ G(0)`
    /// (0 = always take the full Newton step).
    pub max_line_search_iterations: usize,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            load_steps: 1,
            max_iterations: 30,
            relative_tolerance: 1e-10,
            max_line_search_iterations: 6,
        }
    }
}

/// What happened in one load step.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    /// Relative residual before each iteration, and after the last (so its last entry is the
    /// converged value).
    pub relative_residuals: Vec<f64>,
    /// Line-search factor of each accepted update (1 = full Newton step).
    pub step_lengths: Vec<f64>,
}

/// A converged equilibrium.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSolution {
    /// Displacement of every dof (m), prescribed values included.
    pub displacement_m: Vec<f64>,
    pub steps: Vec<StepReport>,
}

impl StaticSolution {
    /// Displacement of one node (m).
    pub fn node(&self, n: usize) -> [f64; 3] {
        [0, 1, 2].map(|c| self.displacement_m[3 * n + c])
    }
}

impl FemModel {
    /// Solves for static equilibrium under `loads` and the model's prescribed displacements.
    pub fn solve_static(
        &self,
        loads: &Loads,
        settings: &NewtonSettings,
    ) -> Result<StaticSolution, FemError> {
        self.solve_static_path(loads, settings, |_, _| {})
    }

    /// [`Self::solve_static`], handing `visit` each load step's equilibrium on the way (the
    /// step's load factor and the displacement): one solve gives a whole load–response curve.
    pub fn solve_static_path(
        &self,
        loads: &Loads,
        settings: &NewtonSettings,
        visit: impl FnMut(f64, &[f64]),
    ) -> Result<StaticSolution, FemError> {
        let mut solver = TangentSolver::direct(self.pattern())?;
        self.solve_static_path_with(&mut solver, loads, settings, visit)
    }

    /// [`Self::solve_static`] with Newton's linear systems solved by `solver`.
    pub fn solve_static_with(
        &self,
        solver: &mut TangentSolver,
        loads: &Loads,
        settings: &NewtonSettings,
    ) -> Result<StaticSolution, FemError> {
        self.solve_static_path_with(solver, loads, settings, |_, _| {})
    }

    fn solve_static_path_with(
        &self,
        solver: &mut TangentSolver,
        loads: &Loads,
        settings: &NewtonSettings,
        mut visit: impl FnMut(f64, &[f64]),
    ) -> Result<StaticSolution, FemError> {
        check_settings(settings)?;
        if loads.node_count() != self.mesh().node_count() {
            return Err(FemError::InvalidInput {
                what: "loads: node count",
                value: loads.node_count() as f64,
                problem: "not the mesh's node count",
            });
        }
        let mut u = vec![0.0; loads.as_slice().len()];
        let mut steps = Vec::with_capacity(settings.load_steps);
        for step in 1..=settings.load_steps {
            let factor = step as f64 / settings.load_steps as f64;
            let this = (step, settings.load_steps);
            let report = self.load_step(solver, &mut u, loads, factor, this, settings)?;
            visit(factor, &u);
            steps.push(report);
        }
        Ok(StaticSolution {
            displacement_m: u,
            steps,
        })
    }

    /// Newton in one increment from `start_m` (every dof; the prescribed ones are set here)
    /// to equilibrium under `loads`, its linear systems solved by `solver`: for a start
    /// already close to it, such as the solution at a slightly smaller load.
    pub fn solve_static_from(
        &self,
        start_m: Vec<f64>,
        loads: &Loads,
        settings: &NewtonSettings,
        solver: &mut TangentSolver,
    ) -> Result<StaticSolution, FemError> {
        check_settings(settings)?;
        if start_m.len() != loads.as_slice().len() || loads.node_count() != self.mesh().node_count()
        {
            return Err(FemError::InvalidInput {
                what: "start displacement: dof count",
                value: start_m.len() as f64,
                problem: "not three per mesh node",
            });
        }
        let mut u = start_m;
        let report = self.load_step(solver, &mut u, loads, 1.0, (1, 1), settings)?;
        Ok(StaticSolution {
            displacement_m: u,
            steps: vec![report],
        })
    }

    fn load_step(
        &self,
        solver: &mut TangentSolver,
        u: &mut [f64],
        loads: &Loads,
        factor: f64,
        step: (usize, usize),
        settings: &NewtonSettings,
    ) -> Result<StepReport, FemError> {
        let f_ext: Vec<f64> = loads.as_slice().iter().map(|f| f * factor).collect();
        let prescribed = self.dirichlet().scaled_values(factor);
        for dof in (0..u.len()).filter(|&d| self.dirichlet().value(d).is_some()) {
            u[dof] = prescribed[dof];
        }
        self.equilibrate(solver, u, &f_ext, &NoExtraForce, step, settings)
    }

    /// Newton iterations from `u` (prescribed dofs already set) to `f_int(u) + extra(u) = f_ext`.
    /// `step` is (this load step, all of them), for error messages.
    pub(super) fn equilibrate(
        &self,
        solver: &mut TangentSolver,
        u: &mut [f64],
        f_ext: &[f64],
        extra: &dyn ExtraForce,
        (step, steps): (usize, usize),
        settings: &NewtonSettings,
    ) -> Result<StepReport, FemError> {
        let mut report = StepReport {
            relative_residuals: Vec::new(),
            step_lengths: Vec::new(),
        };
        for iteration in 0..=settings.max_iterations {
            let (mut f_int, mut tangent) = self.force_and_tangent(u);
            extra.add(self, u, &mut f_int, Some(&mut tangent));
            let (residual, relative) = self.residual(f_ext, &f_int);
            report.relative_residuals.push(relative);
            if !relative.is_finite() {
                return Err(FemError::NonFiniteSolution {
                    step,
                    steps,
                    iteration,
                });
            }
            if relative <= settings.relative_tolerance {
                return Ok(report);
            }
            if iteration == settings.max_iterations {
                break;
            }
            let mut du = residual.clone();
            let forcing = relative.sqrt().min(MAX_FORCING);
            solver.solve(&self.pattern().matrix(tangent), &mut du, forcing)?;
            let length = self.line_search(u, &du, f_ext, extra, &residual, settings);
            report.step_lengths.push(length);
        }
        Err(FemError::NewtonNotConverged {
            step,
            steps,
            iterations: settings.max_iterations,
            relative_residual: *report.relative_residuals.last().unwrap_or(&f64::NAN),
            tolerance: settings.relative_tolerance,
        })
    }

    /// Applies `α · du` to `u`, with α from a secant search for the root of `G(α)`.
    fn line_search(
        &self,
        u: &mut [f64],
        du: &[f64],
        f_ext: &[f64],
        extra: &dyn ExtraForce,
        r0: &[f64],
        settings: &NewtonSettings,
    ) -> f64 {
        let start = u.to_vec();
        let slope_at = |u: &mut [f64], alpha: f64| {
            for (free, &dof) in self.dofs().free_dofs.iter().enumerate() {
                u[dof] = start[dof] + alpha * du[free];
            }
            let mut f_int = self.internal_force(u);
            extra.add(self, u, &mut f_int, None);
            let (r, _) = self.residual(f_ext, &f_int);
            dot(du, &r)
        };
        let g0 = dot(du, r0);
        let mut alpha = 1.0;
        let mut g = slope_at(u, alpha);
        // A step that turns an element inside out (infinite neo-Hookean energy) is halved until
        // every element keeps a positive volume.
        for _ in 0..MAX_HALVINGS {
            if g.is_finite() {
                break;
            }
            alpha *= 0.5;
            g = slope_at(u, alpha);
        }
        // G(0) ≤ 0 means an indefinite tangent gave no descent direction: take the full step.
        for _ in 0..settings.max_line_search_iterations {
            if g0 <= 0.0 || g >= 0.0 || g.abs() <= 0.5 * g0 {
                break;
            }
            // Overshoot: G changed sign between 0 and α; move to the secant root.
            alpha *= (g0 / (g0 - g)).clamp(0.1, 0.9);
            g = slope_at(u, alpha);
        }
        alpha
    }

    /// Free-dof residual `f_ext − f_int` and its norm relative to the larger of the external
    /// load and the reactions at prescribed dofs (which carry the load of a displacement-driven
    /// problem).
    fn residual(&self, f_ext: &[f64], f_int: &[f64]) -> (Vec<f64>, f64) {
        let dofs = self.dofs();
        let residual: Vec<f64> = dofs
            .free_dofs
            .iter()
            .map(|&d| f_ext[d] - f_int[d])
            .collect();
        let load = norm(dofs.free_dofs.iter().map(|&d| f_ext[d]));
        let reactions = norm(
            (0..f_int.len())
                .filter(|&d| self.dirichlet().value(d).is_some())
                .map(|d| f_int[d] - f_ext[d]),
        );
        let reference = load.max(reactions);
        let r = norm(residual.iter().copied());
        let relative = if reference > 0.0 { r / reference } else { r };
        (residual, relative)
    }
}

fn norm(values: impl Iterator<Item = f64>) -> f64 {
    values.map(|v| v * v).sum::<f64>().sqrt()
}

fn check_settings(settings: &NewtonSettings) -> Result<(), FemError> {
    let bad = |what, value: usize| FemError::InvalidInput {
        what,
        value: value as f64,
        problem: "zero; it must be at least 1",
    };
    if settings.load_steps == 0 {
        return Err(bad("load_steps", 0));
    }
    if settings.max_iterations == 0 {
        return Err(bad("max_iterations", 0));
    }
    let tol = settings.relative_tolerance;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(FemError::InvalidInput {
            what: "relative_tolerance",
            value: tol,
            problem: "not a positive, finite number",
        });
    }
    Ok(())
}
