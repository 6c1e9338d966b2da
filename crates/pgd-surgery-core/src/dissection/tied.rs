//! A bed between two organs of a scene, in the haptic tick: each tick it reads both organs'
//! poses from the contact stage's [`Coupling`], solves the ties' forces against the organs'
//! give ([`TieSolve`]) and hands them back to the coupling as loads on both organs, equal and
//! opposite, so that each organ's vademecum answers its share.
//!
//! The organs' coefficients already hold the ties' forces of the last tick (the coupling is
//! part of them), so the separation measured at the ties is that of the other loads plus
//! what the last forces made; the solve takes the latter out through the same compliance
//! it answers the forces with. That compliance is the two organs' linear modes between the
//! ties (the symmetric part of `X Yᵀ`, as organ contact's, in three directions): the near field
//! the modes miss is not in it, so the ties see the organs a little stiffer than the field
//! they draw, and the next tick's measurement takes up the difference. The ties' forces load
//! both organs through their modes alone: together they are a traction spread over the bed,
//! which has no dimple under each tie for the near field to draw. The near field of other
//! loads (the dimple under a tool) is not read at the ties either.

use std::sync::Arc;

use nalgebra::Vector3;

use super::bed::Bed;
use super::solve::{TieCompliance, TieConvergence, TieSolve};
use crate::contact::{Coupling, ModalRows, OrganPose};
use crate::pgd::Vademecum;

/// One organ's side of the ties: its modes at them, its vademecum and where the ties sit
/// on it at rest.
#[derive(Clone, Debug)]
struct TiedSide {
    index: usize,
    vademecum: Arc<Vademecum>,
    /// Each tie's point as a blend of the organ's load positions.
    blends: Vec<Vec<(usize, f64)>>,
    rest_m: Vec<Vector3<f64>>,
    /// Every load step's modes at the ties: where the organ's coefficients move them.
    displacement: ModalRows,
    linear: LinearRows,
}

impl TiedSide {
    fn new(index: usize, vademecum: Arc<Vademecum>, blends: Vec<Vec<(usize, f64)>>) -> Self {
        let rest_m = (blends.iter())
            .map(|blend| {
                (blend.iter())
                    .map(|&(m, w)| Vector3::from(vademecum.position_coords_m[m].map(f64::from)) * w)
                    .sum()
            })
            .collect();
        Self {
            index,
            displacement: ModalRows::displacements(&vademecum, blends.iter()),
            linear: LinearRows::new(&vademecum, &blends),
            vademecum,
            blends,
            rest_m,
        }
    }

    /// Where the organ's pose has moved tie `i`'s point (m).
    fn moved_m(&self, i: usize, pose: &OrganPose) -> Vector3<f64> {
        let modal = self.displacement.apply(i, pose.alpha).map(f64::from);
        modal + pose.carry.at(&self.rest_m[i])
    }
}

/// One organ's linear load step at the ties, the compliance the solve answers with: per tie
/// and mode, the spatial mode `X` there and the parametric mode `Y` (coefficient per
/// newton). The nonlinear steps are left out: the ties' forces are far below the levels that
/// reach them, and their corrections, taken at full weight, make the compliance's symmetric
/// part indefinite (a stiffening tissue's correction takes compliance away), which conjugate
/// gradients cannot take.
#[derive(Clone, Debug)]
struct LinearRows {
    modes: usize,
    /// `[tie * modes + mode]`.
    spatial: Vec<Vector3<f64>>,
    parametric: Vec<Vector3<f64>>,
    /// `Σ_j Yⱼ fⱼ` and `Σ_j Xⱼ fⱼ` for the forces being applied (one per mode).
    by_parametric: Vec<f64>,
    by_spatial: Vec<f64>,
}

impl LinearRows {
    fn new(vademecum: &Vademecum, blends: &[Vec<(usize, f64)>]) -> Self {
        let modes = vademecum.modes(0);
        let gather = |value: &dyn Fn(usize, usize) -> Vector3<f64>| -> Vec<Vector3<f64>> {
            (blends.iter())
                .flat_map(|blend| {
                    (0..modes).map(move |k| blend.iter().map(|&(m, w)| value(k, m) * w).sum())
                })
                .collect()
        };
        let node = |m: usize| vademecum.positions[m] as usize;
        Self {
            modes,
            spatial: gather(&|k, m| vademecum.mode_at_node(0, k, node(m))),
            parametric: gather(&|k, m| vademecum.load_mode_at(0, k, m)),
            by_parametric: vec![0.0; modes],
            by_spatial: vec![0.0; modes],
        }
    }

