//! The accessible surface of an organ as the tool sees it: a BVH over its rest triangles for
//! closest-point queries, and smooth vertex normals so that the contact normal does not jump
//! when the tool crosses an edge.

use nalgebra::{Point3, Vector3};
use parry3d::query::PointQueryWithLocation;
use parry3d::shape::{TriMesh, TrianglePointLocation};

use crate::parry_interop::{from_parry, to_parry};
use crate::pgd::{SurfacePoint, Vademecum};

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
    /// Per vertex, the triangles around it (`vertex_triangles[offsets[v]..offsets[v + 1]]`):
    /// the neighbourhood a tracked contact point searches.
    offsets: Vec<u32>,
    vertex_triangles: Vec<u32>,
}

impl ContactSurface {
    /// The accessible surface of `vademecum` at rest.
    pub fn new(vademecum: &Vademecum) -> Result<Self, ContactError> {
        let source_name = vademecum.header.source.clone();
        if vademecum.triangles.is_empty() {
            return Err(ContactError::NoSurface { source_name });
        }
        let (coords, triangles) = (&vademecum.position_coords_m, vademecum.triangles.clone());
        Self::of_triangles(coords, triangles, vademecum.rest_normals()).map_err(|reason| {
            ContactError::Degenerate {
                source_name,
                reason,
            }
        })
    }

    /// A surface of vertices `coords_m` and `triangles` over them, with each vertex's outward
    /// unit normal; why not, if the triangles are degenerate.
    pub fn of_triangles(
        coords_m: &[[f32; 3]],
        triangles: Vec<[u32; 3]>,
        normals: Vec<Vector3<f64>>,
    ) -> Result<Self, String> {
        let vertices = coords_m
            .iter()
            .map(|p| to_parry(&Point3::from(p.map(f64::from))))
            .collect();
        let (offsets, vertex_triangles) = triangles_around(&triangles, coords_m.len());
        let mesh = TriMesh::new(vertices, triangles).map_err(|e| e.to_string())?;
        Ok(Self {
            mesh,
            normals,
            offsets,
            vertex_triangles,
        })
    }

    /// The surface point a contact at `previous` moves to for `query_m`: the closest point
    /// among the triangles around `previous`, unless another part of the surface
    /// is closer by more than `switch_m`. A point found globally jumps across a groove when its
    /// two sides are about as close (the tool's patch and force jump with it); tracked, it
    /// slides along the side it is on. Without `previous`, the closest point. The search for
    /// another part stops at the distance that would win, which prunes most of the tree (it
    /// was the tool's largest cost in the tick: four organs, twice each).
    pub fn tracked(
        &self,
        query_m: &Vector3<f64>,
        previous: Option<&SurfacePoint>,
        switch_m: f64,
    ) -> Option<SurfaceHit> {
        if !query_m.iter().all(|c| c.is_finite()) {
            return None;
        }
        let Some(local) = previous.and_then(|at| self.closest_around(query_m, at, switch_m)) else {
            return self.closest(query_m);
        };
        let wins_within_m = (local.point_m - query_m).norm() - switch_m;
        match self.closest_within(query_m, wins_within_m) {
            Some(global) if (global.point_m - query_m).norm() < wins_within_m => Some(global),
            _ => Some(local),
        }
    }

    /// The closest point to `query_m` within `reach_m` of `previous` on the triangles that
    /// share a corner with its triangle (a few shared ones are projected twice: cheaper than
    /// sorting them out).
    fn closest_around(
        &self,
        query_m: &Vector3<f64>,
        previous: &SurfacePoint,
        reach_m: f64,
    ) -> Option<SurfaceHit> {
        let triangle = previous.triangle;
        let vertices = self.mesh.vertices();
        let from = self.mesh.indices()[triangle]
            .iter()
            .zip(previous.barycentric)
            .map(|(&v, l)| from_parry(vertices[v as usize]).coords * l)
            .sum::<Vector3<f64>>();
        let around = self.mesh.indices()[triangle].into_iter().flat_map(|v| {
            let v = v as usize;
            &self.vertex_triangles[self.offsets[v] as usize..self.offsets[v + 1] as usize]
        });
        let query = to_parry(&Point3::from(*query_m));
        around
            .map(|&t| {
                let (projection, location) = self
                    .mesh
                    .triangle(t)
                    .project_local_point_and_get_location(query, false);
                ((projection.point - query).length(), t, projection, location)
            })
            .filter(|(_, _, projection, _)| {
                (from_parry(projection.point).coords - from).norm() <= reach_m
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .and_then(|(_, t, projection, location)| {
                self.hit(t, from_parry(projection.point).coords, location)
            })
    }

    /// The closest surface point to `query_m`, or none for a non-finite query.
    pub fn closest(&self, query_m: &Vector3<f64>) -> Option<SurfaceHit> {
        self.closest_within(query_m, f64::INFINITY)
    }

    /// The closest surface point to `query_m` if it lies within `max_m` of it.
    fn closest_within(&self, query_m: &Vector3<f64>, max_m: f64) -> Option<SurfaceHit> {
        if !query_m.iter().all(|c| c.is_finite()) || max_m <= 0.0 {
            return None;
        }
        let (projection, (triangle, location)) = self
            .mesh
            .project_local_point_and_get_location_with_max_dist(
                to_parry(&Point3::from(*query_m)),
                false,
                max_m.min(f32::MAX as f64) as f32,
            )?;
        self.hit(triangle, from_parry(projection.point).coords, location)
    }

    fn hit(
        &self,
        triangle: u32,
        point_m: Vector3<f64>,
        location: TrianglePointLocation,
    ) -> Option<SurfaceHit> {
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
            point_m,
            normal,
        })
    }
}

/// Per vertex, the triangles that use it, as offsets and a flat list.
fn triangles_around(triangles: &[[u32; 3]], vertices: usize) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; vertices + 1];
    for &v in triangles.iter().flatten() {
        offsets[v as usize + 1] += 1;
    }
    for v in 0..vertices {
        offsets[v + 1] += offsets[v];
    }
    let mut filled = offsets.clone();
    let mut list = vec![0u32; offsets[vertices] as usize];
    for (t, triangle) in triangles.iter().enumerate() {
        for &v in triangle {
            list[filled[v as usize] as usize] = t as u32;
            filled[v as usize] += 1;
        }
    }
    (offsets, list)
}
