//! A thin tube — a duct, an artery — as a reduced beam: a chain of nodes along its axis, each
//! segment stretching at the tube's axial stiffness `EA`, each node bending at its flexural
//! stiffness `EI` by the turn between its two segments' unit tangents,
//! `E = (EI / 2Δ) |tᵢ − tᵢ₋₁|²` (`2 (1 − cos φ)`, the turn's angle squared when small).
//! Large displacements and rotations are exact in both: the stretching reads the segments'
//! lengths, the bending only their directions, so that neither leaks into the other. Twist is
//! left out: an isotropic tube whose ends are free to turn about its axis carries none, and
//! the biliary tree's are. A static solve is a Newton iteration on the chain's energy with a
//! banded tangent (the bending's by Gauss–Newton), `O(nodes)` a step.

use std::fmt;

use nalgebra::{Matrix3, Vector3};

use super::banded::Banded;

/// A tube's cross-section: its outer radius and wall (a solid rod when the wall reaches the
/// axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TubeSection {
    pub outer_radius_m: f64,
    pub wall_m: f64,
}

impl TubeSection {
    fn inner_radius_m(&self) -> f64 {
        (self.outer_radius_m - self.wall_m).max(0.0)
    }

    /// The wall's area (m²).
    pub fn area_m2(&self) -> f64 {
        std::f64::consts::PI * (self.outer_radius_m.powi(2) - self.inner_radius_m().powi(2))
    }

    /// The second moment of area about a diameter (m⁴).
    pub fn second_moment_m4(&self) -> f64 {
        std::f64::consts::FRAC_PI_4 * (self.outer_radius_m.powi(4) - self.inner_radius_m().powi(4))
    }
}

/// Why a rod was refused or a solve failed.
#[derive(Clone, Debug, PartialEq)]
pub enum RodError {
    /// A dimension or a modulus that must be finite and positive is not.
    NotPositive { name: &'static str, value: f64 },
    /// Fewer than two segments, or more than the solve is meant for.
    Segments(usize),
    /// A node number beyond the rod's.
    NoNode { node: usize, nodes: usize },
    /// Newton's method did not settle (a load too large for one solve: ramp it).
    Unsettled { iterations: usize, residual_n: f64 },
    /// No node is held: the rod would fly off.
    Unheld,
}

impl fmt::Display for RodError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotPositive { name, value } => {
                write!(f, "{name} must be finite and above zero, not {value}")
            }
            Self::Segments(n) => write!(f, "{n} segments: from 2 to {MAX_SEGMENTS}"),
            Self::NoNode { node, nodes } => write!(f, "node {node} of a rod of {nodes} nodes"),
            Self::Unsettled {
                iterations,
                residual_n,
            } => write!(
                f,
                "the rod did not settle in {iterations} Newton steps ({residual_n:.3e} N left); \
                 apply the load in smaller steps"
            ),
            Self::Unheld => write!(f, "no node of the rod is held"),
        }
    }
}

impl std::error::Error for RodError {}

/// The most segments a rod takes.
pub const MAX_SEGMENTS: usize = 10_000;

/// The tangent's half bandwidth: bending couples a node with the next two, three unknowns
/// each.
const BAND: usize = 8;

/// How many Newton steps a solve may take.
const MAX_STEPS: usize = 100;

/// A rod: its rest chain, its stiffnesses, where it is now and which nodes are held.
#[derive(Clone, Debug)]
pub struct Rod {
    rest: Vec<Vector3<f64>>,
    segment_m: f64,
    axial_n: f64,
    bending_n_m2: f64,
    /// Where each node is (m).
    pub positions: Vec<Vector3<f64>>,
    held: Vec<bool>,
    /// Segments divided: neither stretched nor bent across.
    cut: Vec<bool>,
    /// The clamped first end's direction: the first segment bends against it as against a
    /// segment before the end held in the clamp.
    clamp: Option<Vector3<f64>>,
    /// Kept from solve to solve, so that a solve allocates nothing once they have grown.
    scratch: Scratch,
}

/// A solve's work space.
#[derive(Clone, Debug, Default)]
struct Scratch {
    dof: Vec<Option<usize>>,
    tangent: Option<Banded>,
    residual: Vec<f64>,
    forces: Vec<Vector3<f64>>,
    /// Each turning node's turn, made once a Newton step for the forces and the tangent.
    turns: Vec<Turn>,
}

/// What a solve took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settled {
    pub newton_steps: usize,
    pub residual_n: f64,
}

