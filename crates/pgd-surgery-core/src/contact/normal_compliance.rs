//! The normal compliance `A` of a contact pair: how the nodes' normal forces change their
//! distances to the master, through both organs' modal compliance (the shell node pushed out,
//! the master pushed back) and their near-field corrections between nodes close together
//! ([`LocalCompliance`]). Modal rows are projected on the rest normals once, so applying it
//! over a set of nodes costs `4 · nodes · (shell modes + master modes)` products plus a
//! sparse row per node, a few times per tick in the contact's force solve. Its diagonal sets
//! the penalties. Where the tool holds an organ, its modal part of `A` takes the tool's
//! answer as a change of rank 3 ([`super::hold`]).

use std::ops::Range;

use nalgebra::Vector3;

use super::hold::ToolHold;
use super::local_compliance::LocalCompliance;
use super::modal_rows::ModalRows;
use super::pointshell::Pointshell;
use crate::dense_sums::{axpy, dot};
use crate::pgd::Vademecum;

#[derive(Clone, Debug, Default)]
pub struct NormalCompliance {
    shell: OrganRows,
    master: OrganRows,
    local: LocalCompliance,
}

/// One organ's part of `A`, per node along its normal: how far the organ's modes move the
/// node's distance (`displacement`, per unit coefficient) and the coefficients of a unit
/// normal force there (`load`), with the signs that make a push apart positive.
///
/// `A_ij = displacement_i · load_j` is the organ's compliance between the nodes, symmetric
/// by Maxwell–Betti; its separated form is only nearly so, and conjugate gradients need a
/// symmetric `A`, so its symmetric part is applied: `½ (displacement_i · load_j +
/// load_i · displacement_j)`, one more pass over the same rows.
#[derive(Clone, Debug, Default)]
pub(super) struct OrganRows {
    modes: usize,
    displacement: Vec<f32>,
    load: Vec<f32>,
    /// `Σ_j load_j v_j` and `Σ_j displacement_j v_j` for the forces `v` being applied.
    by_load: Vec<f32>,
    by_displacement: Vec<f32>,
    /// Whether the tool holds the organ this tick, and then per node and direction `a`: how
    /// far the tool's answer to a metre's move of its patch along `a` moves the node's
    /// distance (`displacement_i · Y e_a`), and how far a unit force on the node moves the
    /// patch along `a` (`load_i · Bᵀ e_a`, m/N).
    held: bool,
    by_tool: Vec<[f32; 3]>,
    moves_tool: Vec<[f32; 3]>,
    /// `Σ_j moves_tool_j v_j` and `Σ_j by_tool_j v_j` for the forces `v`.
    tool_moved: [f32; 3],
    tool_answers: [f32; 3],
}

impl OrganRows {
    fn new(modes: usize, displacement: Vec<f32>, load: Vec<f32>) -> Self {
        let count = displacement.len() / modes.max(1);
        Self {
            modes,
            displacement,
            load,
            by_load: vec![0.0; modes],
            by_displacement: vec![0.0; modes],
            held: false,
            by_tool: vec![[0.0; 3]; count],
            moves_tool: vec![[0.0; 3]; count],
            tool_moved: [0.0; 3],
            tool_answers: [0.0; 3],
        }
    }

    /// Takes the tool's hold of this tick for the nodes of `set`.
    fn hold(&mut self, set: &[u32], hold: &ToolHold) {
        self.held = hold.is_ready();
        if !self.held {
            return;
        }
        for &i in set {
            let i = i as usize;
            let range = i * self.modes..(i + 1) * self.modes;
            let (displacement, load) = (&self.displacement[range.clone()], &self.load[range]);
            self.by_tool[i] = [0, 1, 2].map(|a| dot(displacement, &hold.coefficients_per_m[a]));
            self.moves_tool[i] = [0, 1, 2].map(|a| dot(load, &hold.moved_per_coefficient_m[a]));
        }
    }

    /// How far the surface under the tool moves (m) when the normal forces on the nodes of
    /// `set` change by `change_n`.
    fn tool_moved_m(&self, set: &[u32], change_n: &[f64]) -> Vector3<f64> {
        if !self.held {
            return Vector3::zeros();
        }
        set.iter()
            .map(|&i| {
                Vector3::from(self.moves_tool[i as usize].map(f64::from)) * change_n[i as usize]
            })
            .sum()
    }

    fn gather(&mut self, set: &[u32], v: &[f64]) {
        self.by_load.fill(0.0);
        self.by_displacement.fill(0.0);
        for &i in set {
            let (i, f) = (i as usize, v[i as usize] as f32);
            let range = i * self.modes..(i + 1) * self.modes;
            axpy(f, &self.load[range.clone()], &mut self.by_load);
            axpy(f, &self.displacement[range], &mut self.by_displacement);
        }
        if self.held {
            let weigh = |per: &[[f32; 3]], a: usize| -> f32 {
                set.iter()
                    .map(|&i| per[i as usize][a] * v[i as usize] as f32)
                    .sum()
            };
            self.tool_moved = [0, 1, 2].map(|a| weigh(&self.moves_tool, a));
            self.tool_answers = [0, 1, 2].map(|a| weigh(&self.by_tool, a));
        }
    }

