//! Splitting convex polyhedra into tetrahedra so that neighbours agree on shared faces.

use nalgebra::Point3;

use super::{DEGENERATE_QUALITY, quality};

/// Splits a convex polyhedron, given by its faces as cyclic lists of global vertex indices
/// (triangles or quadrilaterals), into tetrahedra: its lowest-numbered vertex is joined to every
/// face that does not contain it, and each quadrilateral is split along the diagonal through its
/// own lowest-numbered vertex. That choice depends only on the face, so two polyhedra sharing a
/// quadrilateral split it the same way and the mesh stays conforming.
///
/// Tetrahedra are pushed positively oriented; flat ones (possible only where vertices coincide
/// or are coplanar by construction) are dropped.
pub fn pull(faces: &[&[usize]], points: &[Point3<f64>], out: &mut Vec<[usize; 4]>) {
    let apex = faces
        .iter()
        .flat_map(|f| f.iter())
        .copied()
        .min()
        .expect("a polyhedron has faces");
    for face in faces.iter().filter(|f| !f.contains(&apex)) {
        if face.len() == 3 {
            push_oriented([apex, face[0], face[1], face[2]], points, out);
        } else {
            let m = (0..4)
                .min_by_key(|&i| face[i])
                .expect("a quadrilateral has four corners");
            let q = |k: usize| face[(m + k) % 4];
            push_oriented([apex, q(0), q(1), q(2)], points, out);
            push_oriented([apex, q(0), q(2), q(3)], points, out);
        }
    }
}

/// Pushes a tetrahedron with positive orientation, or nothing if it is flat.
pub fn push_oriented(mut tet: [usize; 4], points: &[Point3<f64>], out: &mut Vec<[usize; 4]>) {
    let q = quality(&tet.map(|v| points[v]));
    if q.abs() < DEGENERATE_QUALITY {
        return;
    }
    if q < 0.0 {
        tet.swap(2, 3);
    }
    out.push(tet);
}
