//! A grasper on a dynamic organ: jaws that close on a point of the tissue and hold it, a
//! virtual coupling between the hand and the jaws, slip, release and damage.
//!
//! - **The grasped point** moves with the organ's kept modes and, quasi-statically, with the
//!   modes left out: `x = X + Φₛ q + R F`, `R` the point's static compliance less the kept
//!   modes' share (the mode-acceleration remainder). `R` acts as a spring in series with the
//!   coupling.
//! - **The coupling** pulls the point towards the hand: `F = k (x_hand + offset − x) + b (v_hand
//!   − v)`, solved with the series remainder, `F = (I + kR)⁻¹ (k e + b ė)`. It is evaluated
//!   from the start of the tick and held over the step: explicit, stable while the coupled
//!   modes' `h √(k φ²)` stays far below 2 (about 0.01 for the organs). The hand feels `−F`:
//!   tension as well as compression, with the organ's inertia in it.
//! - **Slip**: the jaws hold up to `slip_force_n`; a pull beyond drags the jaws along the tissue
//!   (the offset gives way so that the force stays at the limit), and after `escape_m` of
//!   slip the tissue leaves the jaws.
//! - **Release**: when the jaws open (or the tissue escapes), the organ is let go at once and
//!   swings back; the force at the hand fades to zero over `release_s`, so it never jumps.
//! - **A restraint** (a bed's ties holding the organ where it lies, as a stiffness over the
//!   kept modes, [`GraspedOrgan::set_restraint`]) is stepped with the organ, and the kept
//!   modes' static share of the jaws' pull is the restrained organ's, `(Λ + K_r)⁻¹ Φₛᵀ F`:
//!   the hand feels the organ held by its bed, and the vademecum's static field (in which the
//!   ties hold the organ too) is what the motion corrects.
//! - **A tether** (a wall far stiffer in tension than the tissue it encloses, carrying the
//!   pull straight to what holds the organ, [`GraspedOrgan::set_tether`]) acts on the grasped
//!   point beside the coupling and the remainder: the point `x` balances the coupling, the
//!   tether's `g − K_t x` and the organ's `R⁻¹ (x − X − Φₛ q)`, so
//!   `F = (I + kR + R K_t)⁻¹ (k e + (I + R K_t) b ė − k R (g − K_t x_hand))`. The hand feels
//!   `−F`; the organ takes what the tether leaves of it, `F + g − K_t x`.
//! - **Damage**: a pull above `damage_force_n`, or the grasped point drawn further than
//!   `damage_stretch_m` from where it was grasped, marks the tissue damaged (reported once per
//!   grasp).

use nalgebra::{Matrix3, Vector3};

use super::small_spd::SmallSpd;
use super::{DynamicsError, EnergyMomentum, ModalBasis, ReducedKsv, ReducedState};

/// The grasper's settings. The defaults are chosen for a hand-held device of about 3 N peak,
/// not measured on tissue (slip and damage thresholds of real jaws on liver are to be
/// taken from measurements; `docs/dynamics.md`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GraspSettings {
    /// Coupling stiffness (N/m): the jaws follow the hand through this spring.
    pub coupling_n_per_m: f64,
    /// Coupling damping (N·s/m): above `k h / 2`, the passivity bound of a sampled spring.
    pub coupling_damping_n_s_per_m: f64,
    pub slip_force_n: f64,
    /// Slip along the jaws after which the tissue leaves them (m).
    pub escape_m: f64,
    /// Seconds over which the hand's force fades after a release.
    pub release_s: f64,
    pub damage_force_n: f64,
    pub damage_stretch_m: f64,
}

impl Default for GraspSettings {
    fn default() -> Self {
        Self {
            coupling_n_per_m: 150.0,
            coupling_damping_n_s_per_m: 0.5,
            slip_force_n: 2.5,
            escape_m: 0.01,
            release_s: 0.05,
            damage_force_n: 2.0,
            damage_stretch_m: 0.04,
        }
    }
}

