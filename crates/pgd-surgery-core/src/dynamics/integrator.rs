//! The energy–momentum step: implicit midpoint with the Simo–Tarnow algorithmic force.
//!
//! In the mass-orthonormal basis (`M = I`), a step of `h` from `(q₀, v₀)` solves for
//! `Δ = q₁ − q₀`
//!
//! `2 (Δ − h v₀) / h² + C Δ / h + f_ST(q₀, q₀ + Δ) = f_ext`,   `v₁ = 2Δ/h − v₀`,
//!
//! so that the kinetic energy changes by `(v₁ − v₀)·(v₀ + v₁)/2` and the strain energy by
//! `f_ST · Δ` exactly: with no damping and no load, `T + W` is conserved to the solver's
//! tolerance, at any step and for any frequency in the basis (unconditionally stable, and no
//! numerical damping). The damping is Rayleigh's, `C = αM + βK`, diagonal in the basis, and
//! removes `Δ·CΔ/h` per step: energy leaves only through it.
//!
//! Newton's method runs with the Jacobian at rest, `2/h² + cᵢ/h + ωᵢ²/2`, diagonal: at the
//! 1 ms tick the inertia term (2·10⁶ s⁻²) dominates the tissue's nonlinear stiffness change,
//! so 3.6–5.5 iterations reach the default tolerance (or, asked, round-off) with no
//! factorization. Where they do not (a body far turned from rest), the exact Jacobian takes
//! over.
//!
//! A **restraint** (springs that hold the body where it lies, such as a bed's ties, as a
//! symmetric positive stiffness `K_r` over the modes) adds `K_r (q₀ + q₁)/2` to the
//! algorithmic force: the midpoint rule conserves a linear spring's energy exactly, so the
//! step stays unconditionally stable however stiff the springs. Half of it joins the rest
//! Jacobian, which is then factored once as the restraint is set.

use nalgebra::{DMatrix, DVector};

use super::polynomial::Scratch;
use super::small_spd::SmallSpd;
use super::{DynamicsError, ReducedKsv};

/// Iterations with the rest Jacobian before Newton's method takes the exact one: enough
/// for an organ held at its attachments, which never turns far from rest; a free body that
/// spins needs the exact one.
const REST_ITERATIONS: usize = 6;

/// An update this small (relative) is round-off: the iterations have done what they can.
const ROUND_OFF: f64 = 1e-15;

/// Below this, an update that no longer halves is round-off in the forces.
const STAGNATION: f64 = 1e-12;

/// Updates are measured against the step's motion, and against this share of the coordinates
/// when the motion dies out (a settled organ), where round-off in the forces sets the floor.
const MOTION_FLOOR: f64 = 1e-3;

/// Rayleigh damping `C = αM + βK`: the modal damping ratio is `α/(2ω) + βω/2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayleighDamping {
    /// Mass-proportional coefficient (1/s).
    pub alpha_per_s: f64,
    /// Stiffness-proportional coefficient (s).
    pub beta_s: f64,
}

impl RayleighDamping {
    pub const NONE: Self = Self {
        alpha_per_s: 0.0,
        beta_s: 0.0,
    };

    /// The damping that gives the ratio `zeta` at the angular frequencies `omega1` and
    /// `omega2` (rad/s), and less between them.
    pub fn with_ratio(zeta: f64, omega1: f64, omega2: f64) -> Self {
        Self {
            alpha_per_s: 2.0 * zeta * omega1 * omega2 / (omega1 + omega2),
            beta_s: 2.0 * zeta / (omega1 + omega2),
        }
    }

    /// The modal damping coefficient `cᵢ = α + β ωᵢ²` (1/s).
    pub fn modal(&self, omega2: f64) -> f64 {
        self.alpha_per_s + self.beta_s * omega2
    }
}

/// Generalized coordinates and velocities.
#[derive(Clone, Debug, PartialEq)]
pub struct ReducedState {
    pub q: Vec<f64>,
    pub v: Vec<f64>,
}

impl ReducedState {
    pub fn at_rest(r: usize) -> Self {
        Self {
            q: vec![0.0; r],
            v: vec![0.0; r],
        }
    }

    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.v.iter().map(|v| v * v).sum::<f64>()
    }
}

