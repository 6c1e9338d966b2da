//! The reference for the peel tests: an elastic strip in its plane (x along it, z up), nodes
//! a tie spacing apart, each bonded to a rigid base through a cohesive tie of its share of
//! the strip's area. Segments stretch (`EA`), nodes bend (`EI`, on the second difference),
//! and the first node is pulled along a direction `d` by a prescribed amount, free across it:
//! the hand's force is along `d`. Quasi-static: each pull step is solved by Newton's method
//! with the ties' damaged secants in the tangent; within a step a tie's damage is what the
//! iterate would give it, and it is committed only once the step has converged, so that an
//! overshooting iterate damages nothing.

use nalgebra::{Matrix2, Vector2, Vector3};
use pgd_surgery_core::dissection::{CohesiveLaw, CohesiveTie};
use pgd_surgery_core::rods::Banded;

/// The strip and its bond.
#[derive(Clone, Copy, Debug)]
pub struct StripSpec {
    pub length_m: f64,
    pub width_m: f64,
    pub thickness_m: f64,
    pub young_pa: f64,
    pub spacing_m: f64,
    pub law: CohesiveLaw,
}

impl StripSpec {
    fn axial_n(&self) -> f64 {
        self.young_pa * self.width_m * self.thickness_m
    }

    fn bending_n_m2(&self) -> f64 {
        self.young_pa * self.width_m * self.thickness_m.powi(3) / 12.0
    }

    /// The steady peel force (N) at `angle_rad` by the energy balance of an extensible strip
    /// (Kendall 1975): `(F/b)(1 − cos θ) + (F/b)² / (2 E h) = G`.
    pub fn kendall_force_n(&self, angle_rad: f64) -> f64 {
        let stretch = 1.0 / (2.0 * self.young_pa * self.thickness_m);
        let lever = 1.0 - angle_rad.cos();
        let g = self.law.fracture_energy_j_per_m2;
        let per_width = (-lever + (lever * lever + 4.0 * stretch * g).sqrt()) / (2.0 * stretch);
        per_width * self.width_m
    }
}

/// A peel in progress.
pub struct Peel {
    spec: StripSpec,
    rest: Vec<Vector2<f64>>,
    ties: Vec<CohesiveTie>,
    areas_m2: Vec<f64>,
    /// The pull's direction and the free one across it.
    along: Vector2<f64>,
    across: Vector2<f64>,
    /// Unknowns: the first node's move across the pull, then every other node's position.
    x: Vec<f64>,
    pull_m: f64,
}

/// The half bandwidth of the tangent: bending couples a node with the next two.
const BAND: usize = 6;

/// What one pull step left: the pull (m), the hand's force along it (N).
#[derive(Clone, Copy, Debug)]
pub struct PeelPoint {
    pub pull_m: f64,
    pub force_n: f64,
}

impl Peel {
    /// The strip bonded along its whole length, to be pulled at `angle_rad` from the base on
    /// the peeled side (the pull's direction `(−cos θ, sin θ)`).
    pub fn new(spec: StripSpec, angle_rad: f64) -> Self {
        let n = (spec.length_m / spec.spacing_m).round() as usize + 1;
        let rest: Vec<Vector2<f64>> = (0..n)
            .map(|i| Vector2::new(i as f64 * spec.spacing_m, 0.0))
            .collect();
        let areas_m2 = (0..n)
            .map(|i| {
                let share = if i == 0 || i == n - 1 { 0.5 } else { 1.0 };
                share * spec.spacing_m * spec.width_m
            })
            .collect();
        let along = Vector2::new(-angle_rad.cos(), angle_rad.sin());
        let mut x = vec![0.0; 1 + 2 * (n - 1)];
        for (i, p) in rest.iter().enumerate().skip(1) {
            x[2 * i - 1] = p.x;
            x[2 * i] = p.y;
        }
        Self {
            spec,
            rest,
            ties: vec![CohesiveTie::default(); n],
            areas_m2,
            along,
            across: Vector2::new(-along.y, along.x),
            x,
            pull_m: 0.0,
        }
    }

    fn nodes(&self) -> usize {
        self.rest.len()
    }