impl Rod {
    /// A straight rod from `from_m` to `to_m` in `segments` equal segments, of `section` and
    /// Young's modulus `young_pa`; no node held.
    pub fn straight(
        from_m: Vector3<f64>,
        to_m: Vector3<f64>,
        segments: usize,
        section: TubeSection,
        young_pa: f64,
    ) -> Result<Self, RodError> {
        let length_m = (to_m - from_m).norm();
        let named = [
            ("length_m", length_m),
            ("outer_radius_m", section.outer_radius_m),
            ("wall_m", section.wall_m),
            ("young_pa", young_pa),
        ];
        if let Some(&(name, value)) = named.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            return Err(RodError::NotPositive { name, value });
        }
        if !(2..=MAX_SEGMENTS).contains(&segments) {
            return Err(RodError::Segments(segments));
        }
        let rest: Vec<Vector3<f64>> = (0..=segments)
            .map(|k| from_m + (to_m - from_m) * (k as f64 / segments as f64))
            .collect();
        Ok(Self {
            positions: rest.clone(),
            held: vec![false; rest.len()],
            cut: vec![false; segments],
            clamp: None,
            scratch: Scratch::default(),
            rest,
            segment_m: length_m / segments as f64,
            axial_n: young_pa * section.area_m2(),
            bending_n_m2: young_pa * section.second_moment_m4(),
        })
    }

    /// The length of each segment at rest (m).
    pub fn segment_m(&self) -> f64 {
        self.segment_m
    }

    /// How many nodes it has.
    pub fn nodes(&self) -> usize {
        self.rest.len()
    }

    /// Holds node `node` where it is.
    pub fn hold(&mut self, node: usize) -> Result<(), RodError> {
        let nodes = self.nodes();
        let held = self
            .held
            .get_mut(node)
            .ok_or(RodError::NoNode { node, nodes })?;
        *held = true;
        Ok(())
    }

    /// Takes `before`'s shape, holds and divisions without allocating: `before` is this rod
    /// as it was (a new attempt starts from the rod at rest).
    ///
    /// # Panics
    /// If `before` has another number of nodes.
    pub fn restore(&mut self, before: &Rod) {
        self.positions.copy_from_slice(&before.positions);
        self.held.copy_from_slice(&before.held);
        self.cut.copy_from_slice(&before.cut);
        self.clamp = before.clamp;
    }

    /// Lets node `node` go, if it was held.
    pub fn release(&mut self, node: usize) {
        if let Some(held) = self.held.get_mut(node) {
            *held = false;
        }
    }

    /// Whether node `node` is held.
    pub fn is_held(&self, node: usize) -> bool {
        self.held.get(node).copied().unwrap_or(false)
    }

    /// Divides segment `segment`: from now on it neither stretches nor bends, and its two
    /// nodes are held where they are (the stumps stay where they were cut, and each piece
    /// stays held at both its ends).
    pub fn divide(&mut self, segment: usize) -> Result<(), RodError> {
        let nodes = self.nodes();
        let cut = self.cut.get_mut(segment).ok_or(RodError::NoNode {
            node: segment + 1,
            nodes,
        })?;
        *cut = true;
        self.held[segment] = true;
        self.held[segment + 1] = true;
        Ok(())
    }

    /// Whether segment `segment` has been divided.
    pub fn is_divided(&self, segment: usize) -> bool {
        self.cut.get(segment).copied().unwrap_or(false)
    }

    /// The energy's gradient at each node at the end of the last solve (N): at a held node,
    /// the force its holder pushes the rod with, so that the rod pushes the holder with its
    /// opposite. Empty before a first solve.
    pub fn node_forces_n(&self) -> &[Vector3<f64>] {
        &self.scratch.forces
    }

    /// Clamps the first end: its node held, and its tangent, as it is now: the first
    /// segment turns against the clamp's direction as against one more segment held in it.
    pub fn clamp_start(&mut self) {
        self.held[0] = true;
        self.clamp = Some((self.positions[1] - self.positions[0]).normalize());
    }

    /// The rod's elastic energy (J).
    pub fn energy_j(&self) -> f64 {
        let (k, kb) = self.stiffnesses();
        let stretch: f64 = (self.positions.windows(2).zip(&self.cut))
            .filter(|(_, cut)| !**cut)
            .map(|(w, _)| 0.5 * k * ((w[1] - w[0]).norm() - self.segment_m).powi(2))
            .sum();
        let bend: f64 = (self.turning()).map(|i| self.turn(i).energy_j(kb)).sum();
        stretch + bend
    }

    /// A segment's stiffness (N/m) and a node's against its turn (N·m): `EA / Δ`, `EI / Δ`.
    fn stiffnesses(&self) -> (f64, f64) {
        (
            self.axial_n / self.segment_m,
            self.bending_n_m2 / self.segment_m,
        )
    }

    /// Settles the free nodes under `loads` (node, force in N) by Newton's method from where
    /// they are, until the forces left are below `tolerance_n` (N). Allocates nothing once a
    /// first solve has made its work space.
    pub fn solve(
        &mut self,
        loads: &[(usize, Vector3<f64>)],
        tolerance_n: f64,
    ) -> Result<Settled, RodError> {
        let settled = self.step(loads, tolerance_n, MAX_STEPS)?;
        match settled.residual_n < tolerance_n {
            true => Ok(settled),
            false => Err(RodError::Unsettled {
                iterations: settled.newton_steps,
                residual_n: settled.residual_n,
            }),
        }
    }

    /// [`Self::solve`] for at most `steps` Newton steps: what a tick can spend, the rod
    /// settling on over the next ticks where these are not enough. Returns the steps taken
    /// and the forces left; an error only for a load on a node the rod lacks, a rod held
    /// nowhere, or a tangent that could not be solved.
    pub fn step(
        &mut self,
        loads: &[(usize, Vector3<f64>)],
        tolerance_n: f64,
        steps: usize,
    ) -> Result<Settled, RodError> {
        let nodes = self.nodes();
        if let Some(&(node, _)) = loads.iter().find(|(n, _)| *n >= nodes) {
            return Err(RodError::NoNode { node, nodes });
        }
        let mut scratch = std::mem::take(&mut self.scratch);
        let settled = self.settle(loads, tolerance_n, steps, &mut scratch);
        self.scratch = scratch;
        settled
    }

    fn settle(
        &mut self,
        loads: &[(usize, Vector3<f64>)],
        tolerance_n: f64,
        steps: usize,
        scratch: &mut Scratch,
    ) -> Result<Settled, RodError> {
        self.dof_numbers(&mut scratch.dof);
        let unknowns = 3 * scratch.dof.iter().flatten().count();
        if unknowns == 3 * self.nodes() {
            return Err(RodError::Unheld);
        }
        // Made once for every node free, so that the nodes held from tick to tick (by an
        // instrument) change its size without allocating.
        let tangent = scratch
            .tangent
            .get_or_insert_with(|| Banded::zeros(3 * self.nodes(), BAND));
        if tangent.len() != unknowns {
            tangent.resize(unknowns);
        }
        let Scratch {
            dof,
            tangent,
            residual,
            forces,
            turns,
        } = scratch;
        let tangent = tangent.as_mut().expect("made above");
        residual.resize(unknowns, 0.0);
        forces.resize(self.nodes(), Vector3::zeros());
        for step in 0..=steps {
            turns.clear();
            turns.extend(self.turning().map(|i| self.turn(i)));
            self.internal_forces(turns, forces);
            for &(node, force) in loads {
                forces[node] -= force;
            }
            for (node, f) in forces.iter().enumerate() {
                if let Some(d) = dof[node] {
                    residual[d..d + 3].copy_from_slice(f.as_slice());
                }
            }
            let residual_n = residual.iter().map(|r| r * r).sum::<f64>().sqrt();
            let settled = Settled {
                newton_steps: step,
                residual_n,
            };
            if residual_n < tolerance_n || step == steps {
                return Ok(settled);
            }
            let unsettled = RodError::Unsettled {
                iterations: step,
                residual_n,
            };
            tangent.clear();
            self.add_tangent(dof, turns, tangent);
            residual.iter_mut().for_each(|r| *r = -*r);
            tangent.solve(residual).ok_or(unsettled)?;
            for (node, d) in dof.iter().enumerate() {
                if let Some(d) = d {
                    self.positions[node] += Vector3::from_column_slice(&residual[*d..*d + 3]);
                }
            }
        }
        unreachable!("the loop returns at its last step")
    }

    /// Each free node's first unknown, in order along the rod, into `dof`.
    fn dof_numbers(&self, dof: &mut Vec<Option<usize>>) {
        let mut next = 0;
        dof.clear();
        dof.extend(self.held.iter().map(|&held| {
            (!held).then(|| {
                next += 3;
                next - 3
            })
        }));
    }

    /// The energy's gradient at each node (N), what holds the node back, its nodes' `turns`
    /// made.
    fn internal_forces(&self, turns: &[Turn], forces: &mut [Vector3<f64>]) {
        forces.fill(Vector3::zeros());
        let (k, kb) = self.stiffnesses();
        for i in self.stretching() {
            let q = self.positions[i + 1] - self.positions[i];
            let l = q.norm();
            let f = q * (k * (l - self.segment_m) / l);
            forces[i + 1] += f;
            forces[i] -= f;
        }
        for turn in turns {
            let pull = turn.gradient(kb);
            for (node, f) in turn.nodes.into_iter().zip(pull) {
                forces[node] += f;
            }
        }
    }

    /// The turn at node `i` between its two segments; at a clamped first node, between the
    /// clamp's direction and the first segment (the clamp's part of the Jacobian zero: it is
    /// held).
    fn turn(&self, i: usize) -> Turn {
        let across = |t: Vector3<f64>, l: f64| (Matrix3::identity() - t * t.transpose()) / l;
        let after = self.positions[i + 1] - self.positions[i];
        let la = after.norm();
        let ta = after / la;
        let pa = across(ta, la);
        let Some(i_before) = i.checked_sub(1) else {
            let clamp = self.clamp.expect("only a clamped first node turns");
            return Turn {
                nodes: [0, 0, 1],
                residual: ta - clamp,
                jacobian: [Matrix3::zeros(), -pa, pa],
                weight: 2.0,
            };
        };
        let before = self.positions[i] - self.positions[i_before];
        let lb = before.norm();
        let tb = before / lb;
        let pb = across(tb, lb);
        Turn {
            nodes: [i_before, i, i + 1],
            residual: ta - tb,
            jacobian: [pb, -pa - pb, pa],
            weight: 1.0,
        }
    }

    /// The nodes that turn: every inner one, and the first where it is clamped; none beside
    /// a divided segment.
    fn turning(&self) -> impl Iterator<Item = usize> + '_ {
        let first = if self.clamp.is_some() { 0 } else { 1 };
        (first..self.nodes() - 1)
            .filter(|&i| !(self.cut[i] || i.checked_sub(1).is_some_and(|b| self.cut[b])))
    }

    /// The segments that stretch: every one not divided, by its first node.
    fn stretching(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.nodes() - 1).filter(|&i| !self.cut[i])
    }
    /// Adds the energy's Hessian over the free nodes to `tangent`: the stretching's, its part
    /// across a segment kept from going negative under compression, and the bending's
    /// Gauss–Newton part `c Jᵀ J` (a modified Newton's method, whose solution is the same).
    fn add_tangent(&self, dof: &[Option<usize>], turns: &[Turn], tangent: &mut Banded) {
        let (k, kb) = self.stiffnesses();
        let mut add = |a: usize, b: usize, block: &Matrix3<f64>| {
            if let (Some(ra), Some(rb)) = (dof[a], dof[b]) {
                tangent.add_block(ra, rb, block);
            }
        };
        for i in self.stretching() {
            let q = self.positions[i + 1] - self.positions[i];
            let l = q.norm();
            let u = q / l;
            let uu = u * u.transpose();
            let transverse = (1.0 - self.segment_m / l).max(0.0);
            let block = (uu + (Matrix3::identity() - uu) * transverse) * k;
            add(i, i, &block);
            add(i + 1, i + 1, &block);
            add(i, i + 1, &-block);
            add(i + 1, i, &-block);
        }
        for turn in turns {
            for (a, b) in (0..3).flat_map(|a| (0..3).map(move |b| (a, b))) {
                add(turn.nodes[a], turn.nodes[b], &turn.tangent(a, b, kb));
            }
        }
    }
}

