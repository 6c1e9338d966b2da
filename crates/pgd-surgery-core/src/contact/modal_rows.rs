//! An organ's modes at a few chosen nodes, laid out node after node so that a node's
//! displacement, or a force's modal coefficients, is one contiguous run over the modes: what
//! the contact stage evaluates hundreds of times per tick.

use std::ops::Range;

use nalgebra::Vector3;

use crate::pgd::Vademecum;

/// Per chosen node, `3 × modes` values `[k * 3 + c]` (all load steps, one after another).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModalRows {
    modes: usize,
    values: Vec<f32>,
}

/// A point of a surface as a weighted sum of load positions (a position itself: `[(m, 1.0)]`;
/// a point inside a triangle: its corners, weighted by its barycentric coordinates).
pub type Blend = [(usize, f64)];

impl ModalRows {
    /// The spatial modes (displacement per unit coefficient, m) at surface points, each a
    /// blend of load positions (interpolated from their volume nodes).
    pub fn displacements<B: AsRef<Blend>>(
        vademecum: &Vademecum,
        points: impl Iterator<Item = B>,
    ) -> Self {
        Self::gather(vademecum, points, |step, mode, position| {
            vademecum.mode_at_node(step, mode, vademecum.positions[position] as usize)
        })
    }

    /// The parametric modes (coefficient per newton) at surface points, each a blend of load
    /// positions (a force there is shared among them by the blend's weights).
    pub fn loads<B: AsRef<Blend>>(vademecum: &Vademecum, points: impl Iterator<Item = B>) -> Self {
        Self::gather(vademecum, points, |step, mode, position| {
            vademecum.load_mode_at(step, mode, position)
        })
    }

    fn gather<B: AsRef<Blend>>(
        vademecum: &Vademecum,
        points: impl Iterator<Item = B>,
        value: impl Fn(usize, usize, usize) -> Vector3<f64>,
    ) -> Self {
        let modes = vademecum.total_modes();
        let mut values = Vec::new();
        for blend in points {
            for step in 0..vademecum.steps.len() {
                for mode in 0..vademecum.modes(step) {
                    let v: Vector3<f64> = blend
                        .as_ref()
                        .iter()
                        .map(|&(position, w)| value(step, mode, position) * w)
                        .sum();
                    values.extend(v.iter().map(|&v| v as f32));
                }
            }
        }
        Self { modes, values }
    }

    pub fn len(&self) -> usize {
        self.values.len() / (3 * self.modes).max(1)
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    fn row(&self, i: usize) -> &[f32] {
        &self.values[3 * self.modes * i..3 * self.modes * (i + 1)]
    }

    /// `Σ_k α_k X^k` at chosen node `i`.
    pub fn apply(&self, i: usize, alpha: &[f32]) -> Vector3<f32> {
        let mut sum = [0.0f32; 3];
        for (x, &a) in self.row(i).chunks_exact(3).zip(alpha) {
            for c in 0..3 {
                sum[c] += a * x[c];
            }
        }
        Vector3::from(sum)
    }

    /// Per mode, the row at chosen node `i` along the direction `n`: `X^k · n`.
    pub fn along(&self, i: usize, n: Vector3<f32>) -> impl Iterator<Item = f32> + '_ {
        self.row(i)
            .chunks_exact(3)
            .map(move |x| x[0] * n.x + x[1] * n.y + x[2] * n.z)
    }

    /// Per mode, the largest `|X^k|` over the chosen nodes: bounds how far they can move.
    pub fn bounds(&self) -> Vec<f32> {
        let mut bounds = vec![0.0f32; self.modes];
        for i in 0..self.len() {
            for (b, x) in bounds.iter_mut().zip(self.row(i).chunks_exact(3)) {
                *b = b.max((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt());
            }
        }
        bounds
    }
}

/// Where each load step's modes sit in a concatenated coefficient list.
pub fn step_ranges(vademecum: &Vademecum) -> Vec<Range<usize>> {
    let mut start = 0;
    (0..vademecum.steps.len())
        .map(|step| {
            let range = start..start + vademecum.modes(step);
            start = range.end;
            range
        })
        .collect()
}

/// The per-step coefficients of an organ, concatenated as f32 into `out`.
pub fn concatenate(coefficients: &[Vec<f64>], out: &mut Vec<f32>) {
    out.clear();
    out.extend(coefficients.iter().flatten().map(|&c| c as f32));
}

/// `Σ_k |α_k| b_k`: how far modes with per-mode bounds `bounds` can move anything, for
/// coefficients `alpha`.
pub fn movement_bound(alpha: &[f32], bounds: &[f32]) -> f32 {
    alpha.iter().zip(bounds).map(|(a, b)| a.abs() * b).sum()
}
