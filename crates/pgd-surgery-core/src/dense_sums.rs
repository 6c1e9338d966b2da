//! The few dense inner products the hot loops spend their time in, written so that the
//! compiler vectorizes them.
//!
//! A sum written as one running total (`iter().map(…).sum()`) is a chain: each addition waits
//! for the one before, a few cycles each, because floating-point addition is not associative
//! and the compiler may not reorder it. Here every sum keeps `LANES` totals side by side,
//! which the compiler maps onto vector registers, and adds them up at the end. The result
//! differs from the chained sum only by rounding.
//!
//! Measured in a same-run A/B against chained sums: the contact solve's block product over 230
//! pushing points takes 6 % of the stage's profile instead of 15 %; the short sums of the
//! four-organ tick take as long either way. The modal rows' `Σ α_k X^k` is not written this
//! way: so written, it makes the haptic tick slower.

use std::ops::{Add, Mul};

/// Independent running totals per sum: two 256-bit registers of `f32`, enough to hide the
/// latency of a fused multiply-add on current cores.
const LANES: usize = 8;

/// The arithmetic the kernels need, for `f32` and `f64`.
pub trait Real: Copy + Default + Add<Output = Self> + Mul<Output = Self> {}

impl Real for f32 {}
impl Real for f64 {}

/// `Σ_k a_k b_k` over the shorter of the two.
pub fn dot<T: Real>(a: &[T], b: &[T]) -> T {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut totals = [T::default(); LANES];
    let (whole_a, whole_b) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: T = whole_a
        .remainder()
        .iter()
        .zip(whole_b.remainder())
        .fold(T::default(), |s, (&x, &y)| s + x * y);
    for (x, y) in whole_a.zip(whole_b) {
        for k in 0..LANES {
            totals[k] = totals[k] + x[k] * y[k];
        }
    }
    fold(totals) + tail
}

/// `y += a x`.
pub fn axpy<T: Real>(a: T, x: &[T], y: &mut [T]) {
    y.iter_mut().zip(x).for_each(|(y, &x)| *y = *y + a * x);
}

/// The totals added pairwise.
fn fold<T: Real>(totals: [T; LANES]) -> T {
    let mut width = LANES;
    let mut totals = totals;
    while width > 1 {
        width /= 2;
        for k in 0..width {
            totals[k] = totals[k] + totals[k + width];
        }
    }
    totals[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lengths on both sides of every multiple of the lanes, against plain sums in `f64`
    /// (exact here: small integers).
    #[test]
    fn the_kernels_agree_with_plain_sums_at_every_length() {
        for n in 0..3 * LANES + 3 {
            let a: Vec<f64> = (0..n).map(|k| (k % 7) as f64 - 3.0).collect();
            let b: Vec<f64> = (0..n).map(|k| (k % 5) as f64 + 1.0).collect();
            let plain: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            assert_eq!(dot(&a, &b), plain, "dot, length {n}");
            let (a32, b32): (Vec<f32>, Vec<f32>) = a
                .iter()
                .zip(&b)
                .map(|(&x, &y)| (x as f32, y as f32))
                .unzip();
            assert_eq!(dot(&a32, &b32), plain as f32, "dot in f32, length {n}");
            let mut y = b.clone();
            axpy(2.0, &a, &mut y);
            let summed: Vec<f64> = a.iter().zip(&b).map(|(x, y)| y + 2.0 * x).collect();
            assert_eq!(y, summed, "axpy, length {n}");
        }
    }

    /// A longer input is read only as far as the shorter goes.
    #[test]
    fn the_shorter_input_sets_the_length() {
        assert_eq!(dot(&[1.0f32, 2.0, 3.0], &[1.0, 1.0]), 3.0);
        assert_eq!(dot(&[1.0f64; 20], &[2.0; 17]), 34.0);
    }
}
