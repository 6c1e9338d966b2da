//! Square matrices whose entries lie within a few diagonals of the main one (the tangent of
//! a chain of nodes, each coupled to its near neighbours), solved by elimination within the
//! band: `O(n · band²)`.

/// A banded square matrix of half bandwidth `band`, solved without pivoting (for the
/// symmetric positive definite tangents of rods and strips).
#[derive(Clone, Debug)]
pub struct Banded {
    n: usize,
    band: usize,
    values: Vec<f64>,
}

impl Banded {
    /// The `n × n` zero matrix of half bandwidth `band`.
    pub fn zeros(n: usize, band: usize) -> Self {
        Self {
            n,
            band,
            values: vec![0.0; n * (2 * band + 1)],
        }
    }

    /// Its size.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether it is 0 × 0.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Makes it `n × n`, every entry zero, within the storage it has (a matrix that shrinks
    /// and grows back allocates nothing).
    pub fn resize(&mut self, n: usize) {
        self.n = n;
        self.values.clear();
        self.values.resize(n * (2 * self.band + 1), 0.0);
    }

    /// Zeroes every entry, keeping the storage.
    pub fn clear(&mut self) {
        self.values.fill(0.0);
    }

    fn index(&self, row: usize, column: usize) -> usize {
        row * (2 * self.band + 1) + column + self.band - row
    }

    /// Adds `value` at (`row`, `column`), which must lie within the band.
    pub fn add(&mut self, row: usize, column: usize, value: f64) {
        assert!(
            row.abs_diff(column) <= self.band,
            "({row}, {column}) outside a band of {}",
            self.band
        );
        let k = self.index(row, column);
        self.values[k] += value;
    }

    /// The entry at (`row`, `column`) within the band.
    pub fn get(&self, row: usize, column: usize) -> f64 {
        self.values[self.index(row, column)]
    }

    /// Adds the 3 × 3 `block` with its first entry at (`row`, `column`), which must lie within
    /// the band.
    pub fn add_block(&mut self, row: usize, column: usize, block: &nalgebra::Matrix3<f64>) {
        assert!(
            row.abs_diff(column) + 2 <= self.band,
            "a block at ({row}, {column}) outside a band of {}",
            self.band
        );
        for r in 0..3 {
            let start = self.index(row + r, column);
            let entries = &mut self.values[start..start + 3];
            entries
                .iter_mut()
                .enumerate()
                .for_each(|(c, v)| *v += block[(r, c)]);
        }
    }

    /// Solves `A x = b` in place (`b` becomes `x`), eliminating within the band; the matrix
    /// is consumed by the elimination. `None` at a pivot that is not positive and finite
    /// (the matrix was singular or not positive definite).
    pub fn solve(&mut self, b: &mut [f64]) -> Option<()> {
        let (n, band) = (self.n, self.band);
        for k in 0..n {
            let pivot = self.get(k, k);
            if !(pivot.is_finite() && pivot > 0.0) {
                return None;
            }
            let end = (k + band + 1).min(n);
            // Row k from its diagonal to the band's edge, contiguous in the storage.
            let (pivot_start, span) = (self.index(k, k), end - k);
            for row in k + 1..end {
                let factor = self.get(row, k) / pivot;
                if factor == 0.0 {
                    continue;
                }
                let start = self.index(row, k);
                let (above, below) = self.values.split_at_mut(start);
                let pivot_row = &above[pivot_start..pivot_start + span];
                for (v, p) in below[..span].iter_mut().zip(pivot_row) {
                    *v -= factor * p;
                }
                b[row] -= factor * b[k];
            }
        }
        for k in (0..n).rev() {
            let end = (k + band + 1).min(n);
            let start = self.index(k, k + 1);
            let row = &self.values[start..start + (end - k - 1)];
            let known: f64 = row.iter().zip(&b[k + 1..end]).map(|(a, x)| a * x).sum();
            b[k] = (b[k] - known) / self.get(k, k);
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tridiagonal system (the 1D Laplacian plus the identity) against its dense solve.
    #[test]
    fn a_banded_solve_matches_the_dense_one() {
        let n = 12;
        let mut banded = Banded::zeros(n, 2);
        let mut dense = nalgebra::DMatrix::zeros(n, n);
        for i in 0..n {
            banded.add(i, i, 3.0);
            dense[(i, i)] = 3.0;
            if i + 1 < n {
                for (r, c) in [(i, i + 1), (i + 1, i)] {
                    banded.add(r, c, -1.0);
                    dense[(r, c)] = -1.0;
                }
            }
            if i + 2 < n {
                for (r, c) in [(i, i + 2), (i + 2, i)] {
                    banded.add(r, c, 0.25);
                    dense[(r, c)] = 0.25;
                }
            }
        }
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut x = b.clone();
        banded.solve(&mut x).unwrap();
        let reference = dense.lu().solve(&nalgebra::DVector::from_vec(b)).unwrap();
        for (a, r) in x.iter().zip(reference.iter()) {
            assert!((a - r).abs() < 1e-12, "{a} against {r}");
        }
    }

    /// A matrix that is not positive definite is refused.
    #[test]
    fn a_pivot_that_is_not_positive_is_refused() {
        let mut banded = Banded::zeros(2, 1);
        banded.add(0, 0, -1.0);
        banded.add(1, 1, 1.0);
        assert!(banded.solve(&mut [1.0, 1.0]).is_none());
    }
}
