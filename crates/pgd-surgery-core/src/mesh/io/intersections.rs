//! Whether a closed surface crosses itself, before it is tetrahedralized: stuffing reads the
//! surface as an inside test, which a surface crossing itself answers wrongly where it
//! crosses. Each triangle is tested against those whose bounding boxes meet its own (parry's
//! bounding-volume tree) and that share no vertex with it: two triangles cross where an edge
//! of one passes through the other, its ends strictly on either side of the other's plane
//! (in double precision; triangles that only touch, or lie in one plane, do not cross). A crossing is not mended (which side is meant is not known): the surface is
//! refused with the two triangles and where.

use nalgebra::Point3;
use parry3d::math::Vector;
use parry3d::shape::Triangle;

use crate::parry_interop::trimesh;

/// Two triangles of a surface that cross, and a point near where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub triangles: [usize; 2],
    pub near_m: Point3<f64>,
}

/// A surface as its vertices and its triangles' corners.
#[derive(Clone, Copy)]
pub struct Faces<'a> {
    pub vertices: &'a [Point3<f64>],
    pub triangles: &'a [[usize; 3]],
}

/// The first crossing of `surface` with itself (the lowest-numbered triangles), and how many
/// pairs of triangles cross; `None` where it does not cross itself.
pub fn self_crossing(surface: Faces<'_>) -> Option<(Crossing, usize)> {
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
        let aabb = triangle(i).local_aabb();
        for j in mesh.bvh().intersect_aabb(&aabb).map(|j| j as usize) {
            let shares_vertex = surface.triangles[j].iter().any(|v| corners.contains(v));
            if j <= i || shares_vertex {
                continue;
            }
            if cross(&corners_of(surface, i), &corners_of(surface, j)) {
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

fn corners_of(surface: Faces<'_>, k: usize) -> [Point3<f64>; 3] {
    surface.triangles[k].map(|v| surface.vertices[v])
}

/// Whether an edge of either triangle passes through the inside of the other.
fn cross(a: &[Point3<f64>; 3], b: &[Point3<f64>; 3]) -> bool {
    let edges = |t: &[Point3<f64>; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    (edges(a).iter()).any(|(p, q)| pierces(p, q, b))
        || (edges(b).iter()).any(|(p, q)| pierces(p, q, a))
}

/// Whether the segment from `p` to `q` passes through `t`: its ends strictly on either side
/// of `t`'s plane (beyond a billionth of `t`'s size, so that touching is not crossing), and
/// where it meets the plane inside `t` or on its edges (a surface crossed where two of its
/// triangles meet is crossed all the same).
fn pierces(p: &Point3<f64>, q: &Point3<f64>, t: &[Point3<f64>; 3]) -> bool {
    let normal = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let size = normal.norm();
    if size == 0.0 {
        return false;
    }
    let tolerance = 1e-9 * size.sqrt();
    let unit = normal / size;
    let (dp, dq) = (unit.dot(&(p - t[0])), unit.dot(&(q - t[0])));
    if !((dp > tolerance && dq < -tolerance) || (dp < -tolerance && dq > tolerance)) {
        return false;
    }
    let x = p + (q - p) * (dp / (dp - dq));
    // Each corner's side of the point: the same sign for all three edges, inside.
    let sides: [f64; 3] =
        std::array::from_fn(|k| (t[(k + 1) % 3] - t[k]).cross(&(x - t[k])).dot(&unit));
    let margin = tolerance * size.sqrt();
    sides.iter().all(|&s| s >= -margin) || sides.iter().all(|&s| s <= margin)
}

/// The centre of two triangles' centres.
fn centre(surface: Faces<'_>, i: usize, j: usize) -> Point3<f64> {
    let sum = [i, j]
        .iter()
        .flat_map(|&k| surface.triangles[k])
        .map(|v| surface.vertices[v].coords)
        .sum::<nalgebra::Vector3<f64>>();
    Point3::from(sum / 6.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    /// A triangle through another's inside, one whose edge passes through another's edge, one
    /// beside another in its plane (two corners in it, as neighbouring triangles of a fine
    /// surface are), and one above another.
    #[test]
    fn crossing_is_an_edge_through_the_other_triangle() {
        let flat = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0)];
        let through = [p(0.2, 0.2, -1.0), p(0.2, 0.2, 1.0), p(0.3, 0.3, 1.0)];
        assert!(cross(&flat, &through));
        let on_edge = [p(0.5, 0.0, -1.0), p(0.5, 0.0, 1.0), p(0.5, -1.0, 0.0)];
        assert!(cross(&flat, &on_edge));
        let beside = [p(1.0, 1.0, 0.0), p(2.0, 1.0, 0.0), p(1.5, 2.0, -0.5)];
        assert!(!cross(&flat, &beside));
        let above = [p(0.0, 0.0, 0.1), p(1.0, 0.0, 0.1), p(0.0, 1.0, 0.2)];
        assert!(!cross(&flat, &above));
    }
}
