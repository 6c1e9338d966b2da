//! Whether a closed surface crosses itself, before it is tetrahedralized: stuffing reads the
//! surface as an inside test, which a surface crossing itself answers wrongly where it
//! crosses. Each triangle is tested against those whose bounding boxes meet its own (parry's
//! bounding-volume tree) and that share no vertex with it. A crossing is not mended (which
//! side is meant is not known): the surface is refused with the two triangles and where.

use nalgebra::Point3;
use parry3d::math::{Pose, Vector};
use parry3d::shape::Triangle;

use super::surface::SurfaceMesh;
use crate::parry_interop::trimesh;

/// Two triangles of a surface that cross, and a point near where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub triangles: [usize; 2],
    pub near_m: Point3<f64>,
}

/// The first crossing of `surface` with itself (the lowest-numbered triangles), and how many
/// pairs of triangles cross; `None` where it does not cross itself.
pub fn self_crossing(surface: &SurfaceMesh) -> Option<(Crossing, usize)> {
    let positions: Vec<[f32; 3]> = (surface.vertices.iter())
        .map(|p| p.coords.map(|c| c as f32).into())
        .collect();
    let triangles: Vec<[u32; 3]> = (surface.triangles.iter())
        .map(|t| t.map(|v| v as u32))
        .collect();
    let mesh = trimesh(&positions, &triangles)?;
    let triangle = |k: usize| {
        let [a, b, c] = triangles[k].map(|v| Vector::from_array(positions[v as usize]));
        Triangle::new(a, b, c)
    };
    let mut first: Option<Crossing> = None;
    let mut count = 0;
    for (i, corners) in surface.triangles.iter().enumerate() {
        let a = triangle(i);
        let aabb = a.local_aabb();
        for j in mesh.bvh().intersect_aabb(&aabb).map(|j| j as usize) {
            let shares_vertex = surface.triangles[j].iter().any(|v| corners.contains(v));
            if j <= i || shares_vertex {
                continue;
            }
            let b = triangle(j);
            let crossing =
                parry3d::query::intersection_test(&Pose::IDENTITY, &a, &Pose::IDENTITY, &b)
                    .is_ok_and(|test| test.intersecting);
            if crossing {
                count += 1;
                first.get_or_insert_with(|| Crossing {
                    triangles: [i, j],
                    near_m: centre(surface, i, j),
                });
            }
        }
    }
    first.map(|crossing| (crossing, count))
}

/// The centre of two triangles' centres.
fn centre(surface: &SurfaceMesh, i: usize, j: usize) -> Point3<f64> {
    let sum = [i, j]
        .iter()
        .flat_map(|&k| surface.triangles[k])
        .map(|v| surface.vertices[v].coords)
        .sum::<nalgebra::Vector3<f64>>();
    Point3::from(sum / 6.0)
}
