//! Penalty contact between the master and one pointshell organ, one tick at a time.
//!
//! A pointshell node inside the master's deformed zero level set (`d < 0`) is pushed out by
//! `F = −k · d · n` (`k`: the node's penalty); the master takes `−F` at its nearest
//! position. Both forces become modal coefficients of their organs and point loads whose
//! near-field corrections dimple them ([`super::local_compliance`]), so the contact deforms
//! both, and the next tick sees the moved surfaces.
//!
//! **Stability.** The vademecums are quasi-static: a force moves the surfaces at once, with no
//! inertia to slow it, so the penalty fed straight back (`f = −k d`, then the surfaces move,
//! then `d` changes) is a fixed-point iteration that diverges as soon as the loop gain
//! `λ_max(KA)` exceeds 1 — `A` maps the normal forces to the change of the distances through
//! both organs' compliance ([`NormalCompliance`]), `K` holds the penalties. The equilibrium
//! the penalty asks for (`f = max(0, −k d)`, with `d` the distance the forces leave) is the
//! minimum of the convex energy `E(f) = ½ fᵀ A f + Σ f²/2k + d₀ᵀ f` over `f ≥ 0`, whose
//! gradient `d + f/k` each tick already measures. So each tick minimizes `E` by conjugate
//! gradients with bounds ([`ProjectedCg`]), warm-started from the last tick's forces, with the
//! distances the tick measured and `A` for how the forces move them:
//! - the energy falls every tick whatever `k`: no divergence, no overshoot, no chatter;
//! - a node pushes only while `f > 0`, and lets go when it comes out, with no force left
//!   pulling or pushing at a distance;
//! - the force on a node is continuous in its depth, zero at `d = 0`.
//!
//! `A` is a model of how the forces move the surfaces, along the nodes' rest normals. Where
//! it is wrong (a free master carried deep swings sideways), the next tick's measurement says
//! so, and a change of the forces that flips from tick to tick is taken in part
//! ([`Relaxation`]) rather than buzzing at 500 Hz.
//!
//! Where the tool holds an organ, `A` is that organ's compliance with the patch under the
//! tool held, and the solve reports how far the forces' change moved that patch, which the
//! tool's load follows in the same tick ([`super::hold`]).
//!
//! **The penalty `k`** of each node is [`PenaltySettings::stiffness_ratio`] times as stiff as
//! the stiffer of the two organs there, so that an overlap pushed into one node alone is cut
//! to at most `1 / (1 + ratio)` of itself at equilibrium, whatever holds the organs. It needs
//! no softer `k` for stability: the energy falls every tick whatever `k`. (Set once for the
//! whole pointshell's loop gain, the first choice, it came out at 5–10 N/m a node on the
//! floppy coarse gallbladder, and a gallbladder held by the tool sank into the liver.)

use std::ops::Range;
use std::sync::Arc;

use nalgebra::Vector3;

use super::clearance::{Clearance, Moving};
use super::hold::ToolHold;
use super::modal_rows::step_ranges;
use super::normal_compliance::NormalCompliance;
use super::pointshell::Pointshell;
use super::pose::OrganPose;
use super::projected_cg::{Convergence, ProjectedCg};
use super::relaxation::Relaxation;
use super::{DistanceField, LatticeCache, MasterShape, NearField};
use crate::pgd::{PointLoad, RigidCarry, Vademecum};

/// How stiff the penalties are (see the module's documentation) and how far each tick solves
/// for the forces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PenaltySettings {
    /// How many times stiffer than the stiffer organ at a node its penalty is.
    pub stiffness_ratio: f64,
    pub convergence: Convergence,
    /// Skip nodes measured clear of the master while nothing has moved far enough since to
    /// close the gap (`Clearance`). Off, every node within reach is measured every tick:
    /// the same forces, more work (tests compare the two).
    pub skip_clear_nodes: bool,
}

impl Default for PenaltySettings {
    /// 1000 cuts an overlap pushed into one node to 0.1 % of itself.
    fn default() -> Self {
        Self {
            stiffness_ratio: 1000.0,
            convergence: Convergence::default(),
            skip_clear_nodes: true,
        }
    }
}

