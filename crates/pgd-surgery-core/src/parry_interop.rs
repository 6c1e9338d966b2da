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

/// A parry triangle mesh over render positions (f32 arrays, the Bevy side's layout), for
/// line-of-sight queries; `None` where parry refuses the triangles.
pub fn trimesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Option<parry3d::shape::TriMesh> {
    let vertices = positions.iter().map(|&p| Vector::from_array(p)).collect();
    parry3d::shape::TriMesh::new(vertices, triangles.to_vec()).ok()
}

/// How far along the ray from `origin` in the unit direction `dir` the mesh is first hit,
/// up to `max_m`.
pub fn ray_distance(
    mesh: &parry3d::shape::TriMesh,
    origin: [f32; 3],
    dir: [f32; 3],
    max_m: f32,
) -> Option<f32> {
    use parry3d::query::{Ray, RayCast};
    let ray = Ray::new(Vector::from_array(origin), Vector::from_array(dir));
    mesh.cast_local_ray(&ray, max_m, true)
}
