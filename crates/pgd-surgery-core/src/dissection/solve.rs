//! The bed's tie forces of one tick, answered with the organs' own give. A tie is far stiffer
//! than the floppy organ it holds, so a force fed back a tick late overshoots and grows from
//! tick to tick; solved within the tick instead, the forces `f` of the live ties satisfy
//! `f = −K (δ + C f)`: `K` their secant stiffnesses times their areas (at the damage each had
//! when the tick began), `δ` the separation the organs' other loads make at the ties, and `C`
//! the separation the ties' own forces add, both organs' compliance between the ties. That is
//! the minimum of the convex energy `½ fᵀ C f + Σ |f|²/2k + δᵀ f`, found by conjugate
//! gradients preconditioned by `K` (as organ contact's forces are, without their sign
//! constraint: a tie pulls and pushes), warm started from the last tick's forces.

use nalgebra::Vector3;

use super::bed::Bed;

/// How the ties' forces separate the two organs at the ties: `C f` (m) for the forces `f`
/// (N), one per tie, in the bed's order; symmetric and positive semi-definite.
pub trait TieCompliance {
    fn separation(&mut self, forces_n: &[Vector3<f64>], out_m: &mut [Vector3<f64>]);
}

/// When to stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TieConvergence {
    /// Most products with `C` a tick.
    pub max_products: usize,
    /// Stop once `Σ k |g|²` is below this fraction of `Σ |f|²/k` (both J).
    pub relative: f64,
}

impl Default for TieConvergence {
    fn default() -> Self {
        Self {
            max_products: 24,
            relative: 1e-10,
        }
    }
}

/// Work vectors, one entry per tie, kept from tick to tick.
#[derive(Clone, Debug, Default)]
pub struct TieSolve {
    stiffness_n_per_m: Vec<f64>,
    residual_m: Vec<Vector3<f64>>,
    direction_n: Vec<Vector3<f64>>,
    product_m: Vec<Vector3<f64>>,
}

impl TieSolve {
    /// The forces `forces_n` (the last tick's on entry) that balance the ties against the
    /// organs' give, given the separation `by_others_m` the other loads make at each tie; a
    /// failed tie carries none, nor one `carried` by something else (a tie beyond the slice's
    /// end is not). Then each tie's damage grows with the separation it ends at. Returns the
    /// products with `C` taken.
    pub fn solve(
        &mut self,
        bed: &mut Bed,
        carried: &[bool],
        by_others_m: &[Vector3<f64>],
        compliance: &mut impl TieCompliance,
        forces_n: &mut [Vector3<f64>],
        convergence: TieConvergence,
    ) -> usize {
        let n = bed.ties.len();
        self.prepare(bed, carried, n);
        let k = &self.stiffness_n_per_m;
        for (f, &k) in forces_n.iter_mut().zip(k) {
            if k == 0.0 {
                *f = Vector3::zeros();
            }
        }
        // r = −δ − (C + K⁻¹) f, the energy's negative gradient.
        let mut products = self.apply(compliance, forces_n, by_others_m);
        let k = &self.stiffness_n_per_m;
        let z = |r: &[Vector3<f64>], out: &mut [Vector3<f64>]| {
            out.iter_mut()
                .zip(r)
                .zip(k)
                .for_each(|((o, r), &k)| *o = r * k);
        };
        z(&self.residual_m, &mut self.direction_n);
        let mut rz = dot_weighted(&self.residual_m, k);
        while products < convergence.max_products {
            let energy: f64 = (forces_n.iter().zip(k))
                .filter(|(_, k)| **k > 0.0)
                .map(|(f, k)| f.norm_squared() / k)
                .sum();
            if rz <= convergence.relative * energy.max(f64::MIN_POSITIVE) || rz == 0.0 {
                break;
            }
            compliance.separation(&self.direction_n, &mut self.product_m);
            products += 1;
            for ((q, p), &k) in self.product_m.iter_mut().zip(&self.direction_n).zip(k) {
                *q = if k > 0.0 {
                    *q + p / k
                } else {
                    Vector3::zeros()
                };
            }
            let pq: f64 = (self.direction_n.iter().zip(&self.product_m))
                .map(|(p, q)| p.dot(q))
                .sum();
            if pq <= 0.0 {
                break;
            }
            let alpha = rz / pq;
            for ((f, r), (p, q)) in forces_n
                .iter_mut()
                .zip(self.residual_m.iter_mut())
                .zip(self.direction_n.iter().zip(&self.product_m))
            {
                *f += p * alpha;
                *r -= q * alpha;
            }
            let next = dot_weighted(&self.residual_m, k);
            let beta = next / rz;
            rz = next;
            for ((p, r), &k) in self.direction_n.iter_mut().zip(&self.residual_m).zip(k) {
                *p = r * k + *p * beta;
            }
        }
        self.commit(bed, compliance, forces_n, by_others_m);
        products + 1
    }