/// The contact of the last tick, for reports and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairReport {
    pub nodes_in_contact: usize,
    /// The pointshell area of the nodes that push (m²).
    pub contact_area_m2: f64,
    /// Nodes whose force was evaluated (not culled).
    pub nodes_evaluated: usize,
    /// The deepest penetration (m, positive), 0 without contact.
    pub deepest_m: f64,
    /// Total force on the pointshell organ (N); the master takes its opposite.
    pub force_on_shell_n: Vector3<f64>,
    /// Products with the normal compliance the force solve took.
    pub products: usize,
}

/// One organ of a pair: its place in the scene and its vademecum.
pub struct PairSide {
    pub organ: usize,
    pub vademecum: Arc<Vademecum>,
}

#[derive(Clone)]
pub struct ContactPair {
    pub master: usize,
    pub shell: usize,
    field: Arc<DistanceField>,
    nodes: Pointshell,
    master_vademecum: Arc<Vademecum>,
    shell_vademecum: Arc<Vademecum>,
    master_steps: Vec<Range<usize>>,
    shell_steps: Vec<Range<usize>>,
    /// Penalty per node (N/m): the stiffness ratio over the stiffer organ's compliance there.
    stiffness_n_per_m: Vec<f64>,
    /// Per node: the normal force (N, ≥ 0) and the energy's gradient `d + f/k` (m).
    force_n: Vec<f64>,
    gradient_m: Vec<f64>,
    /// Nodes that push or are pushed into, this tick.
    active: Vec<u32>,
    /// Scratch: the nodes this tick may measure. The pointshell's nodes lie nearest first, so
    /// those beyond what can move this tick are passed over with one binary search rather
    /// than a test each (on `--subdivide 5`, 8,745 points: 31 µs a tick with the organs
    /// apart); then those not known clear, and the nodes pushing beyond that reach, so that
    /// they let go.
    candidates: Vec<u32>,
    /// Per node, the force the last tick left (N), then how the solve changed it.
    change_n: Vec<f64>,
    compliance: NormalCompliance,
    solver: ProjectedCg,
    convergence: Convergence,
    /// How much of each tick's change of the forces is taken.
    relaxation: Relaxation,
    cache: LatticeCache,
    /// Which nodes are known clear of the master; `None` where every node is measured.
    clearance: Option<Clearance>,
    report: PairReport,
}

/// Per organ, where this tick's contact coefficients go (all load steps concatenated), the
/// contact loads themselves (for their near-field corrections where the field is formed),
/// and the tool's hold on it, which takes the move the contact forces' change makes under
/// the tool.
pub struct PairOutput<'a> {
    pub master: &'a mut [f64],
    pub shell: &'a mut [f64],
    pub master_points: &'a mut Vec<PointLoad>,
    pub shell_points: &'a mut Vec<PointLoad>,
    pub master_hold: &'a mut ToolHold,
    pub shell_hold: &'a mut ToolHold,
}

impl ContactPair {
    /// Room for every pointshell node in the lists the tick fills (a clone keeps none).
    pub(super) fn reserve(&mut self) {
        let count = self.node_count();
        self.active.reserve(count);
        self.candidates.reserve(count);
        self.relaxation.reserve();
        self.compliance.local_mut().reserve();
    }

    /// The pointshell's nodes tested against the master.
    pub(super) fn node_count(&self) -> usize {
        self.force_n.len()
    }

    /// Sets up the pair: each node's penalty from the stiffer organ's compliance there.
    pub fn new(
        master: PairSide,
        shell: PairSide,
        field: Arc<DistanceField>,
        nodes: Pointshell,
        settings: &PenaltySettings,
    ) -> Self {
        let PairSide {
            organ: master,
            vademecum: master_vademecum,
        } = master;
        let PairSide {
            organ: shell,
            vademecum: shell_vademecum,
        } = shell;
        let compliance = NormalCompliance::new(&nodes, &master_vademecum, &shell_vademecum);
        let stiffness_n_per_m = penalties(&compliance, nodes.len(), settings.stiffness_ratio);
        let count = nodes.len();
        Self {
            master,
            shell,
            master_steps: step_ranges(&master_vademecum),
            shell_steps: step_ranges(&shell_vademecum),
            field,
            master_vademecum,
            shell_vademecum,
            stiffness_n_per_m,
            nodes,
            force_n: vec![0.0; count],
            gradient_m: vec![0.0; count],
            active: Vec::with_capacity(count),
            candidates: Vec::with_capacity(count),
            change_n: vec![0.0; count],
            compliance,
            solver: ProjectedCg::new(count),
            relaxation: Relaxation::new(count),
            convergence: settings.convergence,
            cache: LatticeCache::default(),
            clearance: settings.skip_clear_nodes.then(|| Clearance::new(count)),
            report: PairReport::default(),
        }
    }

