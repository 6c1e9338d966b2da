//! The one place where our geometry (nalgebra, f64) meets parry3d's glam types (f32). Bevy's
//! side of the same seam goes through plain `[f32; 3]` arrays in the `app` layer.

use nalgebra::Point3;
use parry3d::math::Vector;

pub fn to_parry(p: &Point3<f64>) -> Vector {
    Vector::new(p.x as f32, p.y as f32, p.z as f32)
}

pub fn from_parry(v: Vector) -> Point3<f64> {
    Point3::new(v.x as f64, v.y as f64, v.z as f64)
}
