//! A bed between two organs of a scene, in the haptic tick: each tick it reads both organs'
//! poses from the contact stage's [`Coupling`], solves the ties' forces against the organs'
//! give ([`TieSolve`]) and hands them back to the coupling as loads on both organs, equal and
//! opposite, so that each organ's vademecum answers its share.
//!
//! The organs' coefficients already hold the ties' forces of the last tick (the coupling is
//! part of them), so the separation measured at the ties is that of the other loads plus
//! what the last forces made; the solve takes the latter out through the same compliance it
//! answers the forces with, and adds back the share of the forces it finds.
//!
//! That compliance is both organs' **linear load step** between the ties (the symmetric part
//! of spatial times parametric modes, in three directions). Made of separated modes, it is
//! only nearly positive: it is set up once as `W Wᵀ`, its negative part dropped, so that
//! conjugate gradients always descend. The nonlinear load steps are left out: the ties' forces stay far
//! below the levels that reach them, and a stiffening tissue's corrections, taken at full
//! weight, make the compliance far from positive.
//!
//! A freed organ that moves (reduced dynamics, which a grasper drives) is also held by the
//! ties in its kept modes: each tick they give it their stiffness over those modes,
//! `K_r = Σ kᵢ Φᵢᵀ Φᵢ` (each live tie's secant stiffness times its area, `Φᵢ` the kept modes
//! at its end on the organ), so that a pull on it is resisted as the bed resists it and lets
//! go as the ties fail. The springs are taken to the liver as fixed: its give under the ties
//! is far below theirs.
//!
//! A grasper's jaws on the freed organ pull the ties near them through its wall
//! ([`WallPull`]): [`TiedOrgans::grip`] as they close, [`TiedOrgans::wall_tether`] for the
//! grasp's tick, [`TiedOrgans::pull_wall`] after it. The ties the wall holds are left out of
//! the fields' solve and the kept modes' restraint while it holds them.
//!
//! The ties load both organs through their linear modes alone: together they are a traction
//! spread over the bed, which has no dimple under each tie for the near field to draw. The
//! near field of other loads (the dimple under a tool) is not read at the ties either.

use std::sync::Arc;

use nalgebra::{DMatrix, SymmetricEigen, Vector3};

use super::bed::{Bed, TieEnds};
use super::cautery::{CauteryMode, TieBurns, TissueHeat};
use super::solve::{TieCompliance, TieConvergence, TieSolve};
use super::wall_pull::{WALL_REACH_M, WallPull, WallPullReport};
use crate::contact::{Coupling, ModalRows, OrganPose};
use crate::dynamics::{ModalBasis, Tether};
use crate::pgd::Vademecum;

/// The connective tissue layer's thickness the hook burns through (m): the bed's ties span
/// up to its 3 mm gap; the areolar layer is taken as 2 mm.
const LAYER_THICKNESS_M: f64 = 2e-3;

/// One organ's side of the ties.
#[derive(Clone, Debug)]
struct TiedSide {
    index: usize,
    /// Where each tie sits on the organ at rest (m).
    rest_m: Vec<Vector3<f64>>,
    /// Every load step's modes at the ties: where the organ's coefficients move them.
    displacement: ModalRows,
    /// The linear step's parametric modes at the ties, `[tie][mode]` (coefficient per
    /// newton): the coefficients the ties' forces give the organ.
    parametric: Vec<Vector3<f64>>,
    /// The coefficients of this tick's forces on this side (one per linear mode).
    linear: Vec<f64>,
}

impl TiedSide {
    fn new(index: usize, vademecum: &Vademecum, blends: &[Vec<(usize, f64)>]) -> Self {
        let point = |blend: &Vec<(usize, f64)>| -> Vector3<f64> {
            (blend.iter())
                .map(|&(m, w)| Vector3::from(vademecum.position_coords_m[m].map(f64::from)) * w)
                .sum()
        };
        let modes = vademecum.modes(0);
        Self {
            index,
            rest_m: blends.iter().map(point).collect(),
            displacement: ModalRows::displacements(vademecum, blends.iter()),
            parametric: linear_rows(blends, modes, |k, m| vademecum.load_mode_at(0, k, m)),
            linear: vec![0.0; modes],
        }
    }

