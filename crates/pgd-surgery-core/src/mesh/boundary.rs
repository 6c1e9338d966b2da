//! The boundary surface of a tetrahedral mesh, with maps between surface and volume numbering.
//!
//! The surface is what the tool touches, what is rendered and what carries the pointshell, so
//! every later layer needs to go from a surface vertex to its volume node and back.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};

use super::TetMesh;

/// Marks a volume node that is not on the surface in [`Surface::surface_index_of`].
pub const NOT_ON_SURFACE: usize = usize::MAX;

/// The outward-oriented boundary triangles of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Triangles in volume node numbering, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// For each triangle, the tetrahedron it bounds.
    pub triangle_tet: Vec<usize>,
    /// Surface vertex → volume node, ascending.
    pub nodes: Vec<usize>,
    /// Volume node → surface vertex, or [`NOT_ON_SURFACE`].
    pub surface_index_of: Vec<usize>,
}

/// The faces of a positively oriented tet `[a, b, c, d]`, each ordered so its right-hand normal
/// points away from the opposite vertex.
const OUTWARD_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

impl Surface {
    /// Extracts the faces that belong to exactly one tetrahedron.
    pub fn extract(mesh: &TetMesh) -> Self {
        let mut owners: HashMap<[usize; 3], (usize, [usize; 3], u8)> =
            HashMap::with_capacity(mesh.tet_count() * 2);
        for (t, tet) in mesh.tets().iter().enumerate() {
            for local in OUTWARD_FACES {
                let face = local.map(|i| tet[i]);
                let entry = owners.entry(sorted(face)).or_insert((t, face, 0));
                entry.2 += 1;
            }
        }
        let mut boundary: Vec<(usize, [usize; 3])> = owners
            .into_values()
            .filter(|&(_, _, count)| count == 1)
            .map(|(t, face, _)| (t, face))
            .collect();
        // Deterministic order, independent of the hash map's.
        boundary.sort_unstable_by_key(|&(t, face)| (t, sorted(face)));

        let mut surface_index_of = vec![NOT_ON_SURFACE; mesh.node_count()];
        for &(_, face) in &boundary {
            for n in face {
                surface_index_of[n] = 0;
            }
        }
        let mut nodes = Vec::new();
        for (n, slot) in surface_index_of.iter_mut().enumerate() {
            if *slot != NOT_ON_SURFACE {
                *slot = nodes.len();
                nodes.push(n);
            }
        }
        Self {
            triangles: boundary.iter().map(|&(_, f)| f).collect(),
            triangle_tet: boundary.iter().map(|&(t, _)| t).collect(),
            nodes,
            surface_index_of,
        }
    }

    /// Triangles in surface vertex numbering, for rendering and surface-only algorithms.
    pub fn local_triangles(&self) -> Vec<[usize; 3]> {
        self.triangles
            .iter()
            .map(|f| f.map(|n| self.surface_index_of[n]))
            .collect()
    }

    /// Total area in m².
    pub fn area(&self, mesh: &TetMesh) -> f64 {
        self.triangles
            .iter()
            .map(|f| area_vector(mesh.nodes(), f).norm())
            .sum()
    }

    /// Unit outward normal per surface vertex (area-weighted over its triangles).
    pub fn vertex_normals(&self, mesh: &TetMesh) -> Vec<Vector3<f64>> {
        let coords: Vec<[f64; 3]> = self.nodes.iter().map(|&n| mesh.nodes()[n].into()).collect();
        vertex_normals(&self.local_triangles(), &coords)
            .into_iter()
            .map(Vector3::from)
            .collect()
    }

    /// Lumped area per surface vertex (a third of each adjacent triangle), in m².
    pub fn vertex_areas(&self, mesh: &TetMesh) -> Vec<f64> {
        let mut areas = vec![0.0; self.nodes.len()];
        for f in &self.triangles {
            let third = area_vector(mesh.nodes(), f).norm() / 3.0;
            for n in f {
                areas[self.surface_index_of[*n]] += third;
            }
        }
        areas
    }
}

/// Area-weighted vertex normals of a triangle soup, for shading a deformed surface: summing
/// the unnormalized face normals weights each face by its area, so slivers do not tilt the
/// result. `triangles` index `positions`; a vertex in no triangle gets a zero normal.
pub fn vertex_normals<T: nalgebra::RealField + Copy>(
    triangles: &[[usize; 3]],
    positions: &[[T; 3]],
) -> Vec<[T; 3]> {
    let mut normals = vec![Vector3::<T>::zeros(); positions.len()];
    for f in triangles {
        let [a, b, c] = f.map(|i| Vector3::from(positions[i]));
        let n = (b - a).cross(&(c - a));
        for &i in f {
            normals[i] += n;
        }
    }
    normals
        .into_iter()
        .map(|n| {
            n.try_normalize(T::zero())
                .unwrap_or_else(Vector3::zeros)
                .into()
        })
        .collect()
}

/// `½ (b − a) × (c − a)`: the outward normal scaled by the triangle's area.
pub fn area_vector(nodes: &[Point3<f64>], f: &[usize; 3]) -> Vector3<f64> {
    let (a, b, c) = (nodes[f[0]], nodes[f[1]], nodes[f[2]]);
    (b - a).cross(&(c - a)) * 0.5
}

fn sorted(mut face: [usize; 3]) -> [usize; 3] {
    face.sort_unstable();
    face
}
