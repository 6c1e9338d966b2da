//! The part of a contact pair's normal compliance `A` that the modes cannot carry: how a
//! contact force dimples both organs near where it pushes.
//!
//! A few smooth modes are far too stiff under a point load (a rank-50 truncation's felt force
//! is 2,000 % off, `docs/pgd.md`), so with modes alone a few pushing nodes would move the
//! liver clear of a whole intrusion, and the contact would feel stiffer than the tissue. Every load position of a
//! vademecum stores its near-field correction (its exact response minus the modes, at every
//! node within the local radius), so the exact compliance between two nodes close enough is
//! the modal one plus `a_ij = Σ_ab w_ia w_jb n_i · R_b(a) · n_j` over the positions `a`, `b`
//! they blend (symmetrized), for both organs (the shell organ at the nodes' load positions,
//! the master at the positions that take the reactions). It acts in two places:
//! - `A` takes it in the force solve, so the solve sees the tissue as soft as it is;
//! - each measured distance takes it times the forces already pushing, because the modal
//!   coefficients the distance is read with carry only the modal part of their effect.
//!
//! **Kept per position, not per node.** `a = G S Gᵀ`: `Gᵀ` sums the nodes' normal forces
//! into forces at the positions, along a few directions each (`G` is sparse, a node's row its
//! blend), and `S` holds the corrections between positions. A pointshell finer than the mesh
//! (`Subdivided(n)`, `n²` points a triangle) then costs what the mesh costs: kept per node,
//! its rows grew with `n²` (some 4,000 entries a node on `--subdivide 5`), and the solve's
//! dense block with the square of the nodes pushing. A position loaded by nodes of one normal
//! (a boundary node alone at its position) keeps one direction.
//!
//! The linear load step's corrections are used (contact forces are spread over many nodes,
//! each well inside the first step), and each pair's own forces only: a reaction another pair
//! puts on the master dimples it for that pair alone.

mod organ_part;
mod solve_block;
mod sparse;

use nalgebra::Vector3;

use self::organ_part::OrganPart;
use self::solve_block::SolveBlock;
use self::sparse::{Scattered, SparseRows};
use super::pointshell::{BLOCK, Pointshell};
use crate::pgd::Vademecum;

/// The near-field compliance as `G S Gᵀ`, with what each tick derives from it. The two
/// organs' directions are numbered one after the other, the shell organ's first.
///
/// The dimples spread each pushing node's force to every node within reach: through the
/// directions, a few rows per position reached, rather than a row per node reached. The force
/// solve works on the pushing nodes alone, through `G` and `S` restricted to them
/// ([`SolveBlock`]).
#[derive(Clone, Debug, Default)]
pub struct LocalCompliance {
    /// `G`: per node, the directions its normal force loads and its distance reads, with
    /// their coefficients (weight times the cosine to the node's normal).
    reads: SparseRows,
    /// Per direction, the blocks of [`BLOCK`] nodes that read it, each with the largest
    /// `|G_id|` among its nodes: bounds how far a move of the direction shifts any of them.
    block_readers: SparseRows,
    /// The largest `Σ_d |G_id|` of any node: bounds the dimples by the directions' moves.
    largest_read_sum: f64,
    /// `S` between directions (m/N), both organs, symmetric, no entry across organs.
    compliance: SparseRows,
    /// Per node, each organ's own `a_ii`: `[shell, master]` (m/N).
    own_m_per_n: Vec<[f64; 2]>,
    /// How far the forces of [`Self::spread_n`] move each direction, `S Gᵀ f` (m): node
    /// `i`'s dimple `Σ_j a_ij f_j` is its row of `G` times these, read when it is measured.
    moves_m: Scattered,
    /// The scratch a change of the forces passes through: per node, per direction summed, and
    /// how far that moves each direction (m).
    changes_n: Scattered,
    loads_n: Scattered,
    move_changes_m: Scattered,
    /// The forces the dimples hold (N, per node) and the nodes where they are not zero.
    spread_n: Vec<f64>,
    spread_nodes: Vec<u32>,
    /// Ticks since the dimples were last summed whole rather than changed.
    ticks_changed: u32,
    /// At least the largest dimple of any node this tick (m).
    largest_gap_m: f64,
    /// Per block of nodes, at least how far this tick changed the dimple of any of its nodes
    /// (m); the blocks it holds are those where one may have changed.
    block_shifts_m: Scattered,
    block: SolveBlock,
}

