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
//! each position's near-field nodes), and only on ticks where a pointshell node comes within
//! reach of the master ([`NearField::gather`] is lazy).

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
    /// Per step and load position: no correction at a surface position is longer than this per
    /// newton of load (m/N; the entry's Frobenius norm, which bounds its action).
    bound_m_per_n: Vec<Vec<f32>>,
}

impl SurfaceEntries {
    fn new(vademecum: &Vademecum) -> Self {
        let mut position_of = vec![u32::MAX; vademecum.dof_count() / 3];
        for (m, &node) in vademecum.positions.iter().enumerate() {
            position_of[node as usize] = m as u32;
        }
        let mut lists = Self::default();
        for step in &vademecum.steps {
            let local = &step.local;
            let (mut offsets, mut entries, mut bounds) = (vec![0], Vec::new(), Vec::new());
            for i in 0..vademecum.positions.len() {
                let mut bound = 0.0f32;
                for e in local.corrections_of(i) {
                    let m = position_of[local.correction_nodes[e] as usize];
                    if m != u32::MAX {
                        entries.push((e as u32, m));
                        let values = &local.correction[9 * e..9 * e + 9];
                        bound = bound.max(values.iter().map(|v| v * v).sum::<f32>().sqrt());
                    }
                }
                offsets.push(entries.len() as u32);
                bounds.push(bound);
            }
            lists.offsets.push(offsets);
            lists.entries.push(entries);
            lists.bound_m_per_n.push(bounds);
        }
        lists
    }

    fn of(&self, step: usize, position: usize) -> &[(u32, u32)] {
        let offsets = &self.offsets[step];
        &self.entries[step][offsets[position] as usize..offsets[position + 1] as usize]
    }
}

/// The near-field displacement (m) of the master's surface positions under its loads of this
/// tick, summed on first use and relaxed ([`RELAXATION`]). Allocates nothing once grown.
#[derive(Clone, Debug)]
pub struct NearField {
    vademecum: Arc<Vademecum>,
    entries: Arc<SurfaceEntries>,
    loads: Vec<PatchLoad>,
    /// Ticks seen (`set_loads` calls), and the last one gathered on.
    tick: u64,
    gathered_on: Option<u64>,
    /// The bound of the loads last gathered (m).
    gathered_bound_m: f32,
    displacement_m: Vec<[f32; 3]>,
}

/// The share of this tick's corrections in the near field the contact reads; the rest is the
/// last tick's. The contact solve's compliance leaves out how its forces change the tool's
/// load and with it the corrections, so they answer a tick late; taken whole, that loop rang
/// at half the tick rate after the tool stopped (0.08 % of the force, decaying over 5 ticks)
/// and dithered at 1e-5 of it. Halved, the loop's gain is halved and shifted away from the
/// alternating mode. The field lags the tool by about a tick (1 ms) and is exact once the tool
/// holds still.
const RELAXATION: f32 = 0.5;

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
            gathered_bound_m: 0.0,
            displacement_m: vec![[0.0; 3]; count],
        }
    }

    /// Takes this tick's loads on the master (the tool's patches); their corrections are summed
    /// when first asked for.
    pub fn set_loads(&mut self, loads: &[PatchLoad]) {
        loads.clone_into(&mut self.loads);
        self.tick += 1;
    }

    /// No surface position moves farther than this (m) by the near field of this tick.
    pub fn bound_m(&self) -> f32 {
        let mut bound = 0.0;
        for_each_share(&self.vademecum, &self.loads, |step, position, force| {
            bound += force.norm() as f32 * self.entries.bound_m_per_n[step][position];
        });
        match self.gathered_on {
            Some(tick) if tick + 1 >= self.tick => bound.max(self.gathered_bound_m),
            _ => bound,
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
        let bound = self.bound_m();
        self.gathered_on = Some(self.tick);
        self.gathered_bound_m = bound;
        for u in &mut self.displacement_m {
            *u = u.map(|c| c * keep);
        }
        let share = 1.0 - keep;
        let (vademecum, entries) = (self.vademecum.clone(), self.entries.clone());
        let loads = std::mem::take(&mut self.loads);
        for_each_share(&vademecum, &loads, |step, position, force| {
            for &(e, m) in entries.of(step, position) {
                let u = vademecum.correction(step, e as usize, force);
                let slot = &mut self.displacement_m[m as usize];
                for c in 0..3 {
                    slot[c] += share * u[c] as f32;
                }
            }
        });
        self.loads = loads;
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
        for &(position, share) in &load.shares {
            for step in 0..vademecum.steps.len() {
                let l = vademecum.step_share(step, position, share, &load.force_n);
                if l != 0.0 {
                    visit(step, position, &(load.force_n * l));
                }
            }
        }
    }
}