/// How a step's Newton iterations went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    pub iterations: usize,
    /// The last update of `Δ`, relative to `Δ`.
    pub last_update: f64,
    pub converged: bool,
}

/// The step of a reduced model at a fixed time step, with its damping.
#[derive(Clone, Debug)]
pub struct EnergyMomentum {
    step_s: f64,
    /// Per mode: `cᵢ` (1/s) and the Newton Jacobian's diagonal.
    damping: Vec<f64>,
    jacobian: Vec<f64>,
    /// The restraint's stiffness over the modes (s⁻², mass-orthonormal modes), row-major;
    /// all zero unless set.
    restraint: Vec<f64>,
    restrained: bool,
    /// With a restraint, the rest Jacobian with half its stiffness, factored.
    restrained_jacobian: SmallSpd,
    /// The step is solved when an update of `Δ` is below this (relative).
    pub tolerance: f64,
    /// Iterate past the tolerance to round-off: energy and momentum then stay to round-off
    /// over any number of ticks (10⁻¹⁴ over 10⁵), at about one and a half times the
    /// iterations. Off by default: at the default tolerance the energy drifts by about 10⁻⁷
    /// over 10⁵ ticks, far less than the tissue's damping takes in one.
    pub to_round_off: bool,
    pub max_iterations: usize,
    scratch: Scratch,
    force: Vec<f64>,
    delta: Vec<f64>,
    q1: Vec<f64>,
    residual: Vec<f64>,
}

impl EnergyMomentum {
    /// The step of `model` (whose modes have squared frequencies `omega2`) at `step_s` with
    /// `damping`.
    pub fn new(model: &ReducedKsv, omega2: &[f64], step_s: f64, damping: RayleighDamping) -> Self {
        let damping: Vec<f64> = omega2.iter().map(|&w2| damping.modal(w2)).collect();
        let jacobian = omega2
            .iter()
            .zip(&damping)
            .map(|(w2, c)| 2.0 / (step_s * step_s) + c / step_s + 0.5 * w2.max(0.0))
            .collect();
        let r = model.len();
        Self {
            step_s,
            damping,
            jacobian,
            restraint: vec![0.0; r * r],
            restrained: false,
            restrained_jacobian: SmallSpd::identity(r),
            tolerance: 1e-9,
            to_round_off: false,
            max_iterations: 50,
            scratch: model.scratch(),
            force: vec![0.0; model.len()],
            delta: vec![0.0; model.len()],
            q1: vec![0.0; model.len()],
            residual: vec![0.0; model.len()],
        }
    }

    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Sets the restraint's stiffness over the modes (`r × r`, row-major, symmetric and
    /// positive semi-definite; s⁻² in the mass-orthonormal modes): it holds from the next step
    /// on. All zeros lets the body go.
    pub fn set_restraint(&mut self, stiffness: &[f64]) {
        self.restraint.copy_from_slice(stiffness);
        self.restrained = stiffness.iter().any(|&k| k != 0.0);
        if self.restrained {
            let (diagonal, r) = (&self.jacobian, self.jacobian.len());
            self.restrained_jacobian.refactor(|m| {
                for (i, j) in (0..r).flat_map(|i| (0..r).map(move |j| (i, j))) {
                    let on_diagonal = if i == j { diagonal[i] } else { 0.0 };
                    m[(i, j)] = on_diagonal + 0.5 * stiffness[i * r + j];
                }
            });
        }
    }

    /// The restraint's stiffness as last set (row-major; zeros when none).
    pub fn restraint(&self) -> Option<&[f64]> {
        self.restrained.then_some(&self.restraint[..])
    }