/// How many ticks the dimples are changed by the forces' changes before they are summed whole
/// again: each change leaves rounding behind (1e-16 of the dimple), which a second's worth
/// cannot make felt, and the whole sum costs no more than a tick where every force changed.
const TICKS_BETWEEN_WHOLE_SUMS: u32 = 1000;

impl LocalCompliance {
    /// Both organs' corrections between the positions `nodes` loads, once per pair at setup.
    pub fn new(nodes: &Pointshell, master: &Vademecum, shell: &Vademecum) -> Self {
        let parts = [
            OrganPart::new(shell, nodes.blends.iter().cloned()),
            OrganPart::new(
                master,
                (0..nodes.len()).map(|i| nodes.master_blend(i).to_vec()),
            ),
        ];
        Self::assemble(&parts, &nodes.rest_normal)
    }

    /// `G`, `S` and `a` from the two organs' parts (shell, master), nodes along `normals`.
    fn assemble(parts: &[OrganPart; 2], normals: &[Vector3<f64>]) -> Self {
        let count = normals.len();
        let mut reads: Vec<Vec<(u32, f64)>> = vec![Vec::new(); count];
        let mut compliance = Vec::new();
        let mut first_direction = 0;
        let mut shell_directions = 0;
        for (o, part) in parts.iter().enumerate() {
            let directions = part.directions(normals);
            let numbers;
            (numbers, first_direction) = numbering(first_direction, &directions);
            add_reads(&mut reads, part, normals, &directions, &numbers);
            compliance.extend(direction_rows(part, &directions, &numbers));
            if o == 0 {
                shell_directions = first_direction as usize;
            }
        }
        for row in &mut reads {
            row.sort_by_key(|e| e.0);
        }
        let reads = SparseRows::from_rows(reads);
        let compliance = SparseRows::from_rows(compliance);
        let directions = compliance.rows();
        let mut part = Self {
            block_readers: block_readers(&reads, directions),
            largest_read_sum: (0..count)
                .map(|i| reads.row(i).1.iter().map(|c| c.abs()).sum())
                .fold(0.0, f64::max),
            reads,
            compliance,
            loads_n: Scattered::new(directions),
            moves_m: Scattered::new(directions),
            move_changes_m: Scattered::new(directions),
            block_shifts_m: Scattered::new(count.div_ceil(BLOCK)),
            changes_n: Scattered::new(count),
            spread_n: vec![0.0; count],
            block: SolveBlock::new(directions),
            ..Self::default()
        };
        part.own_m_per_n = (0..count).map(|i| part.own(i, shell_directions)).collect();
        part.reserve();
        part
    }

    /// Room in every work list for all the nodes and directions at once (a clone keeps only
    /// the contents), so that a tick allocates nothing however many nodes push.
    pub fn reserve(&mut self) {
        let count = self.spread_n.len();
        self.spread_nodes.reserve(count);
        for scattered in [
            &mut self.moves_m,
            &mut self.changes_n,
            &mut self.loads_n,
            &mut self.move_changes_m,
            &mut self.block_shifts_m,
        ] {
            scattered.reserve();
        }
        self.block.reserve(count, &self.reads, &self.compliance);
    }

    /// Node `i`'s `a_ii` in each organ: `Σ_de G_id S_de G_ie` over the organ's directions
    /// (the shell organ's below `shell_directions`).
    fn own(&self, i: usize, shell_directions: usize) -> [f64; 2] {
        let (directions, coefficients) = self.reads.row(i);
        let mut own = [0.0; 2];
        for (&d, &c) in directions.iter().zip(coefficients) {
            for (&e, &g) in directions.iter().zip(coefficients) {
                let organ = usize::from(d as usize >= shell_directions);
                own[organ] += c * g * self.compliance.get(d as usize, e as usize);
            }
        }
        own
    }

    /// Node `i`'s own local compliance in the shell organ and in the master (m/N).
    pub fn own_m_per_n(&self, i: usize) -> [f64; 2] {
        self.own_m_per_n[i]
    }

