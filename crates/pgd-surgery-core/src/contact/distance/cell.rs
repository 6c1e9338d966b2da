//! One lattice cell as a distance read sees it: where a point lies in it, and its eight
//! corners' values interpolated trilinearly, in `f32` as the lattice stores them.
//!
//! Interpolated as seven lerps per value (four along x, two along y, one along z) rather than
//! eight weights: a read takes up to five cells (the pull-back's steps), and the weights, in `f64` products,
//! cost a quarter of a press's contact stage at rest (400 points).

/// Where a point lies in its lattice cell: the cell's lowest node, and the point's coordinates
/// in it (0 to 1 per axis). Corner `k` of a cell lies at `t_c = 1` along axis `c` where bit
/// `c` of `k` is set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Cell {
    pub base: usize,
    pub t: [f32; 3],
}

impl Cell {
    /// The values of the eight corners interpolated at the point.
    pub fn interpolate<const N: usize>(&self, corners: &[[f32; N]; 8]) -> [f32; N] {
        let [tx, ty, tz] = self.t;
        std::array::from_fn(|c| {
            let x = along_x(corners, c, tx);
            lerp(lerp(x[0], x[1], ty), lerp(x[2], x[3], ty), tz)
        })
    }

    /// How the interpolated values change across the cell: `[axis][value]`, per cell width.
    pub fn slopes<const N: usize>(&self, corners: &[[f32; N]; 8]) -> [[f32; N]; 3] {
        let [tx, ty, tz] = self.t;
        let mut slopes = [[0.0; N]; 3];
        for c in 0..N {
            let dx: [f32; 4] = std::array::from_fn(|k| corners[2 * k + 1][c] - corners[2 * k][c]);
            let x = along_x(corners, c, tx);
            slopes[0][c] = lerp(lerp(dx[0], dx[1], ty), lerp(dx[2], dx[3], ty), tz);
            slopes[1][c] = lerp(x[1] - x[0], x[3] - x[2], tz);
            slopes[2][c] = lerp(x[2], x[3], ty) - lerp(x[0], x[1], ty);
        }
        slopes
    }
}

/// Value `c` of the corners interpolated along x, on the cell's four edges along x (ordered
/// by their y, then z).
fn along_x<const N: usize>(corners: &[[f32; N]; 8], c: usize, tx: f32) -> [f32; 4] {
    std::array::from_fn(|k| lerp(corners[2 * k][c], corners[2 * k + 1][c], tx))
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + t * (b - a)
}

/// How much a displacement stretches distances along the surface's normal where its gradient
/// is `slopes` (`[axis][component]`, per metre) and the rest distance's direction `gradient`:
/// `|F⁻ᵀ g|` with `F = I + ∇u` and `g` the unit direction, as `|cof(F) g| / |det F|`. 1 where
/// `F` is singular or no direction is known.
pub(super) fn normal_stretch(slopes: &[[f32; 3]; 3], gradient: [f32; 3]) -> f32 {
    let length = gradient.iter().map(|g| g * g).sum::<f32>().sqrt();
    if length.is_nan() || length < 1e-9 {
        return 1.0;
    }
    let g = gradient.map(|g| g / length);
    // F[i][j] = δ_ij + ∂u_i/∂x_j.
    let f: [[f32; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| f32::from(i == j) + slopes[j][i]));
    let cofactor = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        f[i1][j1] * f[i2][j2] - f[i1][j2] * f[i2][j1]
    };
    let det: f32 = (0..3).map(|j| f[0][j] * cofactor(0, j)).sum();
    let turned: [f32; 3] = std::array::from_fn(|i| (0..3).map(|j| cofactor(i, j) * g[j]).sum());
    let stretch = turned.iter().map(|v| v * v).sum::<f32>().sqrt() / det.abs();
    if stretch.is_finite() && stretch > 1e-3 {
        stretch
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix3, Vector3};

    use super::*;

    /// Corner `k`'s position in the cell (0 or 1 per axis).
    fn corner(k: usize) -> [f32; 3] {
        [0, 1, 2].map(|c| (k >> c & 1) as f32)
    }

    /// A trilinear function (`a + b·x + c·xy + d·xyz`, per value) is reproduced exactly, and
    /// so are its slopes.
    #[test]
    fn a_trilinear_function_and_its_slopes_are_read_back() {
        let value = |p: [f32; 3]| {
            [
                1.0 + 2.0 * p[0] - 3.0 * p[1] + 0.5 * p[2] + 4.0 * p[0] * p[1] * p[2],
                -0.25 * p[0] * p[2] + 1.5 * p[1] * p[2],
            ]
        };
        let slope = |p: [f32; 3]| {
            [
                [2.0 + 4.0 * p[1] * p[2], -0.25 * p[2]],
                [-3.0 + 4.0 * p[0] * p[2], 1.5 * p[2]],
                [0.5 + 4.0 * p[0] * p[1], -0.25 * p[0] + 1.5 * p[1]],
            ]
        };
        let corners: [[f32; 2]; 8] = std::array::from_fn(|k| value(corner(k)));
        for t in [
            [0.0, 0.0, 0.0],
            [0.3, 0.8, 0.1],
            [1.0, 0.5, 0.25],
            [0.9, 0.05, 1.0],
        ] {
            let cell = Cell { base: 0, t };
            let (read, expected) = (cell.interpolate(&corners), value(t));
            for c in 0..2 {
                assert!((read[c] - expected[c]).abs() < 1e-6, "{t:?}: {read:?}");
            }
            let (read, expected) = (cell.slopes(&corners), slope(t));
            for axis in 0..3 {
                for c in 0..2 {
                    let error = (read[axis][c] - expected[axis][c]).abs();
                    assert!(error < 1e-5, "{t:?}, axis {axis}: {read:?}");
                }
            }
        }
    }

    /// Against the inverse: `|F⁻ᵀ g|` for a shear and a stretch, and 1 for a singular `F`.
    #[test]
    fn the_stretch_is_the_inverse_transposes_length() {
        let slopes = [[0.2, -0.1, 0.05], [0.3, 0.1, 0.0], [-0.05, 0.15, 0.4]];
        let f = Matrix3::from_fn(|i, j| f64::from(i == j) + slopes[j][i] as f64);
        let g = Vector3::new(1.0, 2.0, -2.0) / 3.0;
        let expected = (f.try_inverse().unwrap().transpose() * g).norm();
        let stretch = normal_stretch(&slopes, [2.0, 4.0, -4.0]) as f64;
        assert!(
            (stretch - expected).abs() < 1e-6 * expected,
            "{stretch} vs {expected}"
        );
        let flat = [[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        assert_eq!(normal_stretch(&flat, [1.0, 0.0, 0.0]), 1.0);
        assert_eq!(normal_stretch(&[[0.0; 3]; 3], [0.0; 3]), 1.0);
    }
}