    /// Advances `state` by one step under the generalized force `external` (held over the
    /// step). On an error the state is left as it was.
    pub fn step(
        &mut self,
        model: &ReducedKsv,
        state: &mut ReducedState,
        external: &[f64],
    ) -> Result<StepReport, DynamicsError> {
        // From Δ = 0 the first iteration is the linearized step, exact for the linear part of
        // every mode, however stiff; `h v₀` would overshoot a mode whose period is shorter
        // than the step into strains the rest Jacobian cannot bring back.
        self.delta.fill(0.0);
        let mut report = StepReport::default();
        let mut previous = f64::INFINITY;
        for iteration in 1..=self.max_iterations {
            self.residual(model, state, external);
            if iteration > REST_ITERATIONS && model.is_nonlinear() {
                self.exact_newton_update(model, state)?;
            } else if self.restrained {
                self.restrained_jacobian.solve(&mut self.residual);
            } else {
                for (r, j) in self.residual.iter_mut().zip(&self.jacobian) {
                    *r /= j;
                }
            }
            report = StepReport {
                iterations: iteration,
                last_update: self.apply_update(state)?,
                converged: false,
            };
            if self.converged(report.last_update, previous) {
                report.converged = true;
                break;
            }
            previous = report.last_update;
        }
        if !report.converged {
            return Err(DynamicsError::NotConverged {
                iterations: report.iterations,
                update: report.last_update,
            });
        }
        let h = self.step_s;
        for ((q, v), d) in state.q.iter_mut().zip(state.v.iter_mut()).zip(&self.delta) {
            *q += d;
            *v = 2.0 * d / h - *v;
        }
        Ok(report)
    }

    /// Whether the iterations are done, the last update being `update` and the one before
    /// `previous`.
    fn converged(&self, update: f64, previous: f64) -> bool {
        match self.to_round_off {
            true => update <= ROUND_OFF || (update <= STAGNATION && update > 0.5 * previous),
            false => update <= self.tolerance,
        }
    }

    /// The step's equations at the current `Δ`, into `self.residual`; `self.q1` is `q₀ + Δ`.
    fn residual(&mut self, model: &ReducedKsv, state: &ReducedState, external: &[f64]) {
        let h = self.step_s;
        for ((q1, q0), d) in self.q1.iter_mut().zip(&state.q).zip(&self.delta) {
            *q1 = q0 + d;
        }
        model.algorithmic_force((&state.q, &self.q1), &mut self.force, &mut self.scratch);
        if self.restrained {
            let r = self.force.len();
            for (f, row) in self.force.iter_mut().zip(self.restraint.chunks_exact(r)) {
                let mid = row.iter().zip(state.q.iter().zip(&self.q1));
                *f += mid.map(|(k, (q0, q1))| k * 0.5 * (q0 + q1)).sum::<f64>();
            }
        }
        let terms = self.delta.iter().zip(&state.v).zip(&self.damping);
        let forces = self.force.iter().zip(external);
        for ((residual, ((d, v), c)), (f, e)) in self.residual.iter_mut().zip(terms).zip(forces) {
            *residual = 2.0 * (d - h * v) / (h * h) + c * d / h + f - e;
        }
    }

    /// Turns `self.residual` into the full Newton update: the step's exact Jacobian, solved.
    fn exact_newton_update(
        &mut self,
        model: &ReducedKsv,
        state: &ReducedState,
    ) -> Result<(), DynamicsError> {
        let (h, r) = (self.step_s, self.delta.len());
        let mut jacobian = vec![0.0; r * r];
        model.algorithmic_jacobian((&state.q, &self.q1), &mut jacobian, &mut self.scratch);
        let mut matrix = DMatrix::from_row_slice(r, r, &jacobian);
        for i in 0..r {
            matrix[(i, i)] += 2.0 / (h * h) + self.damping[i] / h;
            for j in 0..r {
                matrix[(i, j)] += 0.5 * self.restraint[i * r + j];
            }
        }
        let update = matrix
            .lu()
            .solve(&DVector::from_column_slice(&self.residual))
            .ok_or(DynamicsError::NonFinite)?;
        self.residual.copy_from_slice(update.as_slice());
        Ok(())
    }

    /// `Δ −= update` (the update in `self.residual`); the update's size relative to the step's
    /// motion.
    fn apply_update(&mut self, state: &ReducedState) -> Result<f64, DynamicsError> {
        let (mut change, mut size, mut finite) = (0.0_f64, 0.0_f64, true);
        for ((d, u), q) in self.delta.iter_mut().zip(&self.residual).zip(&state.q) {
            *d -= u;
            finite &= u.is_finite();
            change = change.max(u.abs());
            size = size.max(d.abs()).max(MOTION_FLOOR * q.abs());
        }
        if !finite {
            return Err(DynamicsError::NonFinite);
        }
        Ok(if size > 0.0 { change / size } else { 0.0 })
    }
}