/// A point of the organ the jaws can close on: its rest position, the kept modes there, and
/// the static compliance of the modes left out.
#[derive(Clone, Debug)]
pub struct GraspPoint {
    pub rest_m: Vector3<f64>,
    modes: Vec<Vector3<f64>>,
    remainder_m_per_n: Matrix3<f64>,
}

impl GraspPoint {
    /// The point at `node` of `basis`, whose full static compliance (m/N, from the
    /// vademecum's local part or a FEM solve) is `compliance`.
    pub fn at_node(
        basis: &ModalBasis,
        node: usize,
        rest_m: Vector3<f64>,
        compliance: &Matrix3<f64>,
    ) -> Self {
        Self::at_patch(basis, &[(node, 1.0)], rest_m, compliance)
    }

    /// The jaws' patch: mesh nodes with their shares (summing to one), the patch's rest
    /// centre and its static compliance (m/N).
    pub fn at_patch(
        basis: &ModalBasis,
        shares: &[(usize, f64)],
        rest_m: Vector3<f64>,
        compliance: &Matrix3<f64>,
    ) -> Self {
        let mut point = Self {
            rest_m,
            modes: Vec::with_capacity(basis.len()),
            remainder_m_per_n: Matrix3::zeros(),
        };
        point.move_to(basis, shares, rest_m, compliance);
        point
    }

    /// Moves the point to another patch of the same basis, as [`Self::at_patch`] makes it,
    /// in the room it has: the grasper closing its jaws allocates nothing.
    pub fn move_to(
        &mut self,
        basis: &ModalBasis,
        shares: &[(usize, f64)],
        rest_m: Vector3<f64>,
        compliance: &Matrix3<f64>,
    ) {
        self.modes.clear();
        self.modes.extend((0..basis.len()).map(|k| {
            let mode = basis.mode(k);
            shares
                .iter()
                .map(|&(node, share)| {
                    Vector3::from_column_slice(&mode[3 * node..3 * node + 3]) * share
                })
                .sum::<Vector3<f64>>()
        }));
        let kept: Matrix3<f64> = (self.modes.iter())
            .zip(&basis.omega2)
            .map(|(phi, w2)| phi * phi.transpose() / *w2)
            .sum();
        self.rest_m = rest_m;
        self.remainder_m_per_n = compliance - kept;
    }

    /// Where the kept modes put the point, and how fast it moves with them.
    fn moved(&self, state: &ReducedState) -> (Vector3<f64>, Vector3<f64>) {
        let mut at = Vector3::zeros();
        let mut velocity = Vector3::zeros();
        for (phi, (q, v)) in self.modes.iter().zip(state.q.iter().zip(&state.v)) {
            at += phi * *q;
            velocity += phi * *v;
        }
        (at, velocity)
    }

    /// The generalized force of a force `force_n` at the point.
    fn generalized(&self, force_n: &Vector3<f64>, out: &mut [f64]) {
        for (o, phi) in out.iter_mut().zip(&self.modes) {
            *o = phi.dot(force_n);
        }
    }
}

/// Springs on the grasped point that bypass the organ's bulk, linear within a tick: the force
/// on the point at `x` (m) is `force_at_origin_n − stiffness_n_per_m x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tether {
    pub stiffness_n_per_m: Matrix3<f64>,
    pub force_at_origin_n: Vector3<f64>,
}

impl Tether {
    /// The tether's force on the point at `at_m` (N).
    pub fn force_n(&self, at_m: &Vector3<f64>) -> Vector3<f64> {
        self.force_at_origin_n - self.stiffness_n_per_m * at_m
    }
}

/// What the jaws are doing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Jaws {
    Open,
    /// Holding: the hand's target for the point is the hand plus `offset_m`; `slipped_m` is
    /// how far the jaws have slid along the tissue; `from_m` where the point was grasped.
    Holding {
        offset_m: Vector3<f64>,
        slipped_m: f64,
        from_m: Vector3<f64>,
    },
    /// Let go: the hand's force fades from `force_n` over the release time.
    Releasing {
        force_n: Vector3<f64>,
        elapsed_s: f64,
    },
}