    /// Where the organ's pose has moved tie `i`'s point (m).
    fn moved_m(&self, i: usize, pose: &OrganPose) -> Vector3<f64> {
        let modal = self.displacement.apply(i, pose.alpha).map(f64::from);
        modal + pose.carry.at(&self.rest_m[i])
    }

    /// The linear coefficients of the forces `sign × forces_n` on the ties.
    fn gather(&mut self, forces_n: &[Vector3<f64>], sign: f64) {
        gather(&self.parametric, forces_n, sign, &mut self.linear);
    }
}

/// Per tie (a blend of load positions) and per mode of the linear step, `value(mode,
/// position)` blended: `[tie * modes + mode]`.
fn linear_rows(
    blends: &[Vec<(usize, f64)>],
    modes: usize,
    value: impl Fn(usize, usize) -> Vector3<f64>,
) -> Vec<Vector3<f64>> {
    let value = &value;
    (blends.iter())
        .flat_map(|blend| {
            (0..modes).map(move |k| blend.iter().map(|&(m, w)| value(k, m) * w).sum())
        })
        .collect()
}

/// `out_k = sign × Σ_j rows[j][k] · f_j`.
fn gather(rows: &[Vector3<f64>], forces_n: &[Vector3<f64>], sign: f64, out: &mut [f64]) {
    out.fill(0.0);
    let modes = out.len();
    for (j, force) in forces_n.iter().enumerate() {
        if *force == Vector3::zeros() {
            continue;
        }
        let f = force * sign;
        let row = &rows[j * modes..(j + 1) * modes];
        out.iter_mut().zip(row).for_each(|(o, r)| *o += r.dot(&f));
    }
}

/// The ties' compliance within a tick as `W Wᵀ` (`W`: a column per retained direction, each
/// a vector per tie).
#[derive(Clone, Debug)]
struct LowRank {
    ties: usize,
    columns: Vec<Vector3<f64>>,
    /// `Wᵀ f` for the forces being applied.
    projected: Vec<f64>,
}

impl LowRank {
    /// The positive part of the symmetric `c` (over the ties' `3 n` components): its
    /// eigenvectors scaled by the roots of its eigenvalues above a 1e-12 share of the largest.
    fn positive_part(c: DMatrix<f64>) -> Self {
        let ties = c.nrows() / 3;
        let eigen = SymmetricEigen::new(c);
        let largest = eigen.eigenvalues.iter().copied().fold(0.0, f64::max);
        let mut columns = Vec::new();
        for (k, &lambda) in eigen.eigenvalues.iter().enumerate() {
            if lambda > 1e-12 * largest {
                let v = eigen.eigenvectors.column(k) * lambda.sqrt();
                columns
                    .extend((0..ties).map(|i| Vector3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2])));
            }
        }
        let rank = columns.len() / ties.max(1);
        Self {
            ties,
            columns,
            projected: vec![0.0; rank],
        }
    }

    fn apply(&mut self, forces_n: &[Vector3<f64>], out_m: &mut [Vector3<f64>]) {
        let columns = self.columns.chunks_exact(self.ties.max(1));
        for (p, w) in self.projected.iter_mut().zip(columns.clone()) {
            *p = w.iter().zip(forces_n).map(|(w, f)| w.dot(f)).sum();
        }
        out_m.iter_mut().for_each(|o| *o = Vector3::zeros());
        for (p, w) in self.projected.iter().zip(columns) {
            out_m.iter_mut().zip(w).for_each(|(o, w)| *o += w * *p);
        }
    }
}

impl TieCompliance for LowRank {
    fn separation(&mut self, forces_n: &[Vector3<f64>], out_m: &mut [Vector3<f64>]) {
        self.apply(forces_n, out_m);
    }
}

/// What the ties did in the last tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TiedReport {
    /// The sum of the ties' forces on the freed organ (N); the base takes the opposite.
    pub force_on_freed_n: Vector3<f64>,
    /// Ties not yet failed.
    pub live_ties: usize,
    /// Products with the compliance the solve took.
    pub products: usize,
}

