//! The master's near-field displacement on its surface this tick: what the vademecum's
//! near-field corrections add to its modes around the tool's patch.
//!
//! The modes carry a load's response far from it; within the local radius the vademecum adds
//! each loaded position's exact residual ([`crate::pgd::LocalPart`]). On the coarse
//! gallbladder that residual carries most of the response under the tool and reaches 31 mm
//! from it: a distance field with the modes alone put the deformed surface 9 mm (p95) from
//! where it is near the tool. So the tick sums the tool's corrections at the surface
//! positions, and the lattice adds them at each node's closest rest point
//! ([`super::DistanceField`]).
//!
//! Only the corrections at surface positions are read (on the full gallbladder a third of
//! each position's near-field nodes), and only on ticks where a load presses the master.

use std::sync::Arc;

use nalgebra::Vector3;

use crate::pgd::{PatchLoad, Vademecum};

/// Per load step and loaded position, its correction entries at surface positions.
#[derive(Debug, Default, PartialEq)]
struct SurfaceEntries {
    /// `offsets[step][i]..offsets[step][i + 1]` index `entries[step]` for load position `i`.
    offsets: Vec<Vec<u32>>,
    /// `(correction entry, surface position)`.
    entries: Vec<Vec<(u32, u32)>>,
    /// Per step and load position: the box around the surface positions its corrections reach.
    support: Vec<Vec<Aabb>>,
}

/// An axis-aligned box (m); empty when `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Aabb {
    min: Vector3<f64>,
    max: Vector3<f64>,
}

impl Aabb {
    const EMPTY: Self = Self {
        min: Vector3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: Vector3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    fn grow(&mut self, other: &Self) {
        self.min = self.min.inf(&other.min);
        self.max = self.max.sup(&other.max);
    }

    /// How far `p` lies from the box (m); infinite from an empty one.
    fn distance_m(&self, p: &Vector3<f64>) -> f64 {
        if self.min.x > self.max.x {
            return f64::INFINITY;
        }
        (self.min - p)
            .sup(&(p - self.max))
            .sup(&Vector3::zeros())
            .norm()
    }
}

impl SurfaceEntries {
    fn new(vademecum: &Vademecum) -> Self {
        let mut position_of = vec![u32::MAX; vademecum.dof_count() / 3];
        for (m, &node) in vademecum.positions.iter().enumerate() {
            position_of[node as usize] = m as u32;
        }
        let at = |m: u32| Vector3::from(vademecum.position_coords_m[m as usize].map(f64::from));
        let mut lists = Self::default();
        for step in &vademecum.steps {
            let local = &step.local;
            let (mut offsets, mut entries) = (vec![0], Vec::new());
            let mut support = Vec::new();
            for i in 0..vademecum.positions.len() {
                let mut reach = Aabb::EMPTY;
                for e in local.corrections_of(i) {
                    let m = position_of[local.correction_nodes[e] as usize];
                    if m != u32::MAX {
                        entries.push((e as u32, m));
                        reach.grow(&Aabb {
                            min: at(m),
                            max: at(m),
                        });
                    }
                }
                offsets.push(entries.len() as u32);
                support.push(reach);
            }
            lists.offsets.push(offsets);
            lists.entries.push(entries);
            lists.support.push(support);
        }
        lists
    }

    fn of(&self, step: usize, position: usize) -> &[(u32, u32)] {
        let offsets = &self.offsets[step];
        &self.entries[step][offsets[position] as usize..offsets[position + 1] as usize]
    }
}

/// The near-field displacement (m) of the master's surface positions under its loads of this
/// tick, summed by [`NearField::gather`] on ticks where a load presses the master, and relaxed
/// (`RELAXATION`). Allocates nothing once grown.
#[derive(Clone, Debug)]
pub struct NearField {
    vademecum: Arc<Vademecum>,
    entries: Arc<SurfaceEntries>,
    loads: Vec<PatchLoad>,
    /// Ticks seen (`set_loads` calls), and the last one gathered on.
    tick: u64,
    gathered_on: Option<u64>,
    /// The box outside which the near field moves no surface position this tick: this tick's
    /// loads', and the last tick's where they were gathered and relaxed into this one.
    support: Aabb,
    /// The support as it was when last gathered, and the farthest the near field then moved a
    /// surface position (m).
    gathered_support: Aabb,
    gathered_largest_m: f32,
    /// The farthest the near field moved a surface position from the last tick's (m), as
    /// gathered.
    gathered_change_m: f32,
    displacement_m: Vec<[f32; 3]>,
    /// This tick's corrections, before relaxing (m).
    /// Lane 3 is scratch ([`crate::pgd::LocalPart::add_residual`]).
    sum_m: Vec<[f32; 4]>,
}

/// The share of this tick's corrections in the near field the contact reads; the rest is the
/// last tick's. The contact solve's compliance leaves out how its forces change the tool's
/// load and with it the corrections, so they answer a tick late; taken whole, that loop rang
/// at half the tick rate after the tool stopped (0.08 % of the force, decaying over 5 ticks)
/// and dithered at 1e-5 of it. Halved, the loop's gain is halved and shifted away from the
/// alternating mode. The field lags the tool by about a tick (1 ms) and is exact once the tool
/// holds still.
const RELAXATION: f32 = 0.5;

/// A near-field motion (m) below what the f32 lattice resolves (6 nm at 0.1 m): once the tool
/// has let go and the relaxed field has decayed below it, the field is no longer carried or
/// gathered, rather than halved every tick for ever.
const NEGLIGIBLE_M: f32 = 1e-9;

impl NearField {
    /// Indexes the corrections at `vademecum`'s surface positions (once per scene).
    pub fn new(vademecum: Arc<Vademecum>) -> Self {
        let entries = Arc::new(SurfaceEntries::new(&vademecum));
        let count = vademecum.positions.len();
        Self {
            vademecum,
            entries,
            loads: Vec::new(),
            tick: 0,
            gathered_on: None,
            support: Aabb::EMPTY,
            gathered_support: Aabb::EMPTY,
            gathered_largest_m: 0.0,
            gathered_change_m: 0.0,
            displacement_m: vec![[0.0; 3]; count],
            sum_m: vec![[0.0; 4]; count],
        }
    }

