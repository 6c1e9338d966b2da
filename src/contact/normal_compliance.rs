//! The normal compliance `A` of a contact pair: how the nodes' normal forces change their
//! distances to the master, through both organs' modal compliance (the shell node pushed out,
//! the master pushed back). Rows are projected on the rest normals once, so applying it over
//! a set of nodes costs `2 · nodes · (shell modes + master modes)` products: once per tick for
//! the contact's line search, and a power iteration for the loop gain `λ_max(KA)` at set-up.

use super::modal_rows::ModalRows;
use super::pointshell::Pointshell;
use crate::pgd::Vademecum;

#[derive(Clone, Debug, Default)]
pub struct NormalCompliance {
    /// Per node: the shell's displacement and load modes along the normal, then the master's.
    shell_displacement: Vec<f32>,
    shell_load: Vec<f32>,
    master_displacement: Vec<f32>,
    master_load: Vec<f32>,
    shell_modes: usize,
    master_modes: usize,
    shell_c: Vec<f32>,
    master_c: Vec<f32>,
}

impl NormalCompliance {
    pub fn new(nodes: &Pointshell, master: &Vademecum, shell: &Vademecum) -> Self {
        let master_rows = ModalRows::displacements(
            master,
            nodes
                .master_positions
                .iter()
                .map(|&m| master.positions[m as usize] as usize),
        );
        let project = |rows: &ModalRows| -> Vec<f32> {
            (0..nodes.len())
                .flat_map(|i| rows.along(i, nodes.rest_normal[i].map(|c| c as f32)))
                .collect()
        };
        Self {
            shell_displacement: project(&nodes.displacement),
            shell_load: project(&nodes.load),
            master_displacement: project(&master_rows),
            master_load: project(&nodes.master_load),
            shell_modes: shell.total_modes(),
            master_modes: master.total_modes(),
            shell_c: vec![0.0; shell.total_modes()],
            master_c: vec![0.0; master.total_modes()],
        }
    }

    /// `out[i] = (A v)[i]` for every node `i` of `set` (m), from normal forces `v` (N) on
    /// those nodes; other entries of `out` are left alone.
    pub fn apply(&mut self, set: &[u32], v: &[f64], out: &mut [f64]) {
        let (ms, mm) = (self.shell_modes, self.master_modes);
        self.shell_c.fill(0.0);
        self.master_c.fill(0.0);
        for &i in set {
            let (i, f) = (i as usize, v[i as usize] as f32);
            axpy(f, &self.shell_load[i * ms..(i + 1) * ms], &mut self.shell_c);
            axpy(
                -f,
                &self.master_load[i * mm..(i + 1) * mm],
                &mut self.master_c,
            );
        }
        for &i in set {
            let i = i as usize;
            let moved = dot(
                &self.shell_displacement[i * ms..(i + 1) * ms],
                &self.shell_c,
            ) - dot(
                &self.master_displacement[i * mm..(i + 1) * mm],
                &self.master_c,
            );
            out[i] = moved as f64;
        }
    }

    /// `λ_max(KA)` over `set` by power iteration, with penalties `stiffness[i]` (N/m).
    pub fn loop_gain(&mut self, set: &[u32], stiffness: &[f64]) -> f64 {
        let n = stiffness.len();
        let (mut v, mut w) = (vec![0.0; n], vec![0.0; n]);
        set.iter().for_each(|&i| v[i as usize] = 1.0);
        let mut gain = 0.0;
        for _ in 0..POWER_ITERATIONS {
            self.apply(set, &v, &mut w);
            let norm = set
                .iter()
                .map(|&i| (stiffness[i as usize] * w[i as usize]).powi(2))
                .sum::<f64>()
                .sqrt();
            let previous = set
                .iter()
                .map(|&i| v[i as usize].powi(2))
                .sum::<f64>()
                .sqrt();
            if norm == 0.0 {
                return 0.0;
            }
            gain = norm / previous;
            set.iter()
                .for_each(|&i| v[i as usize] = stiffness[i as usize] * w[i as usize] / norm);
        }
        gain
    }
}

const POWER_ITERATIONS: usize = 60;

fn axpy(a: f32, x: &[f32], y: &mut [f32]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}

fn dot(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}