    /// Each tie's secant stiffness times its area (N/m), zero for a failed or carried one,
    /// and room.
    fn prepare(&mut self, bed: &Bed, carried: &[bool], n: usize) {
        self.stiffness_n_per_m.clear();
        let law = &bed.law;
        self.stiffness_n_per_m
            .extend(bed.ties.iter().enumerate().map(|(i, t)| {
                match carried.get(i).copied().unwrap_or(false) {
                    true => 0.0,
                    false => t.state.secant_pa_per_m(law) * t.area_m2,
                }
            }));
        for v in [
            &mut self.residual_m,
            &mut self.direction_n,
            &mut self.product_m,
        ] {
            v.clear();
            v.resize(n, Vector3::zeros());
        }
    }

    /// `residual = −δ − (C + K⁻¹) f` (zero at failed ties); one product with `C`.
    fn apply(
        &mut self,
        compliance: &mut impl TieCompliance,
        forces_n: &[Vector3<f64>],
        by_others_m: &[Vector3<f64>],
    ) -> usize {
        compliance.separation(forces_n, &mut self.residual_m);
        let k = &self.stiffness_n_per_m;
        for (((r, f), d), &k) in (self.residual_m.iter_mut())
            .zip(forces_n)
            .zip(by_others_m)
            .zip(k)
        {
            *r = if k > 0.0 {
                -(d + *r + f / k)
            } else {
                Vector3::zeros()
            };
        }
        1
    }

    /// Grows each live tie's damage with the separation it ends at: `δ + C f`.
    fn commit(
        &mut self,
        bed: &mut Bed,
        compliance: &mut impl TieCompliance,
        forces_n: &[Vector3<f64>],
        by_others_m: &[Vector3<f64>],
    ) {
        compliance.separation(forces_n, &mut self.product_m);
        let law = bed.law;
        let solved = bed.ties.iter_mut().zip(&self.product_m).zip(by_others_m);
        for (((tie, moved), d), &k) in solved.zip(&self.stiffness_n_per_m) {
            if k > 0.0 {
                tie.state.traction(&law, &(d + moved), &tie.normal);
            }
        }
    }
}