/// One tick's outcome at the hand.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GraspTick {
    /// The force the hand feels (N).
    pub hand_force_n: Vector3<f64>,
    /// The grasped point, where the jaws hold it (m); none when not holding.
    pub point_m: Option<Vector3<f64>>,
    pub slipping: bool,
    /// Set on the tick the tissue is first damaged in this grasp.
    pub damaged_now: bool,
}

/// A dynamic organ and a grasper on it.
pub struct GraspedOrgan {
    pub reduced: ReducedKsv,
    pub step: EnergyMomentum,
    pub state: ReducedState,
    pub point: GraspPoint,
    pub settings: GraspSettings,
    pub jaws: Jaws,
    /// Whether the current (or last) grasp has damaged the tissue.
    pub damaged: bool,
    previous_hand_m: Option<Vector3<f64>>,
    load: Vec<f64>,
    /// The force the jaws put on the organ this tick (N).
    applied_n: Vector3<f64>,
    /// `Λ + K_r` factored, while a restraint holds the organ.
    restrained_stiffness: Option<SmallSpd>,
    /// Springs on the grasped point beside the organ, while the jaws hold.
    tether: Option<Tether>,
}

impl GraspedOrgan {
    pub fn new(
        reduced: ReducedKsv,
        step: EnergyMomentum,
        point: GraspPoint,
        settings: GraspSettings,
    ) -> Self {
        let r = reduced.len();
        Self {
            reduced,
            step,
            state: ReducedState::at_rest(r),
            point,
            settings,
            jaws: Jaws::Open,
            damaged: false,
            previous_hand_m: None,
            load: vec![0.0; r],
            applied_n: Vector3::zeros(),
            restrained_stiffness: None,
            tether: None,
        }
    }

    /// Springs on the grasped point for this tick and the next until set again (none: the
    /// point is held by the organ alone). Dropped when the jaws let go.
    pub fn set_tether(&mut self, tether: Option<Tether>) {
        self.tether = tether;
    }

    /// Springs that hold the organ where it lies (a bed's ties), as a stiffness over the kept
    /// modes (`r × r`, row-major, symmetric positive semi-definite, s⁻²), the modes' squared
    /// frequencies being `omega2`: they act from the next tick on. All zeros lets the organ
    /// go. Allocates only the first time.
    pub fn set_restraint(&mut self, omega2: &[f64], stiffness: &[f64]) {
        self.step.set_restraint(stiffness);
        if self.step.restraint().is_none() {
            self.restrained_stiffness = None;
            return;
        }
        let r = omega2.len();
        let factor = self
            .restrained_stiffness
            .get_or_insert_with(|| SmallSpd::identity(r));
        factor.refactor(|m| {
            for (i, j) in (0..r).flat_map(|i| (0..r).map(move |j| (i, j))) {
                let diagonal = if i == j { omega2[i] } else { 0.0 };
                m[(i, j)] = diagonal + stiffness[i * r + j];
            }
        });
    }