/// A bed between two organs of a [`Coupling`], with its state from tick to tick. Nothing
/// is allocated once set up.
#[derive(Clone, Debug)]
pub struct TiedOrgans {
    pub bed: Bed,
    freed: TiedSide,
    base: TiedSide,
    compliance: LowRank,
    solve: TieSolve,
    convergence: TieConvergence,
    forces_n: Vec<Vector3<f64>>,
    measured_m: Vec<Vector3<f64>>,
    by_others_m: Vec<Vector3<f64>>,
    /// Where each tie's ends are this tick: what the hook reaches and the window draws.
    ends_m: Vec<TieEnds>,
    burns: TieBurns,
    report: TiedReport,
    kept: Option<KeptAtTies>,
    wall: WallPull,
    wall_report: WallPullReport,
}

/// The freed organ's kept vibration modes at the ties, and the ties' stiffness over them.
#[derive(Clone, Debug)]
struct KeptAtTies {
    modes: usize,
    /// `[tie * modes + mode]`: the mode's displacement at the tie's end on the organ.
    at_ties: Vec<Vector3<f64>>,
    /// `modes × modes`, row-major (s⁻² in the mass-orthonormal modes).
    stiffness: Vec<f64>,
}

impl KeptAtTies {
    /// `K_r = Σ kᵢ Φᵢᵀ Φᵢ` over the live ties of `bed` not `carried` by the wall.
    fn restrain(&mut self, bed: &Bed, carried: &[bool]) {
        let (law, r) = (&bed.law, self.modes);
        self.stiffness.fill(0.0);
        let ties = bed.ties.iter().zip(carried);
        for ((tie, &carried), phi) in ties.zip(self.at_ties.chunks_exact(r)) {
            let k = tie.state.secant_pa_per_m(law) * tie.area_m2;
            if carried || tie.state.failed(law) || k <= 0.0 {
                continue;
            }
            for (a, row) in self.stiffness.chunks_exact_mut(r).enumerate() {
                let phi_a = phi[a] * k;
                row.iter_mut()
                    .zip(phi)
                    .for_each(|(s, phi_b)| *s += phi_a.dot(phi_b));
            }
        }
    }
}

/// What the hook did to the ties in one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HookOnTies {
    /// Live ties within the hook's reach, which shared its energy.
    pub heated: usize,
    /// Of those, the ties divided in this tick.
    pub divided: usize,
}

impl TiedOrgans {
    /// The bed between organ `freed` and organ `base` (the coupling's indices) with their
    /// vademecums.
    pub fn new(bed: Bed, freed: (usize, Arc<Vademecum>), base: (usize, Arc<Vademecum>)) -> Self {
        let freed_blends: Vec<Vec<(usize, f64)>> =
            bed.ties.iter().map(|t| vec![(t.position, 1.0)]).collect();
        let base_blends: Vec<Vec<(usize, f64)>> = (bed.ties.iter())
            .map(|t| {
                let corners = base.1.triangles[t.facing.triangle];
                (0..3)
                    .map(|c| (corners[c] as usize, t.facing.barycentric[c]))
                    .collect()
            })
            .collect();
        let n = bed.ties.len();
        let mut within_tick = DMatrix::zeros(3 * n, 3 * n);
        for (vademecum, blends) in [(&freed.1, &freed_blends), (&base.1, &base_blends)] {
            add_linear_compliance(vademecum, blends, &mut within_tick);
        }
        let (freed, base) = (
            TiedSide::new(freed.0, &freed.1, &freed_blends),
            TiedSide::new(base.0, &base.1, &base_blends),
        );
        let ends_m = (freed.rest_m.iter().zip(&base.rest_m))
            .map(|(&freed_m, &base_m)| TieEnds { freed_m, base_m })
            .collect();
        Self {
            freed,
            base,
            compliance: LowRank::positive_part(within_tick),
            bed,
            solve: TieSolve::default(),
            convergence: TieConvergence::default(),
            forces_n: vec![Vector3::zeros(); n],
            measured_m: vec![Vector3::zeros(); n],
            by_others_m: vec![Vector3::zeros(); n],
            ends_m,
            burns: TieBurns::new(n, TissueHeat::SOFT_TISSUE, LAYER_THICKNESS_M),
            report: TiedReport::default(),
            kept: None,
            wall: WallPull::with_room(n),
            wall_report: WallPullReport::default(),
        }
    }

