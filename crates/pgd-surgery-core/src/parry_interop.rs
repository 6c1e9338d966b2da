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

/// Surfaces that may stand on a line of sight: organs at rest, as parry triangle meshes, each
/// with its organ's place in the scene.
#[derive(Clone, Default)]
pub struct SightBlockers(Vec<(usize, parry3d::shape::TriMesh)>);

impl SightBlockers {
    /// The surfaces of `meshes` (render positions and triangles each, in the scene's order);
    /// those parry refuses are left out.
    pub fn new<'a>(meshes: impl IntoIterator<Item = (&'a [[f32; 3]], &'a [[u32; 3]])>) -> Self {
        Self(
            (meshes.into_iter().enumerate())
                .filter_map(|(k, (positions, triangles))| Some((k, trimesh(positions, triangles)?)))
                .collect(),
        )
    }

    /// Whether a surface crosses the segment from `from_m` to `to_m`, leaving out its first
    /// `skip_m` (the surface the line starts on); each organ's surface moved from rest by its
    /// entry in `shifts_m` (none where the slice is short).
    pub fn block(
        &self,
        from_m: &nalgebra::Vector3<f64>,
        to_m: &nalgebra::Vector3<f64>,
        skip_m: f64,
        shifts_m: &[nalgebra::Vector3<f64>],
    ) -> bool {
        let towards = to_m - from_m;
        let length = towards.norm();
        if length <= skip_m {
            return false;
        }
        let dir = towards / length;
        let start = from_m + dir * skip_m;
        let as_f32 = |v: nalgebra::Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
        (self.0.iter()).any(|(organ, mesh)| {
            // The line moved back by the organ's shift meets the surface at rest.
            let shift = shifts_m.get(*organ).copied().unwrap_or_default();
            let origin = as_f32(start - shift);
            ray_distance(mesh, origin, as_f32(dir), (length - skip_m) as f32).is_some()
        })
    }
}
