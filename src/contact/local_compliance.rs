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
use crate::pgd::Vademecum;

/// Compressed rows, one per pointshell node, symmetric (each pair once per row).
#[derive(Clone, Debug, Default)]
pub struct LocalCompliance {
    offsets: Vec<u32>,
    columns: Vec<u32>,
    /// `a_ij` (m/N), both organs summed: how far a unit normal force on node `j` moves node
    /// `i`'s distance beyond what the modes move it.
    values_m_per_n: Vec<f64>,
    /// Per node, each organ's own `a_ii`: `[shell, master]` (m/N).
    own_m_per_n: Vec<[f64; 2]>,
    /// Per node, the largest `|a_ij|` of its row, and the largest `−a_ij` (a force pulling
    /// the node closer, as a Poisson bulge can): bounds for the cull and the clearance.
    largest_m_per_n: Vec<f64>,
    largest_pull_m_per_n: Vec<f64>,
    /// Scratch: which nodes the product in progress covers.
    member: Vec<bool>,
}

/// One organ's side of a node: the load positions it blends and the normal it is pushed along.
struct Side<'a> {
    blend: &'a [(usize, f64)],
    normal: &'a Vector3<f64>,
}

impl LocalCompliance {
    pub fn new(nodes: &Pointshell, master: &Vademecum, shell: &Vademecum) -> Self {
        let count = nodes.len();
        let master_blends: Vec<[(usize, f64); 1]> = nodes
            .master_positions
            .iter()
            .map(|&m| [(m as usize, 1.0)])
            .collect();
        let shell_side = |i: usize| Side {
            blend: &nodes.blends[i],
            normal: &nodes.rest_normal[i],
        };
        let master_side = |i: usize| Side {
            blend: &master_blends[i],
            normal: &nodes.rest_normal[i],
        };
        let near = Nearness::new(nodes, master, shell);
        let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); count];
        let mut own_m_per_n = vec![[0.0; 2]; count];
        for i in 0..count {
            for j in i..count {
                if !near.can_couple(i, j) {
                    continue;
                }
                let s =
                    |a: usize, b: usize| correction_along(shell, &shell_side(a), &shell_side(b));
                let m =
                    |a: usize, b: usize| correction_along(master, &master_side(a), &master_side(b));
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
            member: vec![false; count],
            ..Self::default()
        };
        for row in rows {
            let largest = row.iter().map(|e| e.1.abs()).fold(0.0, f64::max);
            let pull = row.iter().map(|e| -e.1).fold(0.0, f64::max);
            part.largest_m_per_n.push(largest);
            part.largest_pull_m_per_n.push(pull);
            part.columns.extend(row.iter().map(|e| e.0));
            part.values_m_per_n.extend(row.iter().map(|e| e.1));
            part.offsets.push(part.columns.len() as u32);
        }
        part
    }

    fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let range = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        (&self.columns[range.clone()], &self.values_m_per_n[range])
    }

    /// Node `i`'s own local compliance in the shell organ and in the master (m/N).
    pub fn own_m_per_n(&self, i: usize) -> [f64; 2] {
        self.own_m_per_n[i]
    }

    /// `Σ_j a_ij f_j`: how far the forces `force_n` dimple node `i`'s distance (m) beyond
    /// their modes.
    pub fn gap_m(&self, i: usize, force_n: &[f64]) -> f64 {
        let (columns, values) = self.row(i);
        columns
            .iter()
            .zip(values)
            .map(|(&j, a)| a * force_n[j as usize])
            .sum()
    }

    /// How far (m) forces summing to `total_n` can at most bring node `i` closer.
    pub fn closing_bound_m(&self, i: usize, total_n: f64) -> f64 {
        self.largest_pull_m_per_n[i] * total_n
    }

    /// How far (m) a change of the forces on the nodes of `set` by `change_n` can at most
    /// move any node's distance.
    pub fn change_bound_m(&self, set: &[u32], change_n: &[f64]) -> f64 {
        set.iter()
            .map(|&j| change_n[j as usize].abs() * self.largest_m_per_n[j as usize])
            .sum()
    }

    /// Adds `Σ_j a_ij v_j` over `j` in `set` to `out[i]` for every `i` in `set`.
    pub fn add_product(&mut self, set: &[u32], v: &[f64], out: &mut [f64]) {
        set.iter().for_each(|&j| self.member[j as usize] = true);
        for &i in set {
            let (columns, values) = self.row(i as usize);
            let sum: f64 = columns
                .iter()
                .zip(values)
                .filter(|&(&j, _)| self.member[j as usize])
                .map(|(&j, a)| a * v[j as usize])
                .sum();
            out[i as usize] += sum;
        }
        set.iter().for_each(|&j| self.member[j as usize] = false);
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