    /// Holds the freed organ's kept modes (`basis`, of the organ whose vademecum is `freed`)
    /// by the ties too: from the next tick, [`Self::restraint`] gives their stiffness over
    /// them.
    pub fn restrain_kept_modes(&mut self, basis: &ModalBasis, freed: &Vademecum) {
        let modes = basis.len();
        let at_ties = (self.bed.ties.iter())
            .flat_map(|tie| {
                let node = freed.positions[tie.position] as usize;
                (0..modes).map(move |k| {
                    Vector3::from_column_slice(&basis.mode(k)[3 * node..3 * node + 3])
                })
            })
            .collect();
        self.kept = Some(KeptAtTies {
            modes,
            at_ties,
            stiffness: vec![0.0; modes * modes],
        });
    }

    /// The freed organ's index in the scene.
    pub fn freed_index(&self) -> usize {
        self.freed.index
    }

    /// The freed organ's index in the coupling and the live ties' stiffness over its kept
    /// modes as the last tick left them (`modes × modes`, row-major, s⁻²), if the ties hold
    /// its kept modes ([`Self::restrain_kept_modes`]).
    pub fn restraint(&self) -> Option<(usize, &[f64])> {
        (self.kept.as_ref()).map(|kept| (self.freed.index, &kept.stiffness[..]))
    }

    /// Where each tie's ends are, as the last tick left them (at rest before the first).
    pub fn ends_m(&self) -> &[TieEnds] {
        &self.ends_m
    }

    /// Each tie's force on the freed organ in the last tick (N), in the bed's order.
    pub fn forces_n(&self) -> &[Vector3<f64>] {
        &self.forces_n
    }

    /// The hook's energy of one tick, `energy_j` in `mode`, shared equally among the live
    /// ties whose middle (as the last tick left it, [`TieEnds::middle_m`]) lies within `reach_m` of its tip; each
    /// divided once it has taken what divides it ([`TieBurns::heat`]).
    pub fn burn_near(
        &mut self,
        tip_m: &Vector3<f64>,
        reach_m: f64,
        energy_j: f64,
        mode: CauteryMode,
    ) -> HookOnTies {
        let law = self.bed.law;
        let reaches = |tie: &super::Tie, ends: &TieEnds| {
            (ends.middle_m() - tip_m).norm() <= reach_m && !tie.state.failed(&law)
        };
        let ties = self.bed.ties.iter().zip(&self.ends_m);
        let heated = ties.filter(|(t, m)| reaches(t, m)).count();
        let mut outcome = HookOnTies { heated, divided: 0 };
        if heated == 0 {
            return outcome;
        }
        let share_j = energy_j / heated as f64;
        for (i, ends) in self.ends_m.iter().enumerate() {
            if reaches(&self.bed.ties[i], ends) && self.burns.heat(&mut self.bed, i, share_j, mode)
            {
                outcome.divided += 1;
            }
        }
        outcome
    }

    /// A grasper's jaws close on the freed organ at `jaws_m`: the ties within the wall's
    /// reach hang from them ([`WallPull::grip`]).
    pub fn grip(&mut self, jaws_m: &Vector3<f64>) {
        (self.wall).grip(&self.bed, &self.ends_m, jaws_m, WALL_REACH_M);
    }

    /// The taut strands of wall as springs on the jaws for the grasp's tick.
    pub fn wall_tether(&self) -> Option<Tether> {
        self.wall.tether(&self.bed, &self.ends_m)
    }

    /// The jaws are at `jaws_m` after the grasp's tick: the wall opens the ties it holds.
    pub fn pull_wall(&mut self, jaws_m: &Vector3<f64>) -> WallPullReport {
        self.wall_report = self.wall.pull(&mut self.bed, &self.ends_m, jaws_m);
        self.wall_report
    }

