//! Implicit shape primitives: functions negative inside, positive outside, close to the
//! Euclidean distance near the surface (exact for capsules and tubes, approximate for
//! ellipsoids and surfaces of revolution).

use nalgebra::{Point3, Vector3};

/// Approximate distance to an axis-aligned ellipsoid (first-order correction of the scaled
/// sphere distance, accurate near the surface).
pub fn ellipsoid(p: &Point3<f64>, centre: Point3<f64>, radii: Vector3<f64>) -> f64 {
    let q = p - centre;
    let k0 = q.component_div(&radii).norm();
    let k1 = q.component_div(&radii.component_mul(&radii)).norm();
    if k1 == 0.0 {
        return -radii.min();
    }
    k0 * (k0 - 1.0) / k1
}

/// Distance to the segment a–b minus a radius: a rod with round ends.
pub fn capsule(p: &Point3<f64>, a: Point3<f64>, b: Point3<f64>, radius: f64) -> f64 {
    (p - closest_on_segment(p, a, b)).norm() - radius
}

pub fn closest_on_segment(p: &Point3<f64>, a: Point3<f64>, b: Point3<f64>) -> Point3<f64> {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    a + ab * t
}

/// Smooth union: like `min(a, b)`, blended over a band of width `k` so joints are fillets
/// rather than creases.
pub fn smooth_union(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k / 4.0
}

/// A tube of `radius` around an arc of a circle in the plane spanned by `u` and `w` (unit,
/// orthogonal) about `centre`, from angle `from` to `to` (radians, `from < to`), with round ends.
pub struct ArcTube {
    pub centre: Point3<f64>,
    pub u: Vector3<f64>,
    pub w: Vector3<f64>,
    pub arc_radius: f64,
    pub tube_radius: f64,
    pub from: f64,
    pub to: f64,
}

impl ArcTube {
    /// Angle of `p` about the arc's centre, in (−π, π].
    pub fn angle(&self, p: &Point3<f64>) -> f64 {
        let q = p - self.centre;
        libm::atan2(q.dot(&self.w), q.dot(&self.u))
    }

    pub fn point_at(&self, angle: f64) -> Point3<f64> {
        self.centre + (self.u * libm::cos(angle) + self.w * libm::sin(angle)) * self.arc_radius
    }

    pub fn value(&self, p: &Point3<f64>) -> f64 {
        let angle = self.angle(p).clamp(self.from, self.to);
        let on_arc = if (self.from..=self.to).contains(&self.angle(p)) {
            // The nearest arc point lies in the plane of the circle, on the ray towards p.
            let q = p - self.centre;
            let normal = self.u.cross(&self.w);
            let in_plane = q - normal * q.dot(&normal);
            match in_plane.try_normalize(0.0) {
                Some(dir) => self.centre + dir * self.arc_radius,
                None => self.point_at(angle),
            }
        } else {
            let ends = [self.point_at(self.from), self.point_at(self.to)];
            if (p - ends[0]).norm() < (p - ends[1]).norm() {
                ends[0]
            } else {
                ends[1]
            }
        };
        (p - on_arc).norm() - self.tube_radius
    }
}

/// A closed surface of revolution about the axis `start → end`, radius `radius(t)` at
/// `t ∈ [0, 1]` (zero at both ends), offset outward by `offset`: the distance, in the meridian
/// plane, to the profile curve sampled as a polyline (exact up to the sampling), negative inside.
pub fn revolution(
    p: &Point3<f64>,
    start: Point3<f64>,
    end: Point3<f64>,
    radius: &dyn Fn(f64) -> f64,
    offset: f64,
) -> f64 {
    const SEGMENTS: usize = 256;
    let axis = end - start;
    let length = axis.norm();
    let along = (p - start).dot(&axis) / length;
    let radial = ((p - start).norm_squared() - along * along).max(0.0).sqrt();
    let q = nalgebra::Vector2::new(along, radial);
    let station = |k: usize| {
        let t = k as f64 / SEGMENTS as f64;
        nalgebra::Vector2::new(t * length, radius(t))
    };
    let distance = (0..SEGMENTS)
        .map(|k| {
            let (a, b) = (station(k), station(k + 1));
            let ab = b - a;
            let t = ((q - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            (q - (a + ab * t)).norm()
        })
        .fold(f64::INFINITY, f64::min);
    let t = along / length;
    let inside = (0.0..=1.0).contains(&t) && radial < radius(t);
    (if inside { -distance } else { distance }) - offset
}