    /// One tick with the hand at `hand_m`, the jaws kept `closed` or opened: the coupling
    /// force, the organ stepped under it, the state of the jaws. Closed jaws that hold
    /// nothing (open, or the tissue escaped) stay empty: [`Self::close`] takes hold.
    pub fn tick(
        &mut self,
        hand_m: &Vector3<f64>,
        closed: bool,
    ) -> Result<GraspTick, DynamicsError> {
        let h = self.step.step_s();
        let hand_velocity = self
            .previous_hand_m
            .map_or(Vector3::zeros(), |p| (hand_m - p) / h);
        self.previous_hand_m = Some(*hand_m);
        let (moved, velocity) = self.point.moved(&self.state);
        let mut tick = GraspTick {
            hand_force_n: Vector3::zeros(),
            point_m: None,
            slipping: false,
            damaged_now: false,
        };
        let (force, on_organ) = match (self.jaws, closed) {
            (Jaws::Holding { .. }, false) => self.release(),
            (
                Jaws::Holding {
                    offset_m,
                    slipped_m,
                    from_m,
                },
                true,
            ) => {
                let target = hand_m + offset_m;
                let error = target - self.point.rest_m - moved;
                let force = self.coupling(&error, &(hand_velocity - velocity), &target);
                let (force, escaped) = self.slip(force, offset_m, slipped_m, from_m, &mut tick);
                let point_m = self.point_under(&(self.point.rest_m + moved), &force);
                tick.point_m = Some(point_m);
                self.check_damage(&force, &(point_m - from_m), &mut tick);
                let on_organ = force
                    + self
                        .tether
                        .map_or(Vector3::zeros(), |t| t.force_n(&point_m));
                match escaped {
                    true => self.release(),
                    false => (force, on_organ),
                }
            }
            (Jaws::Releasing { force_n, elapsed_s }, _) => {
                self.jaws = match elapsed_s + h >= self.settings.release_s {
                    true => Jaws::Open,
                    false => Jaws::Releasing {
                        force_n,
                        elapsed_s: elapsed_s + h,
                    },
                };
                (Vector3::zeros(), Vector3::zeros())
            }
            (Jaws::Open, _) => (Vector3::zeros(), Vector3::zeros()),
        };
        tick.hand_force_n = match self.jaws {
            Jaws::Holding { .. } => -force,
            Jaws::Releasing { force_n, elapsed_s } => {
                -force_n * (1.0 - elapsed_s / self.settings.release_s)
            }
            Jaws::Open => Vector3::zeros(),
        };
        self.point.generalized(&on_organ, &mut self.load);
        self.step.step(&self.reduced, &mut self.state, &self.load)?;
        self.applied_n = on_organ;
        Ok(tick)
    }

    /// Closes the jaws on the point with the hand at `hand_m` while the tool already pushes on
    /// it with `force_n` (a press; zero for none): the coupling starts at that force, so the
    /// hand feels no jump as the press becomes a grasp. A new grasp can damage the tissue
    /// anew.
    pub fn close(&mut self, hand_m: &Vector3<f64>, force_n: &Vector3<f64>) {
        let at = self.point.rest_m + self.point.moved(&self.state).0;
        let k = self.settings.coupling_n_per_m;
        let stretch = (Matrix3::identity() + self.point.remainder_m_per_n * k) * force_n / k;
        self.jaws = Jaws::Holding {
            offset_m: at + stretch - hand_m,
            slipped_m: 0.0,
            from_m: at,
        };
        self.previous_hand_m = Some(*hand_m);
        self.damaged = false;
    }

    /// The force the jaws put on the organ in the last tick (N).
    pub fn applied_n(&self) -> Vector3<f64> {
        self.applied_n
    }

    /// Whether the jaws hold the tissue.
    pub fn holding(&self) -> bool {
        matches!(self.jaws, Jaws::Holding { .. })
    }

    /// Whether the jaws have let the tissue go and the hand's force is still fading.
    pub fn releasing(&self) -> bool {
        matches!(self.jaws, Jaws::Releasing { .. })
    }

    /// The kept modes' dynamic correction to the static answer of the jaws' load,
    /// `q − Λ⁻¹ Φₛᵀ F` (mode acceleration; `q − (Λ + K_r)⁻¹ Φₛᵀ F` under a restraint), into
    /// `out`: the organ's displacement is the vademecum's static field for `F` at the point
    /// plus `Φ` times this.
    pub fn correction(&self, omega2: &[f64], out: &mut [f64]) {
        self.point.generalized(&self.applied_n, out);
        match &self.restrained_stiffness {
            Some(factor) => factor.solve(out),
            None => out.iter_mut().zip(omega2).for_each(|(o, w2)| *o /= w2),
        }
        out.iter_mut()
            .zip(&self.state.q)
            .for_each(|(o, q)| *o = q - *o);
    }

    /// How far the kept modes have moved the grasp point from rest (m).
    pub fn point_displacement(&self) -> Vector3<f64> {
        self.point.moved(&self.state).0
    }