/// The turn at a node: `r = tᵢ − tᵢ₋₁`, its Jacobian with respect to the three nodes it
/// reads, and its weight: 1 for an inner node, whose turn spans a segment's length of the
/// rod, 2 at a clamp, whose turn spans only the half segment inside the rod (so its
/// curvature is twice the turn over the segment).
#[derive(Clone, Copy, Debug)]
struct Turn {
    nodes: [usize; 3],
    residual: Vector3<f64>,
    jacobian: [Matrix3<f64>; 3],
    weight: f64,
}

impl Turn {
    /// Its bending energy (J) for `c = EI / Δ`: `c w |r|² / 2`.
    fn energy_j(&self, c: f64) -> f64 {
        0.5 * c * self.weight * self.residual.norm_squared()
    }

    /// The bending energy's gradient at the three nodes, `c w Jᵀ r`.
    fn gradient(&self, c: f64) -> [Vector3<f64>; 3] {
        self.jacobian
            .map(|j| j.transpose() * self.residual * (c * self.weight))
    }

    /// Its Gauss–Newton tangent between two of its nodes, `c w Jₐᵀ J_b`.
    fn tangent(&self, a: usize, b: usize, c: f64) -> Matrix3<f64> {
        self.jacobian[a].transpose() * self.jacobian[b] * (c * self.weight)
    }
}
