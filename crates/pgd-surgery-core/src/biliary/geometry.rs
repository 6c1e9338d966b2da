//! Closest points between two segments: where a clip's or a blade's closed jaws cross a
//! tube's axis, and whether a line of sight passes through a strand of fat.

use nalgebra::Vector3;

/// A segment from `from_m` to `to_m` (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub from_m: Vector3<f64>,
    pub to_m: Vector3<f64>,
}

/// The closest points of two segments: each one's parameter in `[0, 1]` from its start, and
/// the distance between them (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    pub on_first: f64,
    pub on_second: f64,
    pub distance_m: f64,
}

impl Segment {
    pub fn new(from_m: Vector3<f64>, to_m: Vector3<f64>) -> Self {
        Self { from_m, to_m }
    }

    pub fn length_m(&self) -> f64 {
        (self.to_m - self.from_m).norm()
    }

    /// The point at parameter `t` from the start.
    pub fn at(&self, t: f64) -> Vector3<f64> {
        self.from_m + (self.to_m - self.from_m) * t
    }

    /// The closest points between this segment and `other`, by minimising the squared
    /// distance over both parameters, each clamped to its segment (degenerate segments taken
    /// as points).
    pub fn closest(&self, other: &Segment) -> Closest {
        let d1 = self.to_m - self.from_m;
        let d2 = other.to_m - other.from_m;
        let r = self.from_m - other.from_m;
        let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
        const POINT: f64 = 1e-24;
        let (s, t) = if a <= POINT && e <= POINT {
            (0.0, 0.0)
        } else if a <= POINT {
            (0.0, (f / e).clamp(0.0, 1.0))
        } else {
            let c = d1.dot(&r);
            if e <= POINT {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else {
                let b = d1.dot(&d2);
                let denominator = a * e - b * b;
                let s = if denominator > POINT * a * e {
                    ((b * f - c * e) / denominator).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let t = (b * s + f) / e;
                if t < 0.0 {
                    ((-c / a).clamp(0.0, 1.0), 0.0)
                } else if t > 1.0 {
                    (((b - c) / a).clamp(0.0, 1.0), 1.0)
                } else {
                    (s, t)
                }
            }
        };
        Closest {
            on_first: s,
            on_second: t,
            distance_m: (self.at(s) - other.at(t)).norm(),
        }
    }
}