    pub fn pointshell(&self) -> &Pointshell {
        &self.nodes
    }

    pub fn field(&self) -> &DistanceField {
        &self.field
    }

    pub fn report(&self) -> &PairReport {
        &self.report
    }

    /// One tick: measures every node that can touch (or still pushes), solves for the forces,
    /// and adds both organs' contact coefficients to `out`. `near` is the master's near-field
    /// displacement, summed here where a load presses the master.
    pub fn tick(
        &mut self,
        master: OrganPose,
        shell: OrganPose,
        mut near: Option<&mut NearField>,
        out: PairOutput,
    ) {
        if let Some(near) = near.as_deref_mut().filter(|near| near.is_active()) {
            near.gather();
        }
        let mut report = self.measure_within_reach(master, shell, near.as_deref());
        if !self.active.is_empty() {
            out.master_hold.prepare(&self.master_vademecum);
            out.shell_hold.prepare(&self.shell_vademecum);
        }
        let compliance = &mut self.compliance;
        compliance.hold(&self.active, out.master_hold, out.shell_hold);
        compliance.local_mut().prepare(&self.active);
        for &i in &self.active {
            self.change_n[i as usize] = -self.force_n[i as usize];
        }
        report.products = self.solver.solve(
            &self.active,
            &self.stiffness_n_per_m,
            &mut |set: &[u32], v: &[f64], out: &mut [f64]| compliance.apply(set, v, out),
            &mut self.force_n,
            &mut self.gradient_m,
            &self.convergence,
        );
        self.relax();
        let (master_moved_m, shell_moved_m) =
            self.compliance.tool_moves_m(&self.active, &self.change_n);
        out.master_hold.moved_m += master_moved_m;
        out.shell_hold.moved_m += shell_moved_m;
        for &i in &self.active {
            let i = i as usize;
            if self.force_n[i] > 0.0 {
                report.nodes_in_contact += 1;
                report.contact_area_m2 += self.nodes.area_m2[i] as f64;
                report.force_on_shell_n += self.nodes.rest_normal[i] * self.force_n[i];
                self.add_loads(i, out.master, out.shell);
                self.add_points(i, out.master_points, out.shell_points);
            }
        }
        self.report = report;
    }

