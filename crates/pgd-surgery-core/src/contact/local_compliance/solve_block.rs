//! The near-field part of `A` over the nodes of one tick's force solve, kept as `G S Gᵀ`
//! restricted to the directions those nodes read.
//!
//! Why not the dense block between the nodes: on a subdivided pointshell the
//! nodes pushing outnumber the positions they load, and `S` between those positions is
//! sparse. Measured on `--subdivide 5` with 407 points sliding, they read 453 directions,
//! with 11,178 entries of `S` between them and 12 of `G` a node: about 21,000 products
//! against 166,000 for the dense block, which at 1.3 MB in `f64` does not even fit a core's
//! L2. Nor is there a block to copy from tick to tick: only the set's rows of `G`
//! (renumbered) and, when the directions change, `S` between them are gathered.

use super::sparse::SparseRows;

/// Marks a direction the set does not read.
const NO_SLOT: u32 = u32::MAX;

#[derive(Clone, Debug, Default)]
pub(super) struct SolveBlock {
    /// The nodes it was built for: a tick whose set is the same keeps it (a press at rest).
    set: Vec<u32>,
    /// The directions the set reads, ascending, and per direction its place among them
    /// (`NO_SLOT` for the others).
    directions: Vec<u32>,
    slot: Vec<u32>,
    /// Scratch: the next set's directions, and which are already listed.
    next_directions: Vec<u32>,
    listed: Vec<bool>,
    /// Per node of the set, in its order: its row of `G` by slot.
    reads: SparseRows,
    /// `S` between the set's directions, by slot (m/N).
    compliance: SparseRows,
    /// Scratch of a product: the forces summed per direction (N), and how far that moves
    /// each direction (m).
    loads_n: Vec<f64>,
    moves_m: Vec<f64>,
}

impl SolveBlock {
    /// An empty block for a compliance of `directions` directions.
    pub(super) fn new(directions: usize) -> Self {
        let mut block = Self {
            slot: vec![NO_SLOT; directions],
            listed: vec![false; directions],
            ..Self::default()
        };
        block.reads.clear();
        block.compliance.clear();
        block
    }

    /// Room for the largest set: every one of `nodes` nodes, reading every direction, with
    /// `reads` and `compliance` whole (their entries), so that preparing allocates nothing.
    pub(super) fn reserve(&mut self, nodes: usize, reads: &SparseRows, compliance: &SparseRows) {
        let directions = self.slot.len();
        self.set.reserve(nodes);
        self.directions.reserve(directions);
        self.next_directions.reserve(directions);
        self.reads.reserve(nodes, reads.entries());
        self.compliance.reserve(directions, compliance.entries());
        self.loads_n.reserve(directions);
        self.moves_m.reserve(directions);
    }

    /// Sets up the block for the nodes of `set`, given `G` (`reads`, per node) and `S`
    /// (`compliance`, per direction). `S` is gathered anew only where the directions changed.
    pub(super) fn prepare(&mut self, set: &[u32], reads: &SparseRows, compliance: &SparseRows) {
        if self.set == set {
            return;
        }
        self.set.clear();
        self.set.extend_from_slice(set);
        if self.list_directions(reads) {
            self.gather_compliance(compliance);
        }
        self.reads.clear();
        for &i in set {
            let (directions, coefficients) = reads.row(i as usize);
            let slots = directions.iter().map(|&d| self.slot[d as usize]);
            self.reads.push_row(slots.zip(coefficients.iter().copied()));
        }
    }

    /// Lists the directions the set reads; returns whether they changed.
    fn list_directions(&mut self, reads: &SparseRows) -> bool {
        self.next_directions.clear();
        for &i in &self.set {
            for &d in reads.row(i as usize).0 {
                if !self.listed[d as usize] {
                    self.listed[d as usize] = true;
                    self.next_directions.push(d);
                }
            }
        }
        for &d in &self.next_directions {
            self.listed[d as usize] = false;
        }
        self.next_directions.sort_unstable();
        if self.next_directions == self.directions {
            return false;
        }
        for &d in &self.directions {
            self.slot[d as usize] = NO_SLOT;
        }
        std::mem::swap(&mut self.directions, &mut self.next_directions);
        for (k, &d) in self.directions.iter().enumerate() {
            self.slot[d as usize] = k as u32;
        }
        self.loads_n.resize(self.directions.len(), 0.0);
        self.moves_m.resize(self.directions.len(), 0.0);
        true
    }

    /// `S` between the listed directions: each one's row, less the columns not listed.
    fn gather_compliance(&mut self, compliance: &SparseRows) {
        self.compliance.clear();
        for &d in &self.directions {
            let (columns, values) = compliance.row(d as usize);
            let slot = &self.slot;
            self.compliance.push_row(
                columns
                    .iter()
                    .zip(values)
                    .map(|(&e, &s)| (slot[e as usize], s))
                    .filter(|e| e.0 != NO_SLOT),
            );
        }
    }

    /// Adds `(G S Gᵀ v)_i` to `out[i]` for every `i` in `set`, the set [`Self::prepare`]
    /// took, from `v` on those nodes alone.
    pub(super) fn add_product(&mut self, set: &[u32], v: &[f64], out: &mut [f64]) {
        debug_assert_eq!(self.set, set, "prepared for another set");
        self.loads_n.fill(0.0);
        for (k, &i) in set.iter().enumerate() {
            let f = v[i as usize];
            let (slots, coefficients) = self.reads.row(k);
            for (&p, &c) in slots.iter().zip(coefficients) {
                self.loads_n[p as usize] += c * f;
            }
        }
        for (p, moved) in self.moves_m.iter_mut().enumerate() {
            let (slots, values) = self.compliance.row(p);
            *moved = slots
                .iter()
                .zip(values)
                .map(|(&q, &s)| s * self.loads_n[q as usize])
                .sum();
        }
        for (k, &i) in set.iter().enumerate() {
            let (slots, coefficients) = self.reads.row(k);
            out[i as usize] += slots
                .iter()
                .zip(coefficients)
                .map(|(&p, &c)| c * self.moves_m[p as usize])
                .sum::<f64>();
        }
    }
}
