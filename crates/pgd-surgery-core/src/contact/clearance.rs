//! Which pointshell nodes the contact can skip this tick because they were measured clear of
//! the master not long ago, and nothing has moved far enough since to close the gap.
//!
//! The rest-distance cull ([`super::ContactPair::tick`]) bounds what *can* move, from rest:
//! on the floppy gallbladder, pressed by the tool, that bound reaches every liver node within
//! centimetres (up to 130 reads and 1,550 lattice nodes a tick while the tool slides over the
//! gallbladder, were each measured every tick). Motion from
//! one tick to the next is micrometres, so a node measured 5 mm clear stays clear for hundreds
//! of ticks. Each tick adds how far anything may have moved since the last
//! ([`Clearance::advance`]); a node is skipped while that drift, summed since it was measured,
//! stays below its measured distance over [`SAFETY`].
//!
//! The nodes are not tested one by one each tick: under a press every node lies within the
//! bound from rest (on `--subdivide 5`, all 8,745 points, a third of the stage's tick with 400
//! pushing), and most are known clear for hundreds of ticks. Each block of nodes keeps a drift
//! up to which all its nodes are surely clear (its *wake*), so that
//! [`Clearance::candidates`] passes over a block with one comparison. The contact forces'
//! dimples shift the nodes' read points too; a block's wake is lowered each tick by a bound
//! of how far they shifted any of its nodes ([`super::LocalCompliance::block_shift_m`]),
//! without visiting the nodes (a sliding press changes the dimples of some 8,000 nodes a
//! tick, of which about 1,200 are read).

use super::DistanceField;
use super::pointshell::BLOCK;
use super::pose::OrganPose;
use crate::pgd::RigidCarry;

/// How many times the motion since a measurement the measured distance must exceed for the
/// node to stay clear. The distance read moves with the point it is read from at a slope up
/// to `√3` (trilinear interpolation); the pull-back amplifies a motion of the master's surface
/// by up to `1 / (1 − L)`, `L` the slope of its displacement (≤ 0.5 around the tool, where
/// four fixed-point steps converge); and dividing by the normal stretch changes it by up to
/// 1.5 for that slope. `√3 · 2 · 1.5 ≈ 5.2`; 6 leaves a margin. Exactness is tested: with and
/// without the skip, every tick's forces are the same.
const SAFETY: f64 = 6.0;

#[derive(Clone, Debug, Default)]
pub struct Clearance {
    /// The motion bound summed over every tick so far (m).
    drift_m: f64,
    /// Per node, the summed drift up to which it is clear (m) while its read point's shift
    /// stays where it was measured; −∞ for a node measured every tick (it pushes or is pushed
    /// into).
    clear_until_m: Vec<f64>,
    /// Per node, how far its read point was shifted along its normal when it was measured
    /// (m): the contact forces' dimple, known exactly every tick, so that only its net
    /// change since counts.
    shift_at_m: Vec<f64>,
    /// Per node, its *wake*: less its block's shift since the block was last scanned, a drift
    /// up to which the node is surely clear. Exact when the node is measured or its shift is
    /// read; lowered by its block's shift when the block is scanned without reading it.
    wake_m: Vec<f64>,
    /// Per block of [`BLOCK`] nodes, a drift up to which all its nodes are surely clear:
    /// lowered as a node is measured closer or its dimple may have shifted, raised to the
    /// true least when the block is scanned.
    block_wake_m: Vec<f64>,
    /// Per block, how far the dimples may have shifted any of its nodes since it was last
    /// scanned (m).
    block_shift_m: Vec<f64>,
    /// The last tick's poses, to bound what moved since; none before the first tick.
    last: Option<LastPoses>,
}

#[derive(Clone, Debug)]
struct LastPoses {
    master: Vec<f32>,
    shell: Vec<f32>,
    master_carry: RigidCarry,
    shell_carry: RigidCarry,
}