    /// Measures every node that pushes or can touch, and collects the active set. Skipped with
    /// a comparison or two:
    /// - nodes farther at rest than everything can move: the point where the distance is read
    ///   moves by at most the field's bound (the master's modes), the shell's bound, both
    ///   carries and, where it reaches, the near field's ([`Self::near_moves_m`]), across an
    ///   interpolated distance whose slope is at most `√3` (trilinear, per axis at most 1);
    /// - nodes measured clear not long ago, where little has moved since ([`Clearance`]), a
    ///   block of them at a time where all are surely clear.
    ///
    /// The forces already pushing dimple both organs (the near-field part of `A`), which moves
    /// each node's read point along its normal by its dimple: known before the node is read.
    fn measure_within_reach(
        &mut self,
        master: OrganPose,
        shell: OrganPose,
        near: Option<&NearField>,
    ) -> PairReport {
        self.compliance
            .local_mut()
            .dimple(&self.active, &self.force_n);
        let local = self.compliance.local();
        let point_moves = self.field.movement_bound_m(master.alpha)
            + self.nodes.movement_bound_m(shell.alpha)
            + carry_bound_m(master.carry, &self.field)
            + carry_bound_m(shell.carry, &self.field);
        if let Some(clearance) = &mut self.clearance {
            clearance.advance(
                Moving {
                    pose: master,
                    bounds: self.field.mode_bounds(),
                },
                Moving {
                    pose: shell,
                    bounds: &self.nodes.mode_bounds,
                },
                &self.field,
                near.map_or(0.0, NearField::largest_change_m) as f64,
            );
            for &b in local.shifted_blocks() {
                clearance.shifted(b as usize, local.block_shift_m(b as usize));
            }
        }
        let shape = MasterShape {
            alpha: master.alpha,
            near: near.filter(|near| near.is_active()),
        };
        self.cache.next_tick(&self.field, &shape);
        let reach_m = 3f32.sqrt()
            * (point_moves + local.largest_gap_m() as f32 + near.map_or(0.0, NearField::largest_m));
        let rest_m = &self.nodes.rest_distance_m;
        let within = rest_m.partition_point(|&d| d <= reach_m);
        self.candidates.clear();
        match &mut self.clearance {
            Some(clearance) => {
                clearance.candidates(within, |i| local.gap_m(i), &mut self.candidates)
            }
            None => self.candidates.extend(0..within as u32),
        }
        self.candidates.extend(
            self.active
                .iter()
                .filter(|&&i| self.force_n[i as usize] > 0.0 && rest_m[i as usize] > reach_m),
        );
        let mut report = PairReport::default();
        self.active.clear();
        for k in 0..self.candidates.len() {
            let i = self.candidates[k] as usize;
            let shift_m = self.compliance.local().gap_m(i);
            if self.force_n[i] == 0.0 && self.out_of_reach(i, shift_m, point_moves, near) {
                continue;
            }
            report.nodes_evaluated += 1;
            let depth_m = self.measure(i, shift_m, &shape, master.carry, shell);
            report.deepest_m = report.deepest_m.max(depth_m);
        }
        report
    }

    /// Whether node `i`, pushing nothing, its read point shifted by its dimple `shift_m`,
    /// cannot reach the master from rest this tick.
    fn out_of_reach(
        &self,
        i: usize,
        shift_m: f64,
        point_moves: f32,
        near: Option<&NearField>,
    ) -> bool {
        let moves = point_moves + shift_m.abs() as f32;
        let near_moves = near.map_or(0.0, |near| {
            self.near_moves_m(i, near, moves + near.largest_m())
        });
        self.nodes.rest_distance_m[i] > 3f32.sqrt() * (moves + near_moves)
    }

    /// How far (m) the master's near field can move the distance node `i` reads, given that
    /// the point it reads from moves by at most `moves_m` (all motions, the near field's
    /// included): the lattice nodes it reads lie within `r = moves_m + √3 · spacing` of its
    /// rest point, their distances within `r` of its own, and so their closest rest points
    /// within `2r + rest distance` of it. No near-field motion there, none read.
    fn near_moves_m(&self, i: usize, near: &NearField, moves_m: f32) -> f32 {
        let r = (moves_m as f64) + 3f64.sqrt() * self.field.spacing_m();
        let within = 2.0 * r + self.nodes.rest_distance_m[i].abs() as f64;
        near.largest_near_m(&self.nodes.rest_m[i].map(f64::from), within)
    }

    /// Node `i`'s distance to the master, read with its dimple `shift_m`, and the energy's
    /// gradient there; joins the active set if it pushes or is inside. Returns how deep it is
    /// (m, 0 outside).
    fn measure(
        &mut self,
        i: usize,
        shift_m: f64,
        master: &MasterShape,
        master_carry: &RigidCarry,
        shell: OrganPose,
    ) -> f64 {
        let rest = self.nodes.rest_m[i].map(f64::from);
        let mut p = rest + self.nodes.displacement.apply(i, shell.alpha).map(f64::from);
        p += shell.carry.at(&rest);
        // The forces already pushing dimple both organs apart along the node's normal: read
        // where the node is against the dimpled master, near its surface, rather than deep
        // inside the master's modal shape and corrected after.
        p += self.nodes.rest_normal[i] * shift_m;
        // The master's lattice is at rest: pull the point back through the master's carry.
        let q = master_carry.pull_back(&p);
        let Some(distance_m) = self.field.distance_m(&q, master, &mut self.cache) else {
            self.force_n[i] = 0.0;
            if let Some(clearance) = &mut self.clearance {
                clearance.outside_lattice(i, self.field.outside_by_m(&q), shift_m);
            }
            return 0.0;
        };
        if let Some(clearance) = &mut self.clearance {
            clearance.measured(i, distance_m, shift_m);
        }
        let k = self.stiffness_n_per_m[i];
        let gradient = distance_m + self.force_n[i] / k;
        if self.force_n[i] > 0.0 || gradient < 0.0 {
            self.gradient_m[i] = gradient;
            self.active.push(i as u32);
            if let Some(clearance) = &mut self.clearance {
                clearance.keep_measuring(i);
            }
        }
        (-distance_m).max(0.0)
    }

