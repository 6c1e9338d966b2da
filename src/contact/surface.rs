//! The accessible surface of an organ as the tool sees it: a BVH over its rest triangles for
//! closest-point queries, and smooth vertex normals so that the contact normal does not jump
//! when the tool crosses an edge.

use nalgebra::{Point3, Vector3};
use parry3d::query::PointQueryWithLocation;
use parry3d::shape::TriMesh;

use crate::pgd::{SurfacePoint, Vademecum};
use crate::seam::{from_parry, to_parry};

#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    #[error("the vademecum of {source_name} has no accessible triangles to touch")]
    NoSurface { source_name: String },
    #[error("the accessible surface of {source_name} cannot be indexed: {reason}")]
    Degenerate { source_name: String, reason: String },
}

/// The closest point of the accessible surface to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub at: SurfacePoint,
    /// Its rest position (m).
    pub point_m: Vector3<f64>,
    /// Outward unit normal, interpolated from the vertex normals.
    pub normal: Vector3<f64>,
}

pub struct ContactSurface {
    mesh: TriMesh,
    normals: Vec<Vector3<f64>>,
}

impl ContactSurface {
    /// The accessible surface of `vademecum` at rest.
    pub fn new(vademecum: &Vademecum) -> Result<Self, ContactError> {
        let source_name = vademecum.header.source.clone();
        if vademecum.triangles.is_empty() {
            return Err(ContactError::NoSurface { source_name });
        }
        let normals = vademecum.rest_normals();
        let vertices = vademecum
            .position_coords_m
            .iter()
            .map(|p| to_parry(&Point3::from(p.map(f64::from))))
            .collect();
        let mesh = TriMesh::new(vertices, vademecum.triangles.clone()).map_err(|e| {
            ContactError::Degenerate {
                source_name,
                reason: e.to_string(),
            }
        })?;
        Ok(Self { mesh, normals })
    }

    /// The closest surface point to `query_m`, or none for a non-finite query.
    pub fn closest(&self, query_m: &Vector3<f64>) -> Option<SurfaceHit> {
        if !query_m.iter().all(|c| c.is_finite()) {
            return None;
        }
        let (projection, (triangle, location)) = self
            .mesh
            .project_local_point_and_get_location(to_parry(&Point3::from(*query_m)), false);
        let barycentric = location.barycentric_coordinates()?.map(f64::from);
        let corners = self.mesh.indices()[triangle as usize];
        let normal = corners
            .iter()
            .zip(barycentric)
            .map(|(&v, l)| self.normals[v as usize] * l)
            .sum::<Vector3<f64>>()
            .try_normalize(0.0)?;
        Some(SurfaceHit {
            at: SurfacePoint {
                triangle: triangle as usize,
                barycentric,
            },
            point_m: from_parry(projection.point).coords,
            normal,
        })
    }
}