    /// Takes the forces pushing at the start of the tick (`force_n` on the nodes of
    /// `pushing`) into the dimples, through how they changed since the last tick: a press at
    /// rest, or one where a few nodes' forces change, costs what changed rather than every
    /// pushing node's reach (on `--subdivide 4`, 317 points pushing at rest, 69 µs a tick).
    pub fn dimple(&mut self, pushing: &[u32], force_n: &[f64]) {
        self.ticks_changed += 1;
        self.block_shifts_m.clear();
        let forgot = self.ticks_changed >= TICKS_BETWEEN_WHOLE_SUMS;
        if forgot {
            self.forget_forces();
        }
        for &j in &self.spread_nodes {
            self.changes_n.add(j as usize, -self.spread_n[j as usize]);
            self.spread_n[j as usize] = 0.0;
        }
        self.spread_nodes.clear();
        for &j in pushing {
            let f = force_n[j as usize];
            if f != 0.0 {
                self.changes_n.add(j as usize, f);
                self.spread_n[j as usize] = f;
                self.spread_nodes.push(j);
            }
        }
        let changes = std::mem::take(&mut self.changes_n);
        let moved = self.spread(
            changes
                .touched()
                .iter()
                .map(|&j| (j, changes.get(j as usize)))
                .filter(|e| e.1 != 0.0),
        );
        self.changes_n = changes;
        self.changes_n.clear();
        if !(moved || forgot) {
            // The same moves: a press at rest keeps its largest dimple.
            return;
        }
        let moves = &self.moves_m;
        let largest_move_m = moves
            .touched()
            .iter()
            .map(|&e| moves.get(e as usize).abs())
            .fold(0.0, f64::max);
        self.largest_gap_m = self.largest_read_sum * largest_move_m;
    }

    /// At least the largest of [`Self::gap_m`] over the nodes (m): bounds how far the dimples
    /// moved any node's read point.
    pub fn largest_gap_m(&self) -> f64 {
        self.largest_gap_m
    }

    /// The blocks of [`BLOCK`] nodes (node `i` in block `i / BLOCK`) where [`Self::dimple`]
    /// may have changed a dimple this tick, each once.
    pub fn shifted_blocks(&self) -> &[u32] {
        self.block_shifts_m.touched()
    }

    /// At least how far (m) this tick changed the dimple of any node in block `b`.
    pub fn block_shift_m(&self, b: usize) -> f64 {
        self.block_shifts_m.get(b)
    }

    /// Drops every force from the dimples, so that the next are summed whole.
    fn forget_forces(&mut self) {
        for &e in self.moves_m.touched() {
            let moved_m = self.moves_m.get(e as usize).abs();
            mark_shifted(&self.block_readers, e, moved_m, &mut self.block_shifts_m);
        }
        self.moves_m.clear();
        for &j in &self.spread_nodes {
            self.spread_n[j as usize] = 0.0;
        }
        self.spread_nodes.clear();
        self.ticks_changed = 0;
    }

    /// Adds `S Gᵀ f` to the directions' moves for the normal forces `(node, f)`: summed per
    /// direction, moved through `S`, at a cost of the directions they reach; the blocks whose
    /// nodes read a moved direction are marked shifted. Returns whether any direction moved.
    fn spread(&mut self, forces: impl Iterator<Item = (u32, f64)>) -> bool {
        for (j, f) in forces {
            let (directions, coefficients) = self.reads.row(j as usize);
            for (&d, &c) in directions.iter().zip(coefficients) {
                self.loads_n.add(d as usize, c * f);
            }
        }
        for &d in self.loads_n.touched() {
            let f = self.loads_n.get(d as usize);
            let (directions, values) = self.compliance.row(d as usize);
            for (&e, &s) in directions.iter().zip(values) {
                self.move_changes_m.add(e as usize, s * f);
            }
        }
        for &e in self.move_changes_m.touched() {
            let change_m = self.move_changes_m.get(e as usize);
            self.moves_m.add(e as usize, change_m);
            mark_shifted(
                &self.block_readers,
                e,
                change_m.abs(),
                &mut self.block_shifts_m,
            );
        }
        let moved = !self.move_changes_m.touched().is_empty();
        self.loads_n.clear();
        self.move_changes_m.clear();
        moved
    }

    /// `Σ_j a_ij f_j`: how far the forces taken by [`Self::dimple`] move node `i`'s distance
    /// (m) beyond their modes, `G` times the directions' moves.
    pub fn gap_m(&self, i: usize) -> f64 {
        let (directions, coefficients) = self.reads.row(i);
        directions
            .iter()
            .zip(coefficients)
            .map(|(&d, &c)| c * self.moves_m.get(d as usize))
            .sum()
    }

    /// Sets up the block of the tick's force solve over the nodes of `set`, so that each
    /// product costs the entries of `G` and `S` between them ([`SolveBlock`]).
    pub fn prepare(&mut self, set: &[u32]) {
        self.block.prepare(set, &self.reads, &self.compliance);
    }