/// `Σ k |r|²`.
fn dot_weighted(r: &[Vector3<f64>], k: &[f64]) -> f64 {
    r.iter().zip(k).map(|(r, k)| k * r.norm_squared()).sum()
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;
    use crate::dissection::bed::tie_over_plane;
    use crate::dissection::{CohesiveLaw, CohesiveTie};

    /// A compliance from a dense symmetric positive definite matrix over the ties' `3 n`
    /// components.
    struct Dense(DMatrix<f64>);

    impl TieCompliance for Dense {
        fn separation(&mut self, forces_n: &[Vector3<f64>], out_m: &mut [Vector3<f64>]) {
            let f = DVector::from_iterator(
                3 * forces_n.len(),
                forces_n.iter().flat_map(|f| f.iter().copied()),
            );
            let u = &self.0 * f;
            for (i, out) in out_m.iter_mut().enumerate() {
                *out = Vector3::new(u[3 * i], u[3 * i + 1], u[3 * i + 2]);
            }
        }
    }

    /// Six ties of 0.1 cm² (50 N/m each at the bed's law) on organs whose give between them is
    /// a floppy organ's: `C = B Bᵀ` of about 0.1 m/N, five times softer than a tie is stiff.
    fn bed_and_compliance() -> (Bed, Dense) {
        let bed = Bed {
            law: CohesiveLaw::gallbladder_bed(),
            ties: (0..6)
                .map(|position| tie_over_plane(position, 1e-5))
                .collect(),
        };
        let b = DMatrix::from_fn(18, 18, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.4);
        let c = (&b * b.transpose()) * 0.02 + DMatrix::identity(18, 18) * 1e-3;
        (bed, Dense(c))
    }

    /// A pull that separates the ties by 0.2 mm: `δ`.
    fn by_others() -> Vec<Vector3<f64>> {
        (0..6)
            .map(|i| Vector3::new(0.0, 1e-5 * i as f64, 2e-4))
            .collect()
    }

    /// How far the ties' forces are from `f = −K (δ + C f)`: the worst tie's imbalance over
    /// its force.
    fn imbalance(forces: &[Vector3<f64>], k: f64, compliance: &mut Dense) -> f64 {
        let mut moved = vec![Vector3::zeros(); forces.len()];
        compliance.separation(forces, &mut moved);
        let delta = by_others();
        (0..forces.len())
            .map(|i| (forces[i] + (delta[i] + moved[i]) * k).norm() / forces[i].norm())
            .fold(0.0, f64::max)
    }

    /// Solved to the end, the forces satisfy `f = −K (δ + C f)` to 1e-8 in no more products
    /// than there are unknowns; at the default convergence, to 1e-4 in fewer. Fed back a tick
    /// late instead, the same forces grow without bound.
    #[test]
    fn the_ties_answer_the_organs_give_within_the_tick() {
        let (bed, mut compliance) = bed_and_compliance();
        let k = bed.law.stiffness_pa_per_m * 1e-5;
        let delta = by_others();
        let exact = TieConvergence {
            max_products: 40,
            relative: 1e-24,
        };
        let mut solved = Vec::new();
        for convergence in [exact, TieConvergence::default()] {
            let mut forces = vec![Vector3::zeros(); 6];
            let products = TieSolve::default().solve(
                &mut bed.clone(),
                &[],
                &delta,
                &mut compliance,
                &mut forces,
                convergence,
            );
            let worst = imbalance(&forces, k, &mut compliance);
            eprintln!("{convergence:?}: {products} products; worst imbalance {worst:.1e}");
            solved.push((products, worst, forces));
        }
        assert!(
            solved[0].1 < 1e-8 && solved[0].0 <= 18 + 2,
            "{:?}",
            &solved[0]
        );
        assert!(
            solved[1].1 < 1e-4 && solved[1].0 <= solved[0].0,
            "{:?}",
            &solved[1]
        );
        let forces = &solved[0].2;
        let mut moved = vec![Vector3::zeros(); 6];
        let mut lagged = vec![Vector3::zeros(); 6];
        for _ in 0..50 {
            compliance.separation(&lagged, &mut moved);
            for i in 0..6 {
                lagged[i] = -(delta[i] + moved[i]) * k;
            }
        }
        let grown: f64 = lagged.iter().map(|f| f.norm()).fold(0.0, f64::max);
        let solved: f64 = forces.iter().map(|f| f.norm()).fold(0.0, f64::max);
        assert!(
            grown > 1e3 * solved,
            "the lagged forces stayed at {grown} N"
        );
    }

    /// A failed tie carries no force, and the others still balance; a separation past failure
    /// fails them all.
    #[test]
    fn failed_ties_carry_nothing() {
        let (mut bed, mut compliance) = bed_and_compliance();
        bed.ties[2].state.reached_m = 1.0;
        let mut forces = vec![Vector3::x(); 6];
        let delta = by_others();
        let mut solve = TieSolve::default();
        solve.solve(
            &mut bed,
            &[],
            &delta,
            &mut compliance,
            &mut forces,
            TieConvergence::default(),
        );
        assert_eq!(forces[2], Vector3::zeros());
        assert!(forces[0].norm() > 0.0);
        let torn: Vec<Vector3<f64>> = (0..6).map(|_| Vector3::z() * 0.1).collect();
        let mut none = Dense(DMatrix::zeros(18, 18));
        solve.solve(
            &mut bed,
            &[],
            &torn,
            &mut none,
            &mut forces,
            TieConvergence::default(),
        );
        assert_eq!(bed.released_share(), 1.0);
    }

    /// A tie carried by something else (the wall, under a grasper's pull) carries no force
    /// here and is not damaged by what the organs' fields open it by; the others balance as
    /// before, to 1e-4 at the default stop.
    #[test]
    fn carried_ties_are_left_to_what_carries_them() {
        let (mut bed, mut compliance) = bed_and_compliance();
        let k = bed.ties[0].area_m2 * bed.law.stiffness_pa_per_m;
        let mut carried = [false; 6];
        carried[4] = true;
        let torn: Vec<Vector3<f64>> = (0..6).map(|_| Vector3::z() * 0.1).collect();
        let mut forces = vec![Vector3::zeros(); 6];
        TieSolve::default().solve(
            &mut bed,
            &carried,
            &by_others(),
            &mut compliance,
            &mut forces,
            TieConvergence::default(),
        );
        assert_eq!(forces[4], Vector3::zeros());
        assert_eq!(bed.ties[4].state, CohesiveTie::default());
        let mut moved = vec![Vector3::zeros(); 6];
        compliance.separation(&forces, &mut moved);
        let delta = by_others();
        for i in (0..6).filter(|&i| i != 4) {
            let miss = (forces[i] + (delta[i] + moved[i]) * k).norm() / forces[i].norm();
            assert!(miss < 1e-4, "tie {i}: {miss}");
        }
        let mut none = Dense(DMatrix::zeros(18, 18));
        TieSolve::default().solve(
            &mut bed,
            &carried,
            &torn,
            &mut none,
            &mut forces,
            TieConvergence::default(),
        );
        assert!(!bed.ties[4].state.failed(&bed.law));
        assert!(bed.ties[0].state.failed(&bed.law));
    }
}