/// An organ's pose and the per-mode bounds of how far its modes move what the contact reads.
pub struct Moving<'a> {
    pub pose: OrganPose<'a>,
    pub bounds: &'a [f32],
}

impl Clearance {
    pub fn new(count: usize) -> Self {
        Self {
            drift_m: 0.0,
            clear_until_m: vec![f64::NEG_INFINITY; count],
            shift_at_m: vec![0.0; count],
            wake_m: vec![f64::NEG_INFINITY; count],
            block_wake_m: vec![f64::NEG_INFINITY; count.div_ceil(BLOCK)],
            block_shift_m: vec![0.0; count.div_ceil(BLOCK)],
            last: None,
        }
    }

    /// Adds how far (m) a node's read point, or the master's surface under it, can have moved
    /// since the last tick: through either organ's modes or carry, or the master's near field
    /// (`near_moved_m`). Everything counts as moved on the first tick.
    pub fn advance(
        &mut self,
        master: Moving,
        shell: Moving,
        field: &DistanceField,
        near_moved_m: f64,
    ) {
        let moved_m = match &self.last {
            Some(last) => {
                change_bound(master.pose.alpha, &last.master, master.bounds)
                    + change_bound(shell.pose.alpha, &last.shell, shell.bounds)
                    + carry_change_m(master.pose.carry, &last.master_carry, field)
                    + carry_change_m(shell.pose.carry, &last.shell_carry, field)
                    + near_moved_m
            }
            None => f64::INFINITY,
        };
        match moved_m.is_finite() {
            true => self.drift_m += moved_m,
            false => {
                self.clear_until_m.fill(f64::NEG_INFINITY);
                self.wake_m.fill(f64::NEG_INFINITY);
                self.block_wake_m.fill(f64::NEG_INFINITY);
            }
        }
        let last = self.last.get_or_insert_with(|| LastPoses {
            master: Vec::new(),
            shell: Vec::new(),
            master_carry: RigidCarry::default(),
            shell_carry: RigidCarry::default(),
        });
        master.pose.alpha.clone_into(&mut last.master);
        shell.pose.alpha.clone_into(&mut last.shell);
        last.master_carry = *master.pose.carry;
        last.shell_carry = *shell.pose.carry;
    }

    /// The drift up to which node `i`, its read point now shifted by `shift_m` along its
    /// normal, is surely clear of the master (m): its budget, less how far the shift moved
    /// since it was measured.
    fn exact_wake_m(&self, i: usize, shift_m: f64) -> f64 {
        self.clear_until_m[i] - (shift_m - self.shift_at_m[i]).abs()
    }

    /// Node `i` was measured `distance_m` from the master this tick (negative inside), its
    /// read point shifted by `shift_m` along its normal.
    pub fn measured(&mut self, i: usize, distance_m: f64, shift_m: f64) {
        self.clear_for(i, distance_m / SAFETY, shift_m);
    }

    /// Node `i`'s read point, shifted by `shift_m` along its normal, lies `outside_m` outside
    /// the master's lattice: no distance can be read there until it has moved that far, and
    /// none is needed (the lattice reaches farther around the master than it can move).
    /// Without this, a press that carries the lattice into the shell organ left hundreds of
    /// its nodes just past the lattice's edge read every tick (299 of 616 on
    /// `--subdivide 4`).
    pub fn outside_lattice(&mut self, i: usize, outside_m: f64, shift_m: f64) {
        self.clear_for(i, outside_m, shift_m);
    }

    /// Node `i` stays clear until the drift has grown by `budget_m` or its shift changed.
    fn clear_for(&mut self, i: usize, budget_m: f64, shift_m: f64) {
        self.clear_until_m[i] = self.drift_m + budget_m;
        self.shift_at_m[i] = shift_m;
        self.wake_m[i] = self.clear_until_m[i];
        self.lower_block(i);
    }