    /// Adds `Σ_j a_ij v_j` over `j` in `set` to `out[i]` for every `i` in `set`, the set
    /// [`Self::prepare`] took.
    pub fn add_product(&mut self, set: &[u32], v: &[f64], out: &mut [f64]) {
        self.block.add_product(set, v, out);
    }
}

/// Per direction, the blocks of [`BLOCK`] nodes whose rows of `G` (`reads`) hold it, each
/// with the largest `|G_id|` in the block, blocks ascending.
fn block_readers(reads: &SparseRows, directions: usize) -> SparseRows {
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); directions];
    for i in 0..reads.rows() {
        let block = (i / BLOCK) as u32;
        let (columns, coefficients) = reads.row(i);
        for (&d, &c) in columns.iter().zip(coefficients) {
            let row = &mut rows[d as usize];
            match row.last_mut() {
                Some(last) if last.0 == block => last.1 = last.1.max(c.abs()),
                _ => row.push((block, c.abs())),
            }
        }
    }
    SparseRows::from_rows(rows)
}

/// Marks the blocks reading direction `e` as shifted by as much as a move of `moved_m` (m)
/// there can shift their nodes.
fn mark_shifted(block_readers: &SparseRows, e: u32, moved_m: f64, shifts: &mut Scattered) {
    let (blocks, coefficients) = block_readers.row(e as usize);
    for (&b, &c) in blocks.iter().zip(coefficients) {
        shifts.add(b as usize, c * moved_m);
    }
}

/// Adds to each node's row of `G` the directions of `part` its force loads: its weight at
/// each position times the cosine of each direction there to its normal.
fn add_reads(
    reads: &mut [Vec<(u32, f64)>],
    part: &OrganPart,
    normals: &[Vector3<f64>],
    directions: &[Vec<Vector3<f64>>],
    numbers: &[u32],
) {
    for (i, blend) in part.blends.iter().enumerate() {
        for &(a, w) in blend {
            for (k, e) in directions[a].iter().enumerate() {
                let c = w * normals[i].dot(e);
                if c != 0.0 {
                    reads[i].push((numbers[a] + k as u32, c));
                }
            }
        }
    }
}

/// `part`'s rows of `S` between directions, `d · S_ab · e`, columns ascending.
fn direction_rows(
    part: &OrganPart,
    directions: &[Vec<Vector3<f64>>],
    numbers: &[u32],
) -> Vec<Vec<(u32, f64)>> {
    let mut rows = Vec::new();
    for (a, blocks) in part.blocks.iter().enumerate() {
        for d in &directions[a] {
            let mut row = Vec::new();
            for (&b, s) in blocks {
                let sd = s.tr_mul(d);
                for (l, e) in directions[b].iter().enumerate() {
                    row.push((numbers[b] + l as u32, sd.dot(e)));
                }
            }
            row.retain(|e| e.1 != 0.0);
            rows.push(row);
        }
    }
    rows
}

