//! The contact forces of one tick: the minimum of the convex contact energy
//! `E(f) = ½ fᵀ A f + Σ f²/2k + d₀ᵀ f` over `f ≥ 0` (see [`super::pair`]), by conjugate
//! gradients on the nodes that push, restarted whenever a node starts or stops pushing
//! (Polyak's active-set method, preconditioned by the penalties).
//!
//! Why not one steepest-descent step per tick: `E` is ill-conditioned (the penalty is a
//! thousand times stiffer than the tissue behind it), so steepest descent zig-zags from tick to
//! tick and the felt force with it. `A` has the rank of the two organs' modes, so conjugate
//! gradients on a fixed set of pushing nodes converge in that many steps at most, and warm
//! started from the last tick's forces, in a few.

/// Work vectors, one entry per pointshell node; only the entries of the tick's set are used.
#[derive(Clone, Debug, Default)]
pub struct ProjectedCg {
    /// `−k ∂E/∂f` on the free nodes, the direction of the current conjugate step (N).
    direction_n: Vec<f64>,
    /// `(A + K⁻¹)` times the direction (m).
    product_m: Vec<f64>,
    /// Whether a node takes part in the current conjugate sequence.
    free: Vec<bool>,
}

/// When to stop: the preconditioned gradient's square norm, relative to the forces' energy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    /// Most products with `A` per tick: bounds the tick's cost.
    pub max_products: usize,
    /// Stop once `Σ k g²` is below this fraction of `Σ f²/k` (both J): 1e-6 leaves the
    /// forces about 0.1 % from the minimum, near what the f32 modes resolve.
    pub relative: f64,
}

impl Default for Convergence {
    fn default() -> Self {
        Self {
            max_products: 12,
            relative: 1e-6,
        }
    }
}

impl ProjectedCg {
    pub fn new(count: usize) -> Self {
        Self {
            direction_n: vec![0.0; count],
            product_m: vec![0.0; count],
            free: vec![false; count],
        }
    }

    /// Lowers `E` over the nodes of `set` from the forces `force_n`, given the energy's
    /// gradient there `gradient_m` (`d + f/k`, m, as the tick measured it). Nodes outside `set`
    /// keep zero force. Returns the number of products with `A` taken.
    pub fn solve(
        &mut self,
        set: &[u32],
        stiffness_n_per_m: &[f64],
        compliance: &mut impl FnMut(&[u32], &[f64], &mut [f64]),
        force_n: &mut [f64],
        gradient_m: &mut [f64],
        convergence: &Convergence,
    ) -> usize {
        let mut products = 0;
        while products < convergence.max_products {
            let Some(mut residual) = self.restart(set, stiffness_n_per_m, force_n, gradient_m)
            else {
                break;
            };
            let energy: f64 = set
                .iter()
                .map(|&i| force_n[i as usize].powi(2) / stiffness_n_per_m[i as usize])
                .sum();
            let tolerance = convergence.relative * energy.max(f64::MIN_POSITIVE);
            while residual > tolerance && products < convergence.max_products {
                self.multiply(set, stiffness_n_per_m, compliance);
                products += 1;
                match self.step(set, stiffness_n_per_m, force_n, gradient_m, residual) {
                    Some(next) => residual = next,
                    None => break,
                }
            }
            if residual <= tolerance {
                break;
            }
        }
        products
    }

    /// Starts a new conjugate sequence along the preconditioned steepest descent of the free
    /// nodes (pushing, or pushed into); returns its square norm `Σ k g²`, `None` when no node
    /// is free.
    fn restart(
        &mut self,
        set: &[u32],
        stiffness_n_per_m: &[f64],
        force_n: &[f64],
        gradient_m: &[f64],
    ) -> Option<f64> {
        let mut residual = 0.0;
        let mut any = false;
        for &i in set {
            let i = i as usize;
            let free = force_n[i] > 0.0 || gradient_m[i] < 0.0;
            self.free[i] = free;
            let (k, g) = (stiffness_n_per_m[i], gradient_m[i]);
            self.direction_n[i] = if free { -k * g } else { 0.0 };
            residual += if free { k * g * g } else { 0.0 };
            any |= free;
        }
        any.then_some(residual)
    }

    /// `(A + K⁻¹)` times the direction, `A` given as `compliance(set, v, out)`.
    fn multiply(
        &mut self,
        set: &[u32],
        stiffness_n_per_m: &[f64],
        compliance: &mut impl FnMut(&[u32], &[f64], &mut [f64]),
    ) {
        compliance(set, &self.direction_n, &mut self.product_m);
        for &i in set {
            let i = i as usize;
            self.product_m[i] += self.direction_n[i] / stiffness_n_per_m[i];
        }
    }