    fn position(&self, i: usize) -> Vector2<f64> {
        match i {
            0 => self.rest[0] + self.along * self.pull_m + self.across * self.x[0],
            _ => Vector2::new(self.x[2 * i - 1], self.x[2 * i]),
        }
    }

    /// Node `i`'s unknowns and how its position moves with each.
    fn dofs(&self, i: usize) -> ([(usize, Vector2<f64>); 2], usize) {
        match i {
            0 => ([(0, self.across), (0, Vector2::zeros())], 1),
            _ => ([(2 * i - 1, Vector2::x()), (2 * i, Vector2::y())], 2),
        }
    }

    /// Pulls `by_m` further, in one step; the hand's force after it.
    pub fn pull(&mut self, by_m: f64) -> PeelPoint {
        self.pull_m += by_m;
        // A billionth of the strip's axial stiffness: far below the peel force, above the
        // round-off of the finest strips' sums.
        let tolerance_n = 1e-9 * self.spec.axial_n();
        let mut converged = false;
        let mut norms = Vec::new();
        for _ in 0..400 {
            let (gradient, mut tangent) = self.gradient_and_tangent();
            let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
            norms.push(norm);
            if norm < tolerance_n {
                converged = true;
                break;
            }
            let mut step: Vec<f64> = gradient.iter().map(|g| -g).collect();
            tangent
                .solve(&mut step)
                .expect("the strip's tangent is positive definite");
            self.x.iter_mut().zip(&step).for_each(|(x, s)| *x += s);
        }
        assert!(
            converged,
            "pull {:.3} mm did not converge: {:?}",
            self.pull_m * 1e3,
            &norms[norms.len() - 8..]
        );
        for i in 0..self.nodes() {
            let separation = self.separation(i);
            self.ties[i].traction(&self.spec.law, &separation, &Vector3::z_axis());
        }
        PeelPoint {
            pull_m: self.pull_m,
            force_n: self.node_force(0).dot(&self.along),
        }
    }

    fn separation(&self, i: usize) -> Vector3<f64> {
        let d = self.position(i) - self.rest[i];
        Vector3::new(d.x, 0.0, d.y)
    }

    /// The strip's elastic energy (J): stretching and bending.
    pub fn strip_energy_j(&self) -> f64 {
        let (k, kb) = (self.axial_k(), self.bending_k());
        let stretch: f64 = (0..self.nodes() - 1)
            .map(|i| {
                let l = (self.position(i + 1) - self.position(i)).norm();
                0.5 * k * (l - self.spec.spacing_m).powi(2)
            })
            .sum();
        let bend: f64 = (1..self.nodes() - 1)
            .map(|i| 0.5 * kb * self.second_difference(i).norm_squared())
            .sum();
        stretch + bend
    }

    /// What the ties hold (J): the energy each would give back unloading along its secant.
    pub fn ties_recoverable_j(&self) -> f64 {
        (0..self.nodes())
            .map(|i| {
                let law = &self.spec.law;
                let kept = law.stiffness_pa_per_m * (1.0 - self.ties[i].damage(law));
                let d = self.separation(i);
                let opening2 = d.x * d.x + d.z.max(0.0).powi(2);
                let closing2 = d.z.min(0.0).powi(2);
                0.5 * self.areas_m2[i] * (kept * opening2 + law.stiffness_pa_per_m * closing2)
            })
            .sum()
    }

    /// What the ties dissipated (J): for each, the work of the law up to the largest
    /// separation it reached less what it would give back from there, `G_c` a unit area of
    /// a failed tie.
    pub fn ties_dissipated_j(&self) -> f64 {
        let law = &self.spec.law;
        let (peak, failure) = (law.peak_separation_m(), law.failure_separation_m());
        let t = law.peak_traction_pa;
        (0..self.nodes())
            .map(|i| {
                let reached = self.ties[i].reached_m.min(failure);
                if reached <= peak {
                    return 0.0;
                }
                let softening = t * (failure - reached) / (failure - peak);
                let done = 0.5 * t * peak + 0.5 * (t + softening) * (reached - peak);
                let given_back = 0.5 * softening * reached;
                self.areas_m2[i] * (done - given_back)
            })
            .sum()
    }