    /// The jaws let the freed organ go: the ties go back to the organs' fields.
    pub fn let_go(&mut self) {
        self.wall.let_go();
        self.wall_report = WallPullReport::default();
    }

    /// What the wall did in the last tick.
    pub fn wall_report(&self) -> &WallPullReport {
        &self.wall_report
    }

    /// The bed whole again for another attempt: every tie undamaged and unheated, carrying
    /// nothing until the next tick solves it.
    pub fn heal(&mut self) {
        self.let_go();
        for tie in &mut self.bed.ties {
            tie.state = super::CohesiveTie::default();
        }
        self.burns.cool();
        self.forces_n.fill(Vector3::zeros());
        self.report = TiedReport::default();
    }

    pub fn report(&self) -> &TiedReport {
        &self.report
    }

    /// One tick, after the coupling's own ([`Coupling::tick`]): measures the ties'
    /// separations from both organs' poses, solves their forces and adds them to both
    /// organs' coupling.
    pub fn tick(&mut self, coupling: &mut Coupling) {
        let (freed_pose, base_pose) = (
            coupling.pose(self.freed.index),
            coupling.pose(self.base.index),
        );
        for (i, (measured, ends)) in (self.measured_m.iter_mut())
            .zip(self.ends_m.iter_mut())
            .enumerate()
        {
            let (freed, base) = (
                self.freed.moved_m(i, &freed_pose),
                self.base.moved_m(i, &base_pose),
            );
            *measured = freed - base;
            *ends = TieEnds {
                freed_m: self.freed.rest_m[i] + freed,
                base_m: self.base.rest_m[i] + base,
            };
        }
        self.wall.draw_open(&mut self.ends_m);
        // What the last tick's forces add to the measurement comes out: the solve adds it
        // back for the forces it finds.
        self.compliance.apply(&self.forces_n, &mut self.by_others_m);
        for (others, measured) in self.by_others_m.iter_mut().zip(&self.measured_m) {
            *others = measured - *others;
        }
        let products = self.solve.solve(
            &mut self.bed,
            self.wall.carried(),
            &self.by_others_m,
            &mut self.compliance,
            &mut self.forces_n,
            self.convergence,
        );
        let force_on_freed_n: Vector3<f64> = self.forces_n.iter().sum();
        self.report = TiedReport {
            force_on_freed_n,
            live_ties: (self.bed.ties.iter())
                .filter(|t| !t.state.failed(&self.bed.law))
                .count(),
            products: products + 1,
        };
        if let Some(kept) = &mut self.kept {
            kept.restrain(&self.bed, self.wall.carried());
        }
        self.freed.gather(&self.forces_n, 1.0);
        self.base.gather(&self.forces_n, -1.0);
        coupling.add_linear_load(self.freed.index, &self.freed.linear, &force_on_freed_n);
        coupling.add_linear_load(self.base.index, &self.base.linear, &-force_on_freed_n);
    }
}

/// Adds one organ's linear-step compliance between the ties (the symmetric part of `X Yᵀ`)
/// to `c`.
fn add_linear_compliance(
    vademecum: &Vademecum,
    blends: &[Vec<(usize, f64)>],
    c: &mut DMatrix<f64>,
) {
    let modes = vademecum.modes(0);
    let node = |m: usize| vademecum.positions[m] as usize;
    let spatial = linear_rows(blends, modes, |k, m| vademecum.mode_at_node(0, k, node(m)));
    let parametric = linear_rows(blends, modes, |k, m| vademecum.load_mode_at(0, k, m));
    let as_matrix = |rows: &[Vector3<f64>]| {
        DMatrix::from_fn(3 * blends.len(), modes, |r, k| {
            rows[(r / 3) * modes + k][r % 3]
        })
    };
    let (x, y) = (as_matrix(&spatial), as_matrix(&parametric));
    let product = &x * y.transpose();
    *c += (&product + product.transpose()) * 0.5;
}