    /// Takes this tick's loads on the master (the tool's patches); their corrections are summed
    /// by [`Self::gather`].
    pub fn set_loads(&mut self, loads: &[PatchLoad]) {
        loads.clone_into(&mut self.loads);
        self.tick += 1;
        let mut support = Aabb::EMPTY;
        for_each_share(&self.vademecum, &self.loads, |step, position, _| {
            support.grow(&self.entries.support[step][position]);
        });
        let carried = self.gathered_largest_m > NEGLIGIBLE_M;
        if carried && self.gathered_on.is_some_and(|tick| tick + 1 == self.tick) {
            support.grow(&self.gathered_support);
        }
        self.support = support;
    }

    /// Whether the near field moves anything this tick.
    pub fn is_active(&self) -> bool {
        self.support.min.x <= self.support.max.x
    }

    /// How far (m) the near field moves the surface positions within `within_m` of `point_m` at
    /// most, as gathered this tick: 0 where it moves none of them.
    pub fn largest_near_m(&self, point_m: &Vector3<f64>, within_m: f64) -> f32 {
        let largest = self.largest_m();
        match largest > 0.0 && self.support.distance_m(point_m) <= within_m {
            true => largest,
            false => 0.0,
        }
    }

    /// How far (m) the near field moves any surface position, as gathered this tick.
    pub fn largest_m(&self) -> f32 {
        match self.gathered_on == Some(self.tick) {
            true => self.gathered_largest_m,
            false => 0.0,
        }
    }

    /// How far (m) the near field moved any surface position since the last tick.
    pub fn largest_change_m(&self) -> f32 {
        match self.gathered_on {
            Some(tick) if tick == self.tick => self.gathered_change_m,
            // Gathered the tick before, not now: it has dropped to zero.
            Some(tick) if tick + 1 == self.tick => self.gathered_largest_m,
            _ => 0.0,
        }
    }

    /// Sums this tick's corrections at the surface positions, once per tick, relaxed with the
    /// last tick's where it was gathered too.
    pub fn gather(&mut self) {
        let keep = match self.gathered_on {
            Some(tick) if tick == self.tick => return,
            Some(tick) if tick + 1 == self.tick => 1.0 - RELAXATION,
            _ => 0.0,
        };
        self.gathered_on = Some(self.tick);
        self.gathered_support = self.support;
        self.sum_corrections();
        let (mut largest, mut change) = (0.0f32, 0.0f32);
        for (u, sum) in self.displacement_m.iter_mut().zip(&self.sum_m) {
            // The field of a tick not gathered was zero.
            let last = match keep > 0.0 {
                true => Vector3::from(*u),
                false => Vector3::zeros(),
            };
            let relaxed = last * keep + Vector3::new(sum[0], sum[1], sum[2]) * (1.0 - keep);
            largest = largest.max(relaxed.norm());
            change = change.max((relaxed - last).norm());
            *u = relaxed.into();
        }
        self.gathered_largest_m = largest;
        self.gathered_change_m = change;
    }

    /// This tick's corrections at the surface positions, unrelaxed, into `sum_m`.
    fn sum_corrections(&mut self) {
        self.sum_m.fill([0.0; 4]);
        let (vademecum, entries) = (self.vademecum.clone(), self.entries.clone());
        for_each_share(&vademecum, &self.loads, |step, position, force| {
            let force = [0, 1, 2].map(|c| force[c] as f32);
            let local = &vademecum.steps[step].local;
            for &(e, m) in entries.of(step, position) {
                local.add_residual(e as usize, &force, &mut self.sum_m[m as usize]);
            }
        });
    }

    /// Position `position`'s near-field displacement (m) as gathered this tick, zero before.
    pub fn at(&self, position: usize) -> [f32; 3] {
        match self.displacement_m.get(position) {
            Some(u) if self.gathered_on == Some(self.tick) => *u,
            _ => [0.0; 3],
        }
    }
}

/// Calls `visit(step, position, force)` for every share of every active load that carries a
/// force in a load step: `force` is the part of the load's force that position takes there.
fn for_each_share(
    vademecum: &Vademecum,
    loads: &[PatchLoad],
    mut visit: impl FnMut(usize, usize, &Vector3<f64>),
) {
    for load in loads.iter().filter(|l| l.is_active()) {
        let level_n = vademecum.level_force_n(&load.shares, &load.force_n);
        for &(position, share) in &load.shares {
            for step in 0..vademecum.steps.len() {
                let l = vademecum.step_share(step, position, share, level_n);
                if l != 0.0 {
                    visit(step, position, &(load.force_n * l));
                }
            }
        }
    }
}
