//! How much of each tick's change of the contact forces is taken: Aitken's dynamic
//! relaxation, as partitioned fluid–structure solvers couple their two fields.
//!
//! Each tick solves for the forces with `A`, the compliance projected on the nodes' rest
//! normals, and the next tick measures where the surfaces really went. Where `A` is right the
//! two agree and the whole change is taken. Where the surfaces move more than `A` says (a
//! free master carried deep into the shell organ swings sideways under the forces, and its
//! nodes' distances no longer change along their rest normals), the full change overshoots:
//! measured on `pgd bench contact --case pressed`, a 20 mm press flipped every tick between
//! nodes 0.3 mm and 6.5 mm deep, a 500 Hz buzz in the tool. Aitken's factor comes from the
//! last two changes: `ω_t = −ω_{t−1} r_{t−1}·(r_t − r_{t−1}) / |r_t − r_{t−1}|²`, `r` the
//! change the solve asked for; where the solve overshoots by a steady factor, it is the
//! share that lands on the fixed point. It is used only where the change flips
//! (`r_{t−1}·r_t < 0`): the forces' change also follows what moves the organs (a push that
//! speeds up grows it tick by tick, which the formula would read as divergence), and a change
//! that agrees with the last is taken whole, so a steady push is not slowed.

/// The least share of a change taken: a tenth still reaches a fixed point within some tens
/// of ticks.
const LEAST: f64 = 0.1;

#[derive(Clone, Debug)]
pub struct Relaxation {
    /// The share of the change taken last tick.
    omega: f64,
    /// Per node, the change the solve asked for last tick (N), and the nodes where it is set.
    last_n: Vec<f64>,
    last_nodes: Vec<u32>,
    /// Scratch: whether a node is in this tick's set.
    in_set: Vec<bool>,
}

impl Relaxation {
    pub fn new(count: usize) -> Self {
        Self {
            omega: 1.0,
            last_n: vec![0.0; count],
            last_nodes: Vec::with_capacity(count),
            in_set: vec![false; count],
        }
    }

    /// The room [`Self::new`] made (a clone keeps only the contents).
    pub fn reserve(&mut self) {
        self.last_nodes
            .reserve(self.last_n.len() - self.last_nodes.len());
    }

    /// The share of `change_n` (per node of `set`, the change the solve asked for) to take
    /// this tick, in `[LEAST, 1]`; remembers the change for the next tick.
    pub fn share(&mut self, set: &[u32], change_n: &[f64]) -> f64 {
        let (mut along, mut apart, mut agree) = (0.0, 0.0, 0.0);
        for &i in set {
            let (last, now) = (self.last_n[i as usize], change_n[i as usize]);
            agree += last * now;
            along += last * (now - last);
            apart += (now - last).powi(2);
            self.in_set[i as usize] = true;
        }
        for &j in &self.last_nodes {
            if !self.in_set[j as usize] {
                let last = self.last_n[j as usize];
                along -= last * last;
                apart += last * last;
            }
            self.last_n[j as usize] = 0.0;
        }
        self.last_nodes.clear();
        for &i in set {
            self.in_set[i as usize] = false;
            self.last_n[i as usize] = change_n[i as usize];
            self.last_nodes.push(i);
        }
        self.omega = match agree < 0.0 {
            true => (-self.omega * along / apart).clamp(LEAST, 1.0),
            false => 1.0,
        };
        self.omega
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed-point map `f ↦ f* + g (f* − f)` over two nodes, which overshoots by `g` times
    /// the distance to `f*`: the full change diverges for `g > 1` (it flips about `f*`, ever
    /// wider), the relaxed one lands on `f*` within a few ticks.
    #[test]
    fn an_overshooting_map_converges_relaxed() {
        let target = [2.0, 5.0];
        let set = [0u32, 1];
        for gain in [1.5, 3.0, 6.0] {
            let mut relaxation = Relaxation::new(2);
            let mut f = [0.0, 0.0];
            for _ in 0..30 {
                let change: Vec<f64> = (0..2).map(|i| (target[i] - f[i]) * (1.0 + gain)).collect();
                let omega = relaxation.share(&set, &change);
                (0..2).for_each(|i| f[i] += omega * change[i]);
            }
            for i in 0..2 {
                assert!(
                    (f[i] - target[i]).abs() <= 1e-9 * target[i],
                    "gain {gain}: {f:?}"
                );
            }
        }
    }

    /// Changes that agree, steady, slowing or speeding up, are taken whole; one flip cuts the
    /// share for a tick, and it comes back to 1 with the next change that agrees.
    #[test]
    fn a_steady_push_is_taken_whole() {
        let mut relaxation = Relaxation::new(1);
        for step in [1.0, 1.0, 0.9, 0.8, 0.8, 1.5, 3.0] {
            assert_eq!(relaxation.share(&[0], &[step]), 1.0);
        }
        assert_eq!(relaxation.share(&[0], &[-1.0]), 0.75);
        assert_eq!(relaxation.share(&[0], &[-0.8]), 1.0);
        assert_eq!(relaxation.share(&[0], &[-0.7]), 1.0);
    }

    /// A node that leaves the set counts as a change of zero there.
    #[test]
    fn a_node_that_leaves_counts_as_no_change() {
        let mut relaxation = Relaxation::new(2);
        relaxation.share(&[0, 1], &[1.0, 1.0]);
        // Node 1 gone: r goes from (1, 1) to (1, 0), along = −1, apart = 1: ω = 1.
        assert_eq!(relaxation.share(&[0], &[1.0, 0.0]), 1.0);
        // From (1, 0) to (−1, 0): along −2, apart 4, ω = ½.
        assert_eq!(relaxation.share(&[0], &[-1.0, 0.0]), 0.5);
    }
}
