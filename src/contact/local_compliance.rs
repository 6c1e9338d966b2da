//! The part of a contact pair's normal compliance `A` that the modes cannot carry: how a
//! contact force dimples both organs near where it pushes.
//!
//! A few smooth modes are far too stiff under a point load (issue 4's table: rank 50, felt
//! force 2,000 % off), so with modes alone a few pushing nodes moved the liver clear of a
//! whole intrusion, and the contact felt stiffer than the tissue. Every load position of a
//! vademecum stores its near-field correction (its exact response minus the modes, at every
//! node within the local radius), so the exact compliance between two nodes close enough is
//! the modal one plus `n_i · R_j(node i) · n_j`. This sparse matrix holds that second term
//! for both organs (the shell organ at the nodes' load positions, the master at the positions
//! that take the reactions), fixed once the pair is set up:
//! - `A` takes it in the force solve, so the solve sees the tissue as soft as it is;
//! - each measured distance takes it times the forces already pushing, because the modal
//!   coefficients the distance is read with carry only the modal part of their effect.
//!
//! The linear load step's corrections are used (contact forces are spread over many nodes,
//! each well inside the first step), and each pair's own forces only: a reaction another pair
//! puts on the master dimples it for that pair alone.

use nalgebra::Vector3;

use super::pointshell::Pointshell;
use crate::kernels::dot;
use crate::pgd::Vademecum;

/// Compressed rows, one per pointshell node, symmetric (each pair once per row), and what
/// each tick derives from them for the nodes it works on.
#[derive(Clone, Debug, Default)]
pub struct LocalCompliance {
    offsets: Vec<u32>,
    columns: Vec<u32>,
    /// `a_ij` (m/N), both organs summed: how far a unit normal force on node `j` moves node
    /// `i`'s distance beyond what the modes move it.
    values_m_per_n: Vec<f64>,
    /// Per node, each organ's own `a_ii`: `[shell, master]` (m/N).
    own_m_per_n: Vec<[f64; 2]>,
    /// Per node, `Σ_j a_ij f_j` for the forces pushing at the start of the tick (m), and
    /// the nodes where it is not zero.
    gap_m: Vec<f64>,
    gapped: Vec<u32>,
    /// The block of `a` between the nodes of this tick's force solve, dense (row-major, in
    /// the order of the set), and each node's place in the set.
    block_m_per_n: Vec<f64>,
    slot: Vec<u32>,
    /// Scratch: the vector being multiplied, gathered in the set's order.
    gathered: Vec<f64>,
}

const NO_SLOT: u32 = u32::MAX;

/// One organ's side of a node: the load positions it blends and the normal it is pushed along.
struct Side<'a> {
    blend: &'a [(usize, f64)],
    normal: &'a Vector3<f64>,
}