    /// The bonded area released so far (m²): the failed ties'.
    pub fn released_m2(&self) -> f64 {
        (0..self.nodes())
            .filter(|&i| self.ties[i].failed(&self.spec.law))
            .map(|i| self.areas_m2[i])
            .sum()
    }

    fn axial_k(&self) -> f64 {
        self.spec.axial_n() / self.spec.spacing_m
    }

    fn bending_k(&self) -> f64 {
        self.spec.bending_n_m2() / self.spec.spacing_m.powi(3)
    }

    fn second_difference(&self, i: usize) -> Vector2<f64> {
        self.position(i - 1) - 2.0 * self.position(i) + self.position(i + 1)
    }

    /// The internal force on node `i` (N): the strip's and its tie's, what holds it back.
    fn node_force(&self, i: usize) -> Vector2<f64> {
        let mut forces = vec![Vector2::zeros(); self.nodes()];
        self.add_node_gradients(&mut forces, None);
        forces[i]
    }

    /// Adds each node's energy gradient (N) to `forces`, and, given one, the tangent's
    /// node blocks to `blocks` (called with each pair of nodes and its 2 × 2 block).
    fn add_node_gradients(
        &self,
        forces: &mut [Vector2<f64>],
        mut blocks: Option<&mut dyn FnMut(usize, usize, Matrix2<f64>)>,
    ) {
        let (k, kb, n) = (self.axial_k(), self.bending_k(), self.nodes());
        for i in 0..n - 1 {
            let q = self.position(i + 1) - self.position(i);
            let l = q.norm();
            let u = q / l;
            let f = u * (k * (l - self.spec.spacing_m));
            forces[i + 1] += f;
            forces[i] -= f;
            if let Some(add) = blocks.as_mut() {
                let transverse = (1.0 - self.spec.spacing_m / l).max(0.0);
                let uu = u * u.transpose();
                let block = (uu + (Matrix2::identity() - uu) * transverse) * k;
                for (a, b, s) in [
                    (i, i, 1.0),
                    (i + 1, i + 1, 1.0),
                    (i, i + 1, -1.0),
                    (i + 1, i, -1.0),
                ] {
                    add(a, b, block * s);
                }
            }
        }
        for i in 1..n - 1 {
            let c = self.second_difference(i) * kb;
            let weights = [(i - 1, 1.0), (i, -2.0), (i + 1, 1.0)];
            for &(node, w) in &weights {
                forces[node] += c * w;
            }
            if let Some(add) = blocks.as_mut() {
                for &(a, wa) in &weights {
                    for &(b, wb) in &weights {
                        add(a, b, Matrix2::identity() * (kb * wa * wb));
                    }
                }
            }
        }
        let law = &self.spec.law;
        for (i, force) in forces.iter_mut().enumerate() {
            let mut trial = self.ties[i];
            let separation = self.separation(i);
            let traction = trial.traction(law, &separation, &Vector3::z_axis());
            *force -= Vector2::new(traction.x, traction.z) * self.areas_m2[i];
            if let Some(add) = blocks.as_mut() {
                let kept = law.stiffness_pa_per_m * (1.0 - trial.damage(law));
                add(
                    i,
                    i,
                    Matrix2::identity() * (kept.max(0.0) * self.areas_m2[i]),
                );
            }
        }
    }

    fn gradient_and_tangent(&self) -> (Vec<f64>, Banded) {
        let unknowns = self.x.len();
        let mut tangent = Banded::zeros(unknowns, BAND);
        let mut forces = vec![Vector2::zeros(); self.nodes()];
        {
            let mut add = |a: usize, b: usize, block: Matrix2<f64>| {
                let (da, na) = self.dofs(a);
                let (db, nb) = self.dofs(b);
                for &(ra, ja) in &da[..na] {
                    for &(rb, jb) in &db[..nb] {
                        tangent.add(ra, rb, ja.dot(&(block * jb)));
                    }
                }
            };
            self.add_node_gradients(&mut forces, Some(&mut add));
        }
        let mut gradient = vec![0.0; unknowns];
        for (i, f) in forces.iter().enumerate() {
            let (dofs, count) = self.dofs(i);
            for &(row, j) in &dofs[..count] {
                gradient[row] += j.dot(f);
            }
        }
        (gradient, tangent)
    }
}