    /// Node `i` pushes or is pushed into: it is measured every tick, whatever its clearance.
    pub fn keep_measuring(&mut self, i: usize) {
        self.clear_until_m[i] = f64::NEG_INFINITY;
        self.wake_m[i] = f64::NEG_INFINITY;
        self.lower_block(i);
    }

    /// The dimples may have shifted the read point of any node in block `b` by up to
    /// `shift_m` this tick: the block wakes as much earlier.
    pub fn shifted(&mut self, b: usize, shift_m: f64) {
        self.block_wake_m[b] -= shift_m;
        self.block_shift_m[b] += shift_m;
    }

    /// Node `i`'s wake was just set exactly: the block's wake is lowered to it. The block's
    /// shift so far does not apply to the node, but is taken off every node of the block at
    /// its next scan, so the node's wake is raised by as much.
    fn lower_block(&mut self, i: usize) {
        let b = i / BLOCK;
        self.block_wake_m[b] = self.block_wake_m[b].min(self.wake_m[i]);
        self.wake_m[i] += self.block_shift_m[b];
    }

    /// Adds to `out` the nodes below `count` not surely clear, their read points now shifted
    /// by `shift_m(i)` along their normals, and raises the wake of each block it scans to its
    /// least; a block of nodes all surely clear costs one comparison. Within a scanned block,
    /// a node's shift is read only where its wake, less the block's shift, no longer clears
    /// it.
    pub fn candidates(&mut self, count: usize, shift_m: impl Fn(usize) -> f64, out: &mut Vec<u32>) {
        let drift_m = self.drift_m;
        for block in 0..self.block_wake_m.len() {
            let start = block * BLOCK;
            if start >= count {
                break;
            }
            if self.block_wake_m[block] > drift_m {
                continue;
            }
            let shifted_m = std::mem::take(&mut self.block_shift_m[block]);
            let mut least = f64::INFINITY;
            for i in start..self.clear_until_m.len().min(start + BLOCK) {
                let mut wake = self.wake_m[i] - shifted_m;
                if wake <= drift_m && wake != f64::NEG_INFINITY {
                    wake = self.exact_wake_m(i, shift_m(i));
                }
                self.wake_m[i] = wake;
                least = least.min(wake);
                if wake <= drift_m && i < count {
                    out.push(i as u32);
                }
            }
            self.block_wake_m[block] = least;
        }
    }
}

/// `Σ_k |α_k − α'_k| b_k`: how far modes with per-mode bounds `bounds` can have moved anything
/// between coefficients `last` and `now`; infinite if their counts differ.
fn change_bound(now: &[f32], last: &[f32], bounds: &[f32]) -> f64 {
    if now.len() != last.len() {
        return f64::INFINITY;
    }
    let change = now.iter().zip(last).zip(bounds);
    change.map(|((a, b), m)| ((a - b).abs() * m) as f64).sum()
}

/// How far (m) a change of rigid carry from `last` to `now` can have moved a point of the
/// lattice.
fn carry_change_m(now: &RigidCarry, last: &RigidCarry, field: &DistanceField) -> f64 {
    carry_change_within_m(now, last, field.farthest_from_m(&last.centre_m))
}