impl LocalCompliance {
    /// Both organs' corrections between the nodes of `nodes`, once per pair at setup:
    /// O(nodes²) distance checks and a few binary searches per pair close enough.
    pub fn new(nodes: &Pointshell, master: &Vademecum, shell: &Vademecum) -> Self {
        let count = nodes.len();
        let master_blends: Vec<[(usize, f64); 1]> =
            (0..count).map(|i| nodes.master_blend(i)).collect();
        let shell_side = |i: usize| Side {
            blend: &nodes.blends[i],
            normal: &nodes.rest_normal[i],
        };
        let master_side = |i: usize| Side {
            blend: &master_blends[i],
            normal: &nodes.rest_normal[i],
        };
        let s = |a: usize, b: usize| correction_along(shell, &shell_side(a), &shell_side(b));
        let m = |a: usize, b: usize| correction_along(master, &master_side(a), &master_side(b));
        let near = Nearness::new(nodes, master, shell);
        let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); count];
        let mut own_m_per_n = vec![[0.0; 2]; count];
        for i in 0..count {
            for j in i..count {
                if !near.can_couple(i, j) {
                    continue;
                }
                if i == j {
                    own_m_per_n[i] = [s(i, i), m(i, i)];
                }
                let value = 0.5 * (s(i, j) + s(j, i) + m(i, j) + m(j, i));
                if value != 0.0 {
                    rows[i].push((j as u32, value));
                    if j != i {
                        rows[j].push((i as u32, value));
                    }
                }
            }
        }
        Self::from_rows(rows, own_m_per_n)
    }

    fn from_rows(rows: Vec<Vec<(u32, f64)>>, own_m_per_n: Vec<[f64; 2]>) -> Self {
        let count = rows.len();
        let mut part = Self {
            offsets: vec![0],
            own_m_per_n,
            gap_m: vec![0.0; count],
            slot: vec![NO_SLOT; count],
            ..Self::default()
        };
        for row in rows {
            part.columns.extend(row.iter().map(|e| e.0));
            part.values_m_per_n.extend(row.iter().map(|e| e.1));
            part.offsets.push(part.columns.len() as u32);
        }
        part
    }

    /// Where row `i`'s entries lie in `columns` and `values_m_per_n`.
    fn row_range(&self, i: u32) -> std::ops::Range<usize> {
        self.offsets[i as usize] as usize..self.offsets[i as usize + 1] as usize
    }

    /// Node `i`'s own local compliance in the shell organ and in the master (m/N).
    pub fn own_m_per_n(&self, i: usize) -> [f64; 2] {
        self.own_m_per_n[i]
    }

    /// Takes the forces pushing at the start of the tick (`force_n` on the nodes of
    /// `pushing`): spread along their rows (the matrix is symmetric), at a cost of the pushing
    /// nodes' rows rather than every measured node's.
    pub fn dimple(&mut self, pushing: &[u32], force_n: &[f64]) {
        for &i in &self.gapped {
            self.gap_m[i as usize] = 0.0;
        }
        self.gapped.clear();
        for &j in pushing {
            let f = force_n[j as usize];
            if f == 0.0 {
                continue;
            }
            let range = self.row_range(j);
            for (&i, a) in self.columns[range.clone()]
                .iter()
                .zip(&self.values_m_per_n[range])
            {
                if self.gap_m[i as usize] == 0.0 {
                    self.gapped.push(i);
                }
                self.gap_m[i as usize] += a * f;
            }
        }
    }

    /// `Σ_j a_ij f_j`: how far the forces taken by [`Self::dimple`] move node `i`'s distance
    /// (m) beyond their modes.
    pub fn gap_m(&self, i: usize) -> f64 {
        self.gap_m[i]
    }

    /// Sets up the block of the tick's force solve over the nodes of `set`: one pass over
    /// their rows, so that each product costs `set²` rather than their rows' length.
    pub fn prepare(&mut self, set: &[u32]) {
        for (k, &i) in set.iter().enumerate() {
            self.slot[i as usize] = k as u32;
        }
        let n = set.len();
        self.block_m_per_n.clear();
        self.block_m_per_n.resize(n * n, 0.0);
        for (r, &i) in set.iter().enumerate() {
            let range = self.row_range(i);
            for (&j, &a) in self.columns[range.clone()]
                .iter()
                .zip(&self.values_m_per_n[range])
            {
                if let Some(c) = self.slot_of(j) {
                    self.block_m_per_n[r * n + c] = a;
                }
            }
        }
        for &i in set {
            self.slot[i as usize] = NO_SLOT;
        }
    }

    fn slot_of(&self, j: u32) -> Option<usize> {
        match self.slot[j as usize] {
            NO_SLOT => None,
            c => Some(c as usize),
        }
    }

    /// Adds `Σ_j a_ij v_j` over `j` in `set` to `out[i]` for every `i` in `set`, the set
    /// [`Self::prepare`] took.
    pub fn add_product(&mut self, set: &[u32], v: &[f64], out: &mut [f64]) {
        let n = set.len();
        debug_assert_eq!(self.block_m_per_n.len(), n * n, "prepared for another set");
        self.gathered.clear();
        self.gathered.extend(set.iter().map(|&j| v[j as usize]));
        // An empty set has an empty block: no rows, and no chunk of size zero.
        for (&i, row) in set.iter().zip(self.block_m_per_n.chunks_exact(n.max(1))) {
            out[i as usize] += dot(row, &self.gathered);
        }
    }
}

/// `Σ_ab w_a w_b n_i · R_b(node a) · n_j`: how far a unit force along `j`'s normal, shared
/// among `j`'s positions, moves `i`'s positions along `i`'s normal through the linear step's
/// near-field corrections (m/N); 0 where `i` lies outside every one of them.
fn correction_along(vademecum: &Vademecum, i: &Side, j: &Side) -> f64 {
    let local = &vademecum.steps[0].local;
    let mut sum = 0.0;
    for &(b, wb) in j.blend {
        let range = local.corrections_of(b);
        let nodes = &local.correction_nodes[range.clone()];
        for &(a, wa) in i.blend {
            let node = vademecum.positions[a];
            if let Ok(k) = nodes.binary_search(&node) {
                let u = local.residual(range.start + k, j.normal);
                sum += wa * wb * i.normal.dot(&u);
            }
        }
    }
    sum
}