/// The number of each position's first direction, counting on from `first`, and the next
/// number free.
fn numbering(first: u32, directions: &[Vec<Vector3<f64>>]) -> (Vec<u32>, u32) {
    let mut next = first;
    let numbers = directions
        .iter()
        .map(|d| {
            next += d.len() as u32;
            next - d.len() as u32
        })
        .collect();
    (numbers, next)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use nalgebra::Matrix3;

    use super::*;

    /// Four nodes on three shell positions and two master positions. Position 0 of the shell
    /// is loaded by nodes of two normals, position 1 by one normal (nodes 1 and 3), position 2
    /// by two; each organ's `S` is a symmetric matrix with one pair of positions out of reach.
    fn example() -> ([OrganPart; 2], Vec<Vector3<f64>>) {
        let normals = vec![
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(0.6, 0.0, 0.8),
            Vector3::new(0.0, -0.8, 0.6),
            Vector3::new(0.6, 0.0, 0.8),
        ];
        let shell_blends = vec![
            vec![(0, 1.0)],
            vec![(1, 1.0)],
            vec![(0, 0.5), (2, 0.5)],
            vec![(1, 0.3), (2, 0.7)],
        ];
        let master_blends = vec![
            vec![(0, 1.0)],
            vec![(0, 1.0)],
            vec![(1, 1.0)],
            vec![(1, 1.0)],
        ];
        let parts = [
            OrganPart {
                blends: shell_blends,
                blocks: symmetric_blocks(3, 1.0, &[(1, 2)]),
            },
            OrganPart {
                blends: master_blends,
                blocks: symmetric_blocks(2, 0.3, &[]),
            },
        ];
        (parts, normals)
    }

    /// Blocks of a symmetric positive matrix over `positions` (diagonally dominant), with the
    /// pairs of `apart` left out.
    fn symmetric_blocks(
        positions: usize,
        scale: f64,
        apart: &[(usize, usize)],
    ) -> Vec<BTreeMap<usize, Matrix3<f64>>> {
        let n = 3 * positions;
        let value = |r: usize, c: usize| match r == c {
            true => scale * (n as f64),
            false => scale * 0.1 * ((r * c + r + c) % 7) as f64,
        };
        (0..positions)
            .map(|a| {
                (0..positions)
                    .filter(|&b| !apart.contains(&(a, b)) && !apart.contains(&(b, a)))
                    .map(|b| (b, Matrix3::from_fn(|c, d| value(3 * a + c, 3 * b + d))))
                    .collect()
            })
            .collect()
    }

    /// `a_ij = Σ_ab w_ia w_jb n_i · S_ab · n_j` for one organ, straight from the parts.
    fn direct(part: &OrganPart, normals: &[Vector3<f64>], i: usize, j: usize) -> f64 {
        let mut sum = 0.0;
        for &(a, wa) in &part.blends[i] {
            for &(b, wb) in &part.blends[j] {
                if let Some(s) = part.blocks[a].get(&b) {
                    sum += wa * wb * normals[i].dot(&(s * normals[j]));
                }
            }
        }
        sum
    }

    fn dense(parts: &[OrganPart; 2], normals: &[Vector3<f64>]) -> Vec<Vec<f64>> {
        let n = normals.len();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| parts.iter().map(|p| direct(p, normals, i, j)).sum())
                    .collect()
            })
            .collect()
    }

    /// A position loaded along one normal keeps one direction, one loaded along two the
    /// three axes.
    #[test]
    fn a_position_keeps_one_direction_where_its_nodes_share_a_normal() {
        let (parts, normals) = example();
        let counts: Vec<usize> = parts[0].directions(&normals).iter().map(Vec::len).collect();
        assert_eq!(counts, [3, 1, 3]);
    }

    /// The product over a set of nodes is the dense product restricted to the set, whatever
    /// `v` holds outside it, set after set: the directions read change, stay the same while
    /// the set's order changes, change for as many others (nodes 1 and 3 read 7 directions,
    /// nodes 0 and 3 another 7), then shrink.
    #[test]
    fn the_product_over_a_set_is_the_dense_one_restricted_to_it() {
        let (parts, normals) = example();
        let a = dense(&parts, &normals);
        let mut part = LocalCompliance::assemble(&parts, &normals);
        let v = [1.0, 100.0, -2.0, 0.5];
        for set in [
            &[0u32, 1, 3][..],
            &[3, 0, 2],
            &[2, 3, 0],
            &[1, 3],
            &[0, 3],
            &[1],
        ] {
            part.prepare(set);
            let mut out = [0.0; 4];
            part.add_product(set, &v, &mut out);
            for i in 0..4 {
                let expected: f64 = match set.contains(&(i as u32)) {
                    true => set.iter().map(|&j| a[i][j as usize] * v[j as usize]).sum(),
                    false => 0.0,
                };
                assert!(
                    (out[i] - expected).abs() <= 1e-12 * expected.abs(),
                    "set {set:?}, node {i}: {} against {expected}",
                    out[i]
                );
            }
        }
    }

    /// The dimples are `a f`, to within rounding: 1e-12 of the largest dimple any forces up to
    /// `largest_force_n` a node can make (changed tick by tick, a node's dimple keeps the
    /// rounding of forces gone, which an exact zero shows).
    fn assert_dimples(
        part: &LocalCompliance,
        a: &[Vec<f64>],
        force: &[f64],
        largest_force_n: f64,
        tick: usize,
    ) {
        let row_sums = a.iter().map(|row| row.iter().map(|v| v.abs()).sum::<f64>());
        let tolerance = 1e-12 * largest_force_n * row_sums.fold(0.0, f64::max);
        for (i, row) in a.iter().enumerate() {
            let expected: f64 = row.iter().zip(force).map(|(a, f)| a * f).sum();
            assert!(
                (part.gap_m(i) - expected).abs() <= tolerance,
                "tick {tick}, node {i}: {} against {expected}",
                part.gap_m(i)
            );
        }
    }

    /// The dimples of the pushing nodes' forces are the dense product with the forces, a
    /// second tick's forces replace the first's, and each node's own compliance is the
    /// diagonal of its organ's part.
    #[test]
    fn the_dimples_are_the_matrix_times_the_forces_pushing() {
        let (parts, normals) = example();
        let a = dense(&parts, &normals);
        let mut part = LocalCompliance::assemble(&parts, &normals);
        let force = [0.0, 2.0, 0.0, 1.0];
        part.dimple(&[0, 1, 3], &[5.0, 1.0, 0.0, 3.0]);
        part.dimple(&[1, 3, 2], &force);
        assert_dimples(&part, &a, &force, 5.0, 1);
        for i in 0..normals.len() {
            for (o, organ) in parts.iter().enumerate() {
                let own = direct(organ, &normals, i, i);
                assert!(
                    (part.own_m_per_n(i)[o] - own).abs() < 1e-12 * own,
                    "node {i}"
                );
            }
        }
    }

    /// Three blocks of nodes: block `k`'s nodes load position `k` of each organ, and
    /// positions 1 and 2 are out of each other's reach, so that forces in block 1 alone move
    /// no direction block 2 reads.
    fn three_blocks() -> ([OrganPart; 2], Vec<Vector3<f64>>) {
        let (_, four_normals) = example();
        let count = 2 * BLOCK + 4;
        let normals = (0..count).map(|i| four_normals[i % 4]).collect();
        let blends = || (0..count).map(|i| vec![(i / BLOCK, 1.0)]).collect();
        let parts = [
            OrganPart {
                blends: blends(),
                blocks: symmetric_blocks(3, 1.0, &[(1, 2)]),
            },
            OrganPart {
                blends: blends(),
                blocks: symmetric_blocks(3, 0.3, &[(1, 2)]),
            },
        ];
        (parts, normals)
    }

    /// Ticks on, changed by how their forces change: nodes start and stop pushing, some keep
    /// their force, and past the ticks between whole sums the dimples are still the dense
    /// product with the forces of the tick. Each block's reported shift bounds how far every
    /// one of its nodes' dimples changed, also where a whole sum drops every force; a block
    /// whose dimples cannot have changed is not reported; the largest dimple bounds them all.
    #[test]
    fn the_dimples_follow_the_forces_from_tick_to_tick() {
        let (parts, normals) = three_blocks();
        let count = normals.len();
        let a = dense(&parts, &normals);
        let mut part = LocalCompliance::assemble(&parts, &normals);
        let ticks = 2 * TICKS_BETWEEN_WHOLE_SUMS as usize + 3;
        let mut last_gaps = vec![0.0f64; count];
        for tick in 0..ticks {
            // On the ticks that sum whole, nothing pushes: every dimple falls to zero. Two
            // ticks in six, block 1 alone pushes.
            let whole = (tick + 1) % TICKS_BETWEEN_WHOLE_SUMS as usize == 0;
            let block_1_alone = (tick / 2) % 3 == 0;
            let force: Vec<f64> = (0..count)
                .map(|j| match (tick + j) % 5 {
                    _ if whole => 0.0,
                    _ if block_1_alone && j / BLOCK != 1 => 0.0,
                    0 => 0.0,
                    1 => 1.5,
                    _ => ((tick * 7 + j * 3) % 11) as f64 * 0.25,
                })
                .collect();
            let pushing: Vec<u32> = (0..count as u32)
                .filter(|&j| force[j as usize] > 0.0)
                .collect();
            part.dimple(&pushing, &force);
            assert_dimples(&part, &a, &force, 2.5, tick);
            let shifted = part.shifted_blocks();
            if block_1_alone && tick % 2 == 1 && !whole && tick > 1 {
                assert!(!shifted.contains(&2), "tick {tick}: {shifted:?}");
            }
            for (i, last) in last_gaps.iter_mut().enumerate() {
                let (gap, b) = (part.gap_m(i), i / BLOCK);
                let bound = match shifted.contains(&(b as u32)) {
                    true => part.block_shift_m(b) + 1e-12 * (gap.abs() + last.abs()),
                    false => 0.0,
                };
                assert!(
                    (gap - *last).abs() <= bound,
                    "tick {tick}, node {i}: {last} to {gap}, block {b} shifted {bound}"
                );
                assert!(gap.abs() <= part.largest_gap_m(), "tick {tick}, node {i}");
                *last = gap;
            }
        }
    }
}
