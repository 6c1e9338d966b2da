//! A volume mesh with elements too poor to solve (slivers and needles: a dihedral angle
//! outside what is accepted; or of no volume) re-tetrahedralized from its own boundary
//! surface: the boundary mended ([`mend`]) and stuffed anew at the node count asked for
//! surfaces (`--nodes`), as a segmentation's surface is. Local improvement (moving nodes, flipping faces) keeps the
//! mesh's nodes but cannot promise to reach the accepted angles; meshing the boundary anew
//! does. The file's regions are carried over by where they lie on the surface: a new
//! boundary face takes the face sets of the old boundary face nearest its centre, a new
//! boundary node the node sets holding every corner of the old boundary face nearest it;
//! node sets' interior nodes are not carried over.

use std::collections::{HashMap, HashSet};

use nalgebra::Point3;
use parry3d::query::PointQueryWithLocation;

use super::mend::mend;
use super::surface::{SurfaceMesh, tetrahedralize};
use super::{ImportError, RawMesh, face_nodes};
use crate::mesh::{MeshDensity, QualityReport, Regions, Surface, TetMesh};
use crate::parry_interop::{to_parry, trimesh};

/// `raw` (its quality `before`) meshed anew from its boundary as finely as `density` asks,
/// with its regions carried over, and what was done in words (the quality before and after).
pub(super) fn remesh(
    file: &str,
    raw: RawMesh,
    before: &QualityReport,
    density: MeshDensity,
) -> Result<(RawMesh, String), ImportError> {
    let rest = TetMesh::new(
        file,
        raw.nodes.clone(),
        raw.tets.clone(),
        Regions::default(),
    )?;
    let boundary = Surface::extract(&rest).triangles;
    let (surface, _) =
        mend(surface_of(&raw.nodes, &boundary)).map_err(|reason| ImportError::Unusable {
            file: file.to_owned(),
            reason: format!("its boundary, to mesh it anew from, cannot be mended: {reason}"),
        })?;
    let mesh = tetrahedralize(file, surface, density)?;
    let after = QualityReport::measure(mesh.nodes(), mesh.tets());
    let new_boundary: Vec<[usize; 3]> = Surface::extract(&mesh).triangles;
    let old = OldBoundary::new(file, &raw, &boundary)?;
    let nodes = mesh.nodes().to_vec();
    let nearest_to_face: Vec<Option<[usize; 3]>> = (new_boundary.iter())
        .map(|face| old.nearest(&centre(&nodes, face)))
        .collect();
    let new_surface_nodes = face_nodes(&new_boundary);
    let nearest_to_node: Vec<Option<[usize; 3]>> = (new_surface_nodes.iter())
        .map(|&n| old.nearest(&nodes[n]))
        .collect();
    let mut remeshed = RawMesh {
        nodes,
        tets: mesh.tets().to_vec(),
        ..RawMesh::default()
    };
    for (name, faces) in &raw.face_sets {
        let set: HashSet<[usize; 3]> = faces.iter().map(|f| sorted(*f)).collect();
        let carried = (new_boundary.iter().zip(&nearest_to_face))
            .filter(|(_, old)| old.is_some_and(|f| set.contains(&sorted(f))))
            .map(|(face, _)| *face)
            .collect();
        remeshed.face_sets.insert(name.clone(), carried);
    }
    for (name, nodes) in &raw.node_sets {
        let set: HashSet<usize> = nodes.iter().copied().collect();
        let carried = (new_surface_nodes.iter().zip(&nearest_to_node))
            .filter(|(_, old)| old.is_some_and(|f| f.iter().all(|n| set.contains(n))))
            .map(|(&n, _)| n)
            .collect();
        remeshed.node_sets.insert(name.clone(), carried);
    }
    let said = format!(
        "{} tetrahedra with dihedral angles from {:.2}° to {:.2}° meshed anew from the boundary \
         surface: {} tetrahedra from {:.2}° to {:.2}°, regions carried over by where they lie \
         on the surface",
        before.tets,
        before.min_dihedral_deg,
        before.max_dihedral_deg,
        after.tets,
        after.min_dihedral_deg,
        after.max_dihedral_deg
    );
    Ok((remeshed, said))
}

/// `faces` of `nodes` as a surface of its own vertices.
fn surface_of(nodes: &[Point3<f64>], faces: &[[usize; 3]]) -> SurfaceMesh {
    let mut index: HashMap<usize, usize> = HashMap::new();
    let mut vertices = Vec::new();
    let triangles = (faces.iter())
        .map(|face| {
            face.map(|n| {
                *index.entry(n).or_insert_with(|| {
                    vertices.push(nodes[n]);
                    vertices.len() - 1
                })
            })
        })
        .collect();
    SurfaceMesh {
        vertices,
        triangles,
    }
}

/// The old mesh's boundary, to carry regions over from.
struct OldBoundary<'a> {
    faces: &'a [[usize; 3]],
    mesh: parry3d::shape::TriMesh,
}

impl<'a> OldBoundary<'a> {
    fn new(file: &str, raw: &RawMesh, faces: &'a [[usize; 3]]) -> Result<Self, ImportError> {
        let positions: Vec<[f32; 3]> = (raw.nodes.iter())
            .map(|p| p.coords.map(|c| c as f32).into())
            .collect();
        let triangles: Vec<[u32; 3]> = faces.iter().map(|f| f.map(|n| n as u32)).collect();
        let mesh = trimesh(&positions, &triangles).ok_or_else(|| ImportError::Unusable {
            file: file.to_owned(),
            reason: "its boundary surface could not be searched".into(),
        })?;
        Ok(Self { faces, mesh })
    }

    /// The boundary face nearest `p`.
    fn nearest(&self, p: &Point3<f64>) -> Option<[usize; 3]> {
        let (_, (face, _)) = self
            .mesh
            .project_local_point_and_get_location(to_parry(p), false);
        self.faces.get(face as usize).copied()
    }
}

fn centre(nodes: &[Point3<f64>], face: &[usize; 3]) -> Point3<f64> {
    Point3::from((nodes[face[0]].coords + nodes[face[1]].coords + nodes[face[2]].coords) / 3.0)
}

fn sorted(mut face: [usize; 3]) -> [usize; 3] {
    face.sort_unstable();
    face
}
