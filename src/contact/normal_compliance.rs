//! The normal compliance `A` of a contact pair: how the nodes' normal forces change their
//! distances to the master, through both organs' modal compliance (the shell node pushed out,
//! the master pushed back). Rows are projected on the rest normals once, so applying it over
//! a set of nodes costs `4 · nodes · (shell modes + master modes)` products: a few times per
//! tick in the contact's force solve, and a power iteration for the loop gain `λ_max(KA)` at
//! set-up.

use super::modal_rows::ModalRows;
use super::pointshell::Pointshell;
use crate::pgd::Vademecum;

#[derive(Clone, Debug, Default)]
pub struct NormalCompliance {
    shell: OrganRows,
    master: OrganRows,
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
struct OrganRows {
    modes: usize,
    displacement: Vec<f32>,
    load: Vec<f32>,
    /// `Σ_j load_j v_j` and `Σ_j displacement_j v_j` for the forces `v` being applied.
    by_load: Vec<f32>,
    by_displacement: Vec<f32>,
}

impl OrganRows {
    fn new(modes: usize, displacement: Vec<f32>, load: Vec<f32>) -> Self {
        Self {
            modes,
            displacement,
            load,
            by_load: vec![0.0; modes],
            by_displacement: vec![0.0; modes],
        }
    }

    fn rows(&self, i: usize) -> (&[f32], &[f32]) {
        let range = i * self.modes..(i + 1) * self.modes;
        (&self.displacement[range.clone()], &self.load[range])
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
    }

    fn answer(&self, i: usize) -> f32 {
        let (displacement, load) = self.rows(i);
        0.5 * (dot(displacement, &self.by_load) + dot(load, &self.by_displacement))
    }
}

impl NormalCompliance {
    pub fn new(nodes: &Pointshell, master: &Vademecum, shell: &Vademecum) -> Self {
        let master_points = nodes.master_positions.iter().map(|&m| [(m as usize, 1.0)]);
        let master_rows = ModalRows::displacements(master, master_points);
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
                project(&nodes.load),
            ),
            master: OrganRows::new(
                master.total_modes(),
                negate(project(&master_rows)),
                negate(project(&nodes.master_load)),
            ),
        }
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