    fn rows(&self, i: usize) -> (&[f32], &[f32]) {
        let range = i * self.modes..(i + 1) * self.modes;
        (&self.displacement[range.clone()], &self.load[range])
    }

    /// Adds the coefficients of a normal force `force_n` (N) on node `i` to `out` (all load
    /// steps concatenated, `steps` where each lies), each step's share weighed by `weight`.
    /// The row is the one `A` projects on the node's normal: one product a mode, in a run
    /// the compiler vectorizes, where the force's three components took three.
    pub(super) fn add_force(
        &self,
        i: usize,
        force_n: f64,
        steps: &[Range<usize>],
        weight: impl Fn(usize) -> f64,
        out: &mut [f64],
    ) {
        let row = &self.load[i * self.modes..(i + 1) * self.modes];
        for (step, range) in steps.iter().enumerate() {
            let w = weight(step) * force_n;
            if w == 0.0 {
                continue;
            }
            let (out, row) = (&mut out[range.clone()], &row[range.clone()]);
            out.iter_mut()
                .zip(row)
                .for_each(|(o, &l)| *o += w * f64::from(l));
        }
    }

    /// `A_ii` of this organ (m/N): how far a unit force on node `i` moves it.
    fn diagonal(&self, i: usize) -> f64 {
        let (displacement, load) = self.rows(i);
        dot(displacement, load) as f64
    }

    /// `(A v)_i` of this organ: the symmetric part of `D Lᵀ`, less, where the tool holds
    /// it, that of `D Y B Lᵀ`.
    fn answer(&self, i: usize) -> f32 {
        let (displacement, load) = self.rows(i);
        let free = dot(displacement, &self.by_load) + dot(load, &self.by_displacement);
        let held = match self.held {
            true => {
                dot(&self.by_tool[i], &self.tool_moved)
                    + dot(&self.moves_tool[i], &self.tool_answers)
            }
            false => 0.0,
        };
        0.5 * (free - held)
    }
}

impl NormalCompliance {
    pub fn new(nodes: &Pointshell, master: &Vademecum, shell: &Vademecum) -> Self {
        let master_points = || (0..nodes.len()).map(|i| nodes.master_blend(i));
        let master_rows = ModalRows::displacements(master, master_points());
        let project = |rows: &ModalRows| -> Vec<f32> {
            (0..nodes.len())
                .flat_map(|i| rows.along(i, nodes.rest_normal[i].map(|c| c as f32)))
                .collect()
        };
        // The master is pushed against the normal: both its rows change sign, `A` does not.
        let negate = |rows: Vec<f32>| rows.into_iter().map(|v| -v).collect();
        Self {
            shell: OrganRows::new(
                shell.total_modes(),
                project(&nodes.displacement),
                project(&ModalRows::loads(shell, nodes.blends.iter())),
            ),
            master: OrganRows::new(
                master.total_modes(),
                negate(project(&master_rows)),
                negate(project(&ModalRows::loads(master, master_points()))),
            ),
            local: LocalCompliance::new(nodes, master, shell),
        }
    }

    /// The shell organ's rows: the coefficients a node's push takes.
    pub(super) fn shell_rows(&self) -> &OrganRows {
        &self.shell
    }

    /// The master's rows: the coefficients a node's reaction takes (its `load` rows carry the
    /// reaction's sign).
    pub(super) fn master_rows(&self) -> &OrganRows {
        &self.master
    }

    /// The near-field part of `A`.
    pub fn local(&self) -> &LocalCompliance {
        &self.local
    }

    pub fn local_mut(&mut self) -> &mut LocalCompliance {
        &mut self.local
    }

    /// Node `i`'s own compliance in the stiffer of the two organs (m/N), 0 where neither
    /// moves it (both clamped there).
    pub fn stiffer_diagonal(&self, i: usize) -> f64 {
        let [shell_local, master_local] = self.local.own_m_per_n(i);
        let own = [
            self.shell.diagonal(i) + shell_local,
            self.master.diagonal(i) + master_local,
        ];
        own.into_iter()
            .filter(|&a| a > 0.0)
            .reduce(f64::min)
            .unwrap_or(0.0)
    }

    /// Takes the tool's hold of each organ for this tick's nodes `set`.
    pub fn hold(&mut self, set: &[u32], master: &ToolHold, shell: &ToolHold) {
        self.master.hold(set, master);
        self.shell.hold(set, shell);
    }

    /// How far the surface under the tool moves on the master and on the shell organ (m)
    /// when the normal forces on the nodes of `set` change by `change_n`.
    pub fn tool_moves_m(&self, set: &[u32], change_n: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        (
            self.master.tool_moved_m(set, change_n),
            self.shell.tool_moved_m(set, change_n),
        )
    }

    /// `out[i] = (A v)[i]` for every node `i` of `set` (m), from normal forces `v` (N) on
    /// those nodes; other entries of `out` are left alone.
    pub fn apply(&mut self, set: &[u32], v: &[f64], out: &mut [f64]) {
        self.shell.gather(set, v);
        self.master.gather(set, v);
        for &i in set {
            let i = i as usize;
            out[i] = (self.shell.answer(i) + self.master.answer(i)) as f64;
        }
        self.local.add_product(set, v, out);
    }
}