/// How far (m) a change of rigid carry from `last` to `now` can have moved a point within
/// `reach_m` of the last centre `c'`: `u_now − u_last = (Δt + ω × (c' − c)) + Δω × (p − c')`.
fn carry_change_within_m(now: &RigidCarry, last: &RigidCarry, reach_m: f64) -> f64 {
    let shift = now.translation_m - last.translation_m
        + now.rotation_rad.cross(&(last.centre_m - now.centre_m));
    let turn = now.rotation_rad - last.rotation_rad;
    shift.norm() + turn.norm() * reach_m
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;

    /// The bound holds at points spread through the reach, for carries whose centres differ,
    /// and one of them comes within 2 % of it (1.2 % here): it is not loose.
    #[test]
    fn a_carry_change_moves_no_point_farther_than_its_bound() {
        let last = RigidCarry {
            translation_m: Vector3::new(1e-3, -2e-3, 0.5e-3),
            rotation_rad: Vector3::new(0.01, 0.02, -0.015),
            centre_m: Vector3::new(0.05, 0.1, -0.02),
        };
        let now = RigidCarry {
            translation_m: Vector3::new(1.2e-3, -1.7e-3, 0.4e-3),
            rotation_rad: Vector3::new(0.012, 0.017, -0.01),
            centre_m: Vector3::new(0.052, 0.098, -0.021),
        };
        let reach_m = 0.08;
        let bound = carry_change_within_m(&now, &last, reach_m);
        let mut largest = 0.0f64;
        let steps = 12;
        for i in 0..=steps {
            for j in 0..=2 * steps {
                let (polar, azimuth) = (
                    std::f64::consts::PI * i as f64 / steps as f64,
                    std::f64::consts::PI * j as f64 / steps as f64,
                );
                let direction = Vector3::new(
                    polar.sin() * azimuth.cos(),
                    polar.sin() * azimuth.sin(),
                    polar.cos(),
                );
                for r in [0.0, 0.5, 1.0] {
                    let p = last.centre_m + direction * reach_m * r;
                    let moved = (now.at(&p) - last.at(&p)).norm();
                    assert!(
                        moved <= bound * (1.0 + 1e-12),
                        "{moved} m against {bound} m"
                    );
                    largest = largest.max(moved);
                }
            }
        }
        assert!(
            largest >= 0.98 * bound,
            "largest {largest} m, bound {bound} m"
        );
    }

    /// The nodes `candidates` lists below `count`, node `i`'s read point shifted by
    /// `shifts_m[i]`.
    fn listed(clearance: &mut Clearance, count: usize, shifts_m: &[f64]) -> Vec<u32> {
        let mut out = Vec::new();
        clearance.candidates(count, |i| shifts_m[i], &mut out);
        out
    }

    /// Whether a one-node clearance leaves its node unlisted, shifted by `shift_m`.
    fn is_clear(clearance: &mut Clearance, shift_m: f64) -> bool {
        listed(clearance, 1, &[shift_m]).is_empty()
    }

    /// A node measured clear stays clear while its read point's shift changes less than its
    /// budget, whichever way, and a shift that comes back costs nothing.
    #[test]
    fn a_shift_counts_by_its_net_change_since_the_measurement() {
        let mut clearance = Clearance::new(1);
        clearance.measured(0, 6e-3, 2e-3);
        // Budget: 6 mm / SAFETY = 1 mm.
        for (shift_m, clear) in [
            (2e-3, true),
            (2.9e-3, true),
            (1.1e-3, true),
            (3.1e-3, false),
            (0.9e-3, false),
        ] {
            // Told of each shift, as the dimples tell it, so that the block is scanned.
            clearance.shifted(0, 2e-3);
            assert_eq!(is_clear(&mut clearance, shift_m), clear, "{shift_m} m");
        }
        clearance.measured(0, -1e-3, 0.0);
        assert!(
            !is_clear(&mut clearance, 0.0),
            "a node inside is never clear"
        );
    }

    /// Every node not surely clear is listed, across blocks, and only below `count`; one
    /// measured clear is not, until its dimple moves its read point past its budget and its
    /// block is told so, or it pushes.
    #[test]
    fn the_candidates_are_the_nodes_not_known_clear() {
        let count = 3 * BLOCK + 5;
        let mut clearance = Clearance::new(count);
        let mut shifts_m = vec![0.0; count];
        let all: Vec<u32> = (0..count as u32).collect();
        assert_eq!(
            listed(&mut clearance, count, &shifts_m),
            all,
            "none measured yet"
        );
        for i in 0..count {
            clearance.measured(i, 6e-3, 0.0);
        }
        // Inside, and clear by a budget already spent: measured every tick.
        clearance.measured(1, -1e-3, 0.0);
        clearance.measured(BLOCK + 7, 0.0, 0.0);
        let always = [1, BLOCK as u32 + 7];
        assert_eq!(listed(&mut clearance, count, &shifts_m), always);
        assert_eq!(
            listed(&mut clearance, BLOCK, &shifts_m),
            [1],
            "beyond the count"
        );
        // Budget 1 mm: a dimple of 0.9 mm keeps the node clear, 1.1 mm does not, however it
        // got there; a block is scanned only once told of a shift.
        let (a, b) = (2 * BLOCK + 3, 3 * BLOCK + 4);
        shifts_m[a] = 0.9e-3;
        clearance.shifted(a / BLOCK, 0.9e-3);
        shifts_m[b] = 0.5e-3;
        clearance.shifted(b / BLOCK, 0.5e-3);
        assert_eq!(listed(&mut clearance, count, &shifts_m), always);
        shifts_m[b] = -1.1e-3;
        assert_eq!(
            listed(&mut clearance, count, &shifts_m),
            always,
            "the block not told: not scanned"
        );
        clearance.shifted(b / BLOCK, 1.6e-3);
        assert_eq!(
            listed(&mut clearance, count, &shifts_m),
            [1, BLOCK as u32 + 7, b as u32]
        );
        // A node that pushes is listed though measured clear; measured again, it is not.
        clearance.keep_measuring(a);
        assert_eq!(
            listed(&mut clearance, count, &shifts_m),
            [1, BLOCK as u32 + 7, a as u32, b as u32]
        );
        clearance.measured(a, 6e-3, shifts_m[a]);
        clearance.measured(b, 6e-3, shifts_m[b]);
        assert_eq!(listed(&mut clearance, count, &shifts_m), always);
    }

    /// A scanned block reads the shift of only those nodes its shift may have woken, and a
    /// node measured closer after its block shifted is listed though its wake carries the
    /// block's shift.
    #[test]
    fn a_scanned_block_reads_only_the_shifts_that_may_wake_a_node() {
        let mut clearance = Clearance::new(BLOCK);
        for i in 0..BLOCK {
            // Budgets: 1 mm for the even nodes, 10 mm for the odd ones.
            let distance_m = if i % 2 == 0 { 6e-3 } else { 60e-3 };
            clearance.measured(i, distance_m, 0.0);
        }
        let read = std::cell::RefCell::new(Vec::new());
        let listed = |clearance: &mut Clearance, shift_m: f64| {
            read.borrow_mut().clear();
            let mut out = Vec::new();
            clearance.candidates(
                BLOCK,
                |i| {
                    read.borrow_mut().push(i as u32);
                    shift_m
                },
                &mut out,
            );
            out
        };
        assert!(listed(&mut clearance, 0.0).is_empty());
        clearance.shifted(0, 2e-3);
        assert!(listed(&mut clearance, 0.5e-3).is_empty());
        let even: Vec<u32> = (0..BLOCK as u32).step_by(2).collect();
        assert_eq!(
            *read.borrow(),
            even,
            "the odd nodes' 10 mm budgets clear 2 mm"
        );
        // The block's wake: the even nodes' 0.5 mm, less 0.2 mm, still above the drift.
        clearance.shifted(0, 0.2e-3);
        clearance.measured(1, 0.0, 0.5e-3);
        assert_eq!(listed(&mut clearance, 0.5e-3), [1]);
    }

    /// A node read outside the lattice stays clear for as far as it lies outside, with no
    /// safety factor (the lattice's edge is known exactly, a distance read is not).
    #[test]
    fn a_node_outside_the_lattice_is_clear_until_it_can_reach_it() {
        let mut clearance = Clearance::new(1);
        clearance.outside_lattice(0, 1e-3, 0.0);
        for (shift_m, clear) in [(0.9e-3, true), (-0.9e-3, true), (1.1e-3, false)] {
            clearance.shifted(0, 1.1e-3);
            assert_eq!(is_clear(&mut clearance, shift_m), clear, "{shift_m} m");
        }
    }
}