    /// Takes the share of the solve's change of the forces that [`Relaxation`] allows, and
    /// leaves that change in `change_n`.
    fn relax(&mut self) {
        for &i in &self.active {
            self.change_n[i as usize] += self.force_n[i as usize];
        }
        let share = self.relaxation.share(&self.active, &self.change_n);
        if share == 1.0 {
            return;
        }
        for &i in &self.active {
            let i = i as usize;
            let asked = self.change_n[i];
            self.change_n[i] = share * asked;
            self.force_n[i] = (self.force_n[i] - asked + self.change_n[i]).max(0.0);
        }
    }

    /// Node `i`'s force on the shell organ, shared among its positions, and its reaction on
    /// the master, as point loads.
    fn add_points(&self, i: usize, master: &mut Vec<PointLoad>, shell: &mut Vec<PointLoad>) {
        let force = self.nodes.rest_normal[i] * self.force_n[i];
        shell.extend(self.nodes.blends[i].iter().map(|&(position, w)| PointLoad {
            position,
            force_n: force * w,
        }));
        master.push(PointLoad {
            position: self.nodes.master_positions[i] as usize,
            force_n: -force,
        });
    }

    /// Node `i`'s force on the shell organ and its reaction on the master, as coefficients.
    /// It pushes along the node's rest normal, the direction `A` is projected on.
    fn add_loads(&self, i: usize, master: &mut [f64], shell: &mut [f64]) {
        let f = self.force_n[i];
        let force = self.nodes.rest_normal[i] * f;
        let (s, m) = (
            self.nodes.position(i),
            self.nodes.master_positions[i] as usize,
        );
        let (shell_vademecum, master_vademecum) = (&self.shell_vademecum, &self.master_vademecum);
        let shell_level_n = shell_vademecum.level_force_n(&[(s, 1.0)], &force);
        let master_level_n = master_vademecum.level_force_n(&[(m, 1.0)], &force);
        self.compliance.shell_rows().add_force(
            i,
            f,
            &self.shell_steps,
            |step| shell_vademecum.step_share(step, s, 1.0, shell_level_n),
            shell,
        );
        self.compliance.master_rows().add_force(
            i,
            f,
            &self.master_steps,
            |step| master_vademecum.step_share(step, m, 1.0, master_level_n),
            master,
        );
    }
}

/// Each node's penalty (N/m): `ratio` times as stiff as the stiffer of the two organs there,
/// so that an overlap pushed into one node alone is cut to at most `1 / (1 + ratio)` of
/// itself. A node neither organ can move takes the stiffest penalty of the others.
fn penalties(compliance: &NormalCompliance, count: usize, ratio: f64) -> Vec<f64> {
    let mut stiffness: Vec<f64> = (0..count)
        .map(|i| {
            let a = compliance.stiffer_diagonal(i);
            if a > 0.0 { ratio / a } else { 0.0 }
        })
        .collect();
    let stiffest = stiffness.iter().copied().fold(0.0, f64::max);
    stiffness
        .iter_mut()
        .filter(|k| **k == 0.0)
        .for_each(|k| *k = stiffest);
    stiffness
}

/// How far a rigid carry can move any point of the lattice (m).
fn carry_bound_m(carry: &RigidCarry, field: &DistanceField) -> f32 {
    (carry.translation_m.norm()
        + carry.rotation_rad.norm() * field.farthest_from_m(&carry.centre_m)) as f32
}