/// Which node pairs can share a near field at all: their positions lie within the local
/// radius of each other in the shell organ or in the master.
struct Nearness<'a> {
    nodes: &'a Pointshell,
    master: &'a Vademecum,
    shell_reach_m: f64,
    master_reach_m: f64,
}

impl<'a> Nearness<'a> {
    fn new(nodes: &'a Pointshell, master: &'a Vademecum, shell: &Vademecum) -> Self {
        // A node's blended positions lie within `spread` of it.
        let spread_m = (0..nodes.len())
            .flat_map(|i| {
                nodes.blends[i].iter().map(move |&(a, _)| {
                    let p = Vector3::from(shell.position_coords_m[a].map(f64::from));
                    (p - nodes.rest_m[i].map(f64::from)).norm()
                })
            })
            .fold(0.0, f64::max);
        Self {
            nodes,
            master,
            shell_reach_m: shell.header.settings.local_radius_m + 2.0 * spread_m,
            master_reach_m: master.header.settings.local_radius_m,
        }
    }

    fn can_couple(&self, i: usize, j: usize) -> bool {
        let rest = |k: usize| self.nodes.rest_m[k].map(f64::from);
        let master_at =
            |k: usize| self.master.position_coords_m[self.nodes.master_positions[k] as usize];
        let master_apart = (0..3)
            .map(|c| (master_at(i)[c] - master_at(j)[c]).powi(2) as f64)
            .sum::<f64>()
            .sqrt();
        (rest(i) - rest(j)).norm() <= self.shell_reach_m || master_apart <= self.master_reach_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric sparse matrix over five nodes (node 4 couples with none), as rows, and
    /// the same matrix dense.
    fn example() -> (LocalCompliance, [[f64; 5]; 5]) {
        let pairs = [
            (0, 0, 0.5),
            (0, 1, 0.2),
            (1, 1, 0.4),
            (1, 3, -0.05),
            (2, 2, 0.3),
            (3, 3, 0.6),
        ];
        let mut dense = [[0.0; 5]; 5];
        let mut rows = vec![Vec::new(); 5];
        for (i, j, a) in pairs {
            dense[i][j] = a;
            dense[j][i] = a;
            rows[i].push((j as u32, a));
            if i != j {
                rows[j].push((i as u32, a));
            }
        }
        (LocalCompliance::from_rows(rows, vec![[0.0; 2]; 5]), dense)
    }

    /// The product over a set of nodes, through the block `prepare` builds, is the dense
    /// product restricted to the set, whatever `v` holds outside it.
    #[test]
    fn the_product_over_a_set_is_the_dense_one_restricted_to_it() {
        let (mut part, dense) = example();
        let set = [3u32, 0, 1];
        let v = [1.0, -2.0, 100.0, 0.5, 7.0];
        part.prepare(&set);
        let mut out = [0.0; 5];
        part.add_product(&set, &v, &mut out);
        for &i in &set {
            let i = i as usize;
            let expected: f64 = set
                .iter()
                .map(|&j| dense[i][j as usize] * v[j as usize])
                .sum();
            assert!(
                (out[i] - expected).abs() < 1e-15,
                "node {i}: {} against {expected}",
                out[i]
            );
        }
        assert_eq!(
            (out[2], out[4]),
            (0.0, 0.0),
            "nodes outside the set are left alone"
        );
    }

    /// The dimples of the pushing nodes' forces are the dense product with the forces, and
    /// a second tick's forces replace the first's.
    #[test]
    fn the_dimples_are_the_matrix_times_the_forces_pushing() {
        let (mut part, dense) = example();
        let force = [0.0, 2.0, 0.0, 1.0, 0.0];
        part.dimple(&[0, 1, 3], &[0.0, 5.0, 0.0, 3.0, 0.0]);
        part.dimple(&[1, 3], &force);
        for (i, row) in dense.iter().enumerate() {
            let expected: f64 = row.iter().zip(&force).map(|(a, f)| a * f).sum();
            assert!((part.gap_m(i) - expected).abs() < 1e-15, "node {i}");
        }
    }
}