    fn rows(&self, i: usize) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        let range = i * self.modes..(i + 1) * self.modes;
        (&self.spatial[range.clone()], &self.parametric[range])
    }

    /// Sums the forces' modal sums for [`Self::add_answer`].
    fn gather(&mut self, forces_n: &[Vector3<f64>]) {
        self.by_parametric.fill(0.0);
        self.by_spatial.fill(0.0);
        for (j, force) in forces_n.iter().enumerate() {
            if *force == Vector3::zeros() {
                continue;
            }
            let range = j * self.modes..(j + 1) * self.modes;
            let sums = [
                (&self.parametric[range.clone()], &mut self.by_parametric),
                (&self.spatial[range], &mut self.by_spatial),
            ];
            for (rows, sum) in sums {
                sum.iter_mut()
                    .zip(rows)
                    .for_each(|(s, r)| *s += r.dot(force));
            }
        }
    }

    /// Adds how far the gathered forces move tie `i`'s point (m): the symmetric part of
    /// `X Yᵀ`.
    fn add_answer(&self, i: usize, out: &mut Vector3<f64>) {
        let (spatial, parametric) = self.rows(i);
        let sum = |rows: &[Vector3<f64>], by: &[f64]| -> Vector3<f64> {
            rows.iter().zip(by).map(|(r, b)| r * *b).sum()
        };
        *out += (sum(spatial, &self.by_parametric) + sum(parametric, &self.by_spatial)) * 0.5;
    }
}

/// The two organs' compliance between the ties.
struct BothSides<'a> {
    freed: &'a mut TiedSide,
    base: &'a mut TiedSide,
}

impl TieCompliance for BothSides<'_> {
    /// A force `f` on the freed organ and `−f` on the base both open the tie along `f`.
    fn separation(&mut self, forces_n: &[Vector3<f64>], out_m: &mut [Vector3<f64>]) {
        self.freed.linear.gather(forces_n);
        self.base.linear.gather(forces_n);
        for (i, out) in out_m.iter_mut().enumerate() {
            *out = Vector3::zeros();
            self.freed.linear.add_answer(i, out);
            self.base.linear.add_answer(i, out);
        }
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
    solve: TieSolve,
    convergence: TieConvergence,
    forces_n: Vec<Vector3<f64>>,
    measured_m: Vec<Vector3<f64>>,
    by_others_m: Vec<Vector3<f64>>,
    report: TiedReport,
}

impl TiedOrgans {
    /// The bed between organ `freed` and organ `base` (the coupling's indices) with their
    /// vademecums.
    pub fn new(bed: Bed, freed: (usize, Arc<Vademecum>), base: (usize, Arc<Vademecum>)) -> Self {
        let freed_blends = (bed.ties.iter()).map(|t| vec![(t.position, 1.0)]).collect();
        let base_blends = (bed.ties.iter())
            .map(|t| {
                let corners = base.1.triangles[t.facing.triangle];
                (0..3)
                    .map(|c| (corners[c] as usize, t.facing.barycentric[c]))
                    .collect()
            })
            .collect();
        let n = bed.ties.len();
        Self {
            freed: TiedSide::new(freed.0, freed.1, freed_blends),
            base: TiedSide::new(base.0, base.1, base_blends),
            bed,
            solve: TieSolve::default(),
            convergence: TieConvergence::default(),
            forces_n: vec![Vector3::zeros(); n],
            measured_m: vec![Vector3::zeros(); n],
            by_others_m: vec![Vector3::zeros(); n],
            report: TiedReport::default(),
        }
    }

    /// The freed organ's and the base's indices in the coupling.
    pub fn organs(&self) -> (usize, usize) {
        (self.freed.index, self.base.index)
    }

    /// Each tie's force on the freed organ in the last tick (N), in the bed's order.
    pub fn forces_n(&self) -> &[Vector3<f64>] {
        &self.forces_n
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
        for (i, measured) in self.measured_m.iter_mut().enumerate() {
            *measured = self.freed.moved_m(i, &freed_pose) - self.base.moved_m(i, &base_pose);
        }
        let mut sides = BothSides {
            freed: &mut self.freed,
            base: &mut self.base,
        };
        // What the last tick's forces add to the measurement comes out: the solve adds it
        // back for the forces it finds.
        sides.separation(&self.forces_n, &mut self.by_others_m);
        for (others, measured) in self.by_others_m.iter_mut().zip(&self.measured_m) {
            *others = measured - *others;
        }
        let products = self.solve.solve(
            &mut self.bed,
            &self.by_others_m,
            &mut sides,
            &mut self.forces_n,
            self.convergence,
        );
        self.report = TiedReport {
            force_on_freed_n: self.forces_n.iter().sum(),
            live_ties: (self.bed.ties.iter())
                .filter(|t| !t.state.failed(&self.bed.law))
                .count(),
            products: products + 1,
        };
        for (i, force) in self.forces_n.iter().enumerate() {
            if *force == Vector3::zeros() {
                continue;
            }
            let (freed, base) = (&self.freed, &self.base);
            coupling.add_spread_force(freed.index, &freed.vademecum, &freed.blends[i], force);
            coupling.add_spread_force(base.index, &base.vademecum, &base.blends[i], &-force);
        }
    }
}
