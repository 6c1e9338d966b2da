//! Anderson acceleration of a fixed-point iteration `x ← G(x)` (Walker & Ni 2011, type II):
//! the next iterate is the combination of the last few `G` values whose residuals `G(x) − x`
//! cancel best in least squares. Where the secant iteration of a stiffening law contracts
//! slowly (a deep load step, whose tangent is several times the rest stiffness), a scalar
//! relaxation still crawls; a few remembered directions take most of that away.
//!
//! Where the law stiffens more than twice over (the exponential law pressed deep), the plain
//! iteration overshoots and diverges: each step mixes in only a fraction β of the residual,
//! `x ← x̄ + β f̄` (`x̄`, `f̄` the combined iterate and residual), β given at the start and
//! halved each time the caller sees the iteration grow.

use std::collections::VecDeque;

use nalgebra::{DMatrix, DVector};

/// One fixed point's memory: the differences of the last residuals and `G` values.
pub struct Anderson {
    depth: usize,
    residual_steps: VecDeque<Vec<f64>>,
    value_steps: VecDeque<Vec<f64>>,
    last: Option<(Vec<f64>, Vec<f64>)>,
    /// The fraction β of the combined residual each step takes (1: undamped).
    mixing: f64,
}

impl Anderson {
    /// Remembers up to `depth` differences (0: the plain iteration); each step takes the
    /// fraction `mixing` of the combined residual (1: undamped).
    pub fn new(depth: usize, mixing: f64) -> Self {
        Self {
            depth,
            residual_steps: VecDeque::with_capacity(depth),
            value_steps: VecDeque::with_capacity(depth),
            last: None,
            mixing,
        }
    }

    /// Halves the step's mixing and forgets the history gathered at the old one: the
    /// iteration grew, so the law is stiffer than the rest stiffness by more than 2/β.
    pub fn damp(&mut self) {
        self.mixing *= 0.5;
        self.reset();
    }

    /// Forgets the history: after the iterate was moved off the accelerated path.
    pub fn reset(&mut self) {
        self.residual_steps.clear();
        self.value_steps.clear();
        self.last = None;
    }

    /// Writes the next iterate into `x`, given `g = G(x)`.
    pub fn advance(&mut self, x: &mut [f64], g: Vec<f64>) {
        let residual: Vec<f64> = g.iter().zip(x.iter()).map(|(g, x)| g - x).collect();
        if self.depth == 0 {
            let beta = self.mixing;
            x.iter_mut()
                .zip(&residual)
                .for_each(|(x, r)| *x += beta * r);
            return;
        }
        if let Some((last_residual, last_value)) = self.last.take() {
            if self.residual_steps.len() == self.depth {
                self.residual_steps.pop_front();
                self.value_steps.pop_front();
            }
            self.residual_steps
                .push_back(difference(&residual, &last_residual));
            self.value_steps.push_back(difference(&g, &last_value));
        }
        let weights = self.weights(&residual);
        // x̄ + f̄ = g − Σ γ Δg; the damped step takes back (1 − β) f̄, f̄ = f − Σ γ Δf.
        x.copy_from_slice(&g);
        let undamped = 1.0 - self.mixing;
        if undamped != 0.0 {
            x.iter_mut()
                .zip(&residual)
                .for_each(|(x, r)| *x -= undamped * r);
        }
        for ((w, step), residual_step) in weights
            .iter()
            .zip(&self.value_steps)
            .zip(&self.residual_steps)
        {
            let back = undamped * w;
            x.iter_mut()
                .zip(step.iter().zip(residual_step))
                .for_each(|(x, (s, r))| *x -= w * s - back * r);
        }
        self.last = Some((residual, g));
    }

    /// `γ = argmin ‖f − ΔF γ‖` by the normal equations, lightly regularized: the columns of
    /// `ΔF` grow nearly dependent as the iteration converges.
    fn weights(&self, residual: &[f64]) -> Vec<f64> {
        let m = self.residual_steps.len();
        if m == 0 {
            return Vec::new();
        }
        let gram = DMatrix::from_fn(m, m, |i, j| {
            dot(&self.residual_steps[i], &self.residual_steps[j])
        });
        let rhs = DVector::from_fn(m, |i, _| dot(&self.residual_steps[i], residual));
        let ridge = 1e-12 * gram.trace().max(f64::MIN_POSITIVE);
        let regularized = gram + DMatrix::identity(m, m) * ridge;
        match regularized.cholesky() {
            Some(factor) => factor.solve(&rhs).iter().copied().collect(),
            None => vec![0.0; m],
        }
    }
}

fn difference(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(a, b)| a - b).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear contraction `G(x) = A x + b` with a spectral radius of 0.99: the plain
    /// iteration needs hundreds of steps, Anderson with a memory as large as the dimension
    /// converges in a few more than the dimension (it is then GMRES in disguise).
    #[test]
    fn accelerates_a_slow_linear_contraction() {
        let a = [[0.99, 0.0, 0.0], [0.0, 0.5, 0.1], [0.0, 0.1, -0.3]];
        let b = [1.0, 2.0, 3.0];
        let g = |x: &[f64]| -> Vec<f64> {
            (0..3)
                .map(|i| (0..3).map(|j| a[i][j] * x[j]).sum::<f64>() + b[i])
                .collect()
        };
        let solve = |depth: usize| {
            let mut anderson = Anderson::new(depth, 1.0);
            let mut x = vec![0.0; 3];
            for iteration in 1..=2000 {
                let before = x.clone();
                let value = g(&x);
                anderson.advance(&mut x, value);
                let change: f64 = difference(&x, &before).iter().map(|d| d * d).sum();
                if change.sqrt() < 1e-12 {
                    return (iteration, x);
                }
            }
            (usize::MAX, x)
        };
        let (plain, _) = solve(0);
        let (accelerated, x) = solve(3);
        // The exact fixed point: (I − A) x = b.
        let residual: Vec<f64> = difference(&g(&x), &x);
        assert!(dot(&residual, &residual).sqrt() < 1e-10, "{x:?}");
        assert!(accelerated <= 8, "{accelerated} iterations");
        assert!(plain > 1000, "{plain} iterations");
    }

    /// `G(x) = −3 x + 4` overshoots (its slope is below −1): the plain iteration diverges, a
    /// mixing of β = 1/4 lands on the fixed point x = 1 in one step, with or without memory.
    #[test]
    fn damping_tames_an_overshooting_iteration() {
        let g = |x: &[f64]| vec![-3.0 * x[0] + 4.0];
        for depth in [0, 3] {
            let mut anderson = Anderson::new(depth, 1.0);
            let mut x = vec![0.0];
            let value = g(&x);
            anderson.advance(&mut x, value);
            assert_eq!(x, vec![4.0], "the first step is undamped");
            anderson.damp();
            anderson.damp();
            for _ in 0..5 {
                let value = g(&x);
                anderson.advance(&mut x, value);
            }
            assert!((x[0] - 1.0).abs() < 1e-12, "depth {depth}: {x:?}");
        }
    }
}