    /// The coupling's force for the hand's target `target_m`, `error` from where the kept
    /// modes put the point: `F = (I + kR)⁻¹ (k e + b ė)`, the remainder's spring in series, or
    /// with a tether beside it as the module says.
    fn coupling(
        &self,
        error: &Vector3<f64>,
        rate: &Vector3<f64>,
        target_m: &Vector3<f64>,
    ) -> Vector3<f64> {
        let (k, b) = (
            self.settings.coupling_n_per_m,
            self.settings.coupling_damping_n_s_per_m,
        );
        let r = &self.point.remainder_m_per_n;
        let (series, target) = match &self.tether {
            None => (Matrix3::identity() + r * k, error * k + rate * b),
            Some(tether) => {
                let beside = Matrix3::identity() + r * tether.stiffness_n_per_m;
                let pulled_back = r * tether.force_n(target_m) * k;
                (beside + r * k, error * k + beside * rate * b - pulled_back)
            }
        };
        series.lu().solve(&target).unwrap_or(target)
    }

    /// Where the point balances the jaws' `force` (N), the organ and the tether, its kept
    /// modes putting it at `with_modes_m`: `x = X + Φₛ q + R (F + g − K_t x)`.
    fn point_under(&self, with_modes_m: &Vector3<f64>, force: &Vector3<f64>) -> Vector3<f64> {
        let r = &self.point.remainder_m_per_n;
        match &self.tether {
            None => with_modes_m + r * force,
            Some(tether) => {
                let beside = Matrix3::identity() + r * tether.stiffness_n_per_m;
                let right = with_modes_m + r * (force + tether.force_at_origin_n);
                beside.lu().solve(&right).unwrap_or(right)
            }
        }
    }

    /// Caps the force at the slip limit, moving the jaws along the tissue by what the cap takes
    /// off; whether the tissue has now left the jaws.
    fn slip(
        &mut self,
        force: Vector3<f64>,
        offset_m: Vector3<f64>,
        slipped_m: f64,
        from_m: Vector3<f64>,
        tick: &mut GraspTick,
    ) -> (Vector3<f64>, bool) {
        let limit = self.settings.slip_force_n;
        let size = force.norm();
        if size <= limit {
            return (force, false);
        }
        let capped = force * (limit / size);
        let slide = (force - capped) / self.settings.coupling_n_per_m;
        let slipped_m = slipped_m + slide.norm();
        tick.slipping = true;
        self.jaws = Jaws::Holding {
            offset_m: offset_m - slide,
            slipped_m,
            from_m,
        };
        (capped, slipped_m > self.settings.escape_m)
    }

    /// Marks the tissue damaged, once, under a pull of `force` that has drawn the point
    /// `drawn_m` from where it was grasped.
    fn check_damage(&mut self, force: &Vector3<f64>, drawn_m: &Vector3<f64>, tick: &mut GraspTick) {
        let stretched = drawn_m.norm() > self.settings.damage_stretch_m;
        if !self.damaged && (force.norm() > self.settings.damage_force_n || stretched) {
            self.damaged = true;
            tick.damaged_now = true;
        }
    }

    /// Lets the tissue go: the organ at once (the tether with it), the hand's force over the
    /// release time. Nothing acts on the organ or the hand in this tick: `(0, 0)`.
    fn release(&mut self) -> (Vector3<f64>, Vector3<f64>) {
        let (moved, velocity) = self.point.moved(&self.state);
        let force_n = match self.jaws {
            Jaws::Holding { offset_m, .. } => {
                let hand = self.previous_hand_m.unwrap_or(self.point.rest_m);
                let target = hand + offset_m;
                let error = target - self.point.rest_m - moved;
                self.coupling(&error, &(-velocity), &target)
            }
            _ => Vector3::zeros(),
        };
        self.jaws = Jaws::Releasing {
            force_n,
            elapsed_s: 0.0,
        };
        self.tether = None;
        (Vector3::zeros(), Vector3::zeros())
    }
}