    /// One conjugate step along the direction, cut where a pushing node would let go. Returns
    /// the next residual to go on with, or `None` to restart (a node let go, a held node is
    /// now pushed into, or the curvature vanished).
    fn step(
        &mut self,
        set: &[u32],
        stiffness_n_per_m: &[f64],
        force_n: &mut [f64],
        gradient_m: &mut [f64],
        residual: f64,
    ) -> Option<f64> {
        let curvature: f64 = set
            .iter()
            .map(|&i| self.direction_n[i as usize] * self.product_m[i as usize])
            .sum();
        if curvature <= 0.0 {
            return None;
        }
        let full = residual / curvature;
        let (mut length, mut blocking) = (full, None);
        for &i in set {
            let (f, p) = (force_n[i as usize], self.direction_n[i as usize]);
            if p < 0.0 && f + length * p < 0.0 {
                (length, blocking) = (f / -p, Some(i as usize));
            }
        }
        for &i in set {
            let i = i as usize;
            force_n[i] = (force_n[i] + length * self.direction_n[i]).max(0.0);
            gradient_m[i] += length * self.product_m[i];
        }
        if let Some(i) = blocking {
            force_n[i] = 0.0;
            return None;
        }
        self.conjugate(set, stiffness_n_per_m, force_n, gradient_m, residual)
    }

    /// The next conjugate direction on the same free nodes, or `None` when a held node is now
    /// pushed into (the free set grows: restart).
    fn conjugate(
        &mut self,
        set: &[u32],
        stiffness_n_per_m: &[f64],
        force_n: &[f64],
        gradient_m: &[f64],
        residual: f64,
    ) -> Option<f64> {
        let mut next = 0.0;
        for &i in set {
            let i = i as usize;
            let (free, g) = (self.free[i], gradient_m[i]);
            if !free && force_n[i] == 0.0 && g < 0.0 {
                return None;
            }
            if free {
                next += stiffness_n_per_m[i] * g * g;
            }
        }
        let beta = next / residual;
        for &i in set {
            let i = i as usize;
            if self.free[i] {
                self.direction_n[i] =
                    -stiffness_n_per_m[i] * gradient_m[i] + beta * self.direction_n[i];
            }
        }
        Some(next)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The minimum of `½fᵀHf + d₀ᵀf` over `f ≥ 0` by trying every set of pushing nodes: the
    /// reference for a handful of nodes.
    fn brute_force(h: &[Vec<f64>], d0: &[f64]) -> Vec<f64> {
        let n = d0.len();
        let mut best = (0.0, vec![0.0; n]);
        for mask in 1..1u32 << n {
            let free: Vec<usize> = (0..n).filter(|i| mask >> i & 1 == 1).collect();
            let m = free.len();
            let sub = nalgebra::DMatrix::from_fn(m, m, |r, c| h[free[r]][free[c]]);
            let rhs = nalgebra::DVector::from_fn(m, |r, _| -d0[free[r]]);
            let Some(x) = sub.lu().solve(&rhs) else {
                continue;
            };
            if x.iter().any(|&v| v < 0.0) {
                continue;
            }
            let mut f = vec![0.0; n];
            free.iter().zip(x.iter()).for_each(|(&i, &v)| f[i] = v);
            let energy: f64 = (0..n)
                .map(|i| 0.5 * f[i] * (0..n).map(|j| h[i][j] * f[j]).sum::<f64>() + d0[i] * f[i])
                .sum();
            if energy < best.0 {
                best = (energy, f);
            }
        }
        best.1
    }

    #[test]
    fn reaches_the_constrained_minimum_of_an_ill_conditioned_low_rank_energy() {
        // A = U Uᵀ of rank 2 over 6 nodes, penalties a thousand times stiffer: the contact's
        // shape. Deterministic pseudo-random entries.
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as f64 / (1u64 << 31) as f64
        };
        let n = 6;
        let u: Vec<[f64; 2]> = (0..n).map(|_| [next(), next()]).collect();
        let a = |i: usize, j: usize| u[i][0] * u[j][0] + u[i][1] * u[j][1];
        let k = vec![1000.0; n];
        let d0: Vec<f64> = (0..n).map(|_| next() - 0.6).collect();
        let h: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| a(i, j) + if i == j { 1.0 / k[i] } else { 0.0 })
                    .collect()
            })
            .collect();
        let expected = brute_force(&h, &d0);
        let set: Vec<u32> = (0..n as u32).collect();
        let mut apply = |set: &[u32], v: &[f64], out: &mut [f64]| {
            for &i in set {
                out[i as usize] = set
                    .iter()
                    .map(|&j| a(i as usize, j as usize) * v[j as usize])
                    .sum();
            }
        };
        let mut force = vec![0.0; n];
        let mut gradient = d0.clone();
        let products = ProjectedCg::new(n).solve(
            &set,
            &k,
            &mut apply,
            &mut force,
            &mut gradient,
            &Convergence {
                max_products: 50,
                relative: 1e-14,
            },
        );
        let scale = expected.iter().fold(0.0f64, |m, f| m.max(f.abs()));
        for (f, e) in force.iter().zip(&expected) {
            assert!(
                (f - e).abs() <= 1e-6 * scale,
                "{force:?} against {expected:?}"
            );
        }
        assert!(products <= 2 * n, "{products} products");
    }
}
