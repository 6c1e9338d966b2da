//! A cut organ as drawn: its surface split along the cut, each lip moved with its own side of
//! the cut's faces and opened by the cut's enriched amplitudes under the tool's load, and the
//! walls of the cut drawn as the tissue inside. From the cut view the worker publishes
//! (`docs/cutting.md`, "The incision on screen").

use std::collections::HashMap;
use std::sync::Arc;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use nalgebra::{Point3, Vector3};

use crate::cutting::CutView;
use crate::pgd::{PatchLoad, Vademecum};

/// An organ's surface split by the cut of `view`.
pub(super) struct SplitSurface {
    view: Arc<CutView>,
    /// Per copy (vertex `vertices + k`): the vertex it copies and the enriched function
    /// whose other side it stands on.
    copies: Vec<(usize, usize)>,
    /// The surface's triangles, those across a face from an enriched vertex taking its copy.
    pub(super) triangles: Vec<[usize; 3]>,
    /// The lips: each edge split by the cut, on its own side and across.
    walls: Vec<Wall>,
}

/// One split edge: its ends on the vertices' own side, their copies across, and at each end
/// the way into the tissue along the face times the face's depth (m).
struct Wall {
    own: [usize; 2],
    across: [usize; 2],
    down_m: [Vector3<f64>; 2],
}

impl SplitSurface {
    /// `triangles` (over the vademecum's surface vertices) split by `view`'s cut.
    pub(super) fn new(view: Arc<CutView>, vademecum: &Vademecum, triangles: &[[usize; 3]]) -> Self {
        let mut split = Self {
            view,
            copies: Vec::new(),
            triangles: Vec::with_capacity(triangles.len()),
            walls: Vec::new(),
        };
        let functions_at = split.functions_at(vademecum);
        let mut copy_of: HashMap<(usize, usize), usize> = HashMap::new();
        let vertices = vademecum.positions.len();
        for triangle in triangles {
            let rest = triangle.map(|v| rest_point(vademecum, v));
            let mut split_triangle = *triangle;
            let mut across = [None; 3];
            for (corner, &v) in triangle.iter().enumerate() {
                let Some(j) = split.across_function(&functions_at, v, &rest) else {
                    continue;
                };
                let next = vertices + copy_of.len();
                let copy = *copy_of.entry((v, j)).or_insert(next);
                if copy == next {
                    split.copies.push((v, j));
                }
                split_triangle[corner] = copy;
                across[corner] = Some(j);
            }
            split.add_walls(triangle, &split_triangle, &across, &rest);
            split.triangles.push(split_triangle);
        }
        split
    }

    /// Whether this split is of `view`.
    pub(super) fn is_of(&self, view: &Arc<CutView>) -> bool {
        Arc::ptr_eq(&self.view, view)
    }

    /// Each split vertex with its copy (vertex numbers of the split surface, whose first
    /// `vertices` are the surface's own).
    pub(super) fn lips(&self, vertices: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.copies
            .iter()
            .enumerate()
            .map(move |(k, &(v, _))| (v, vertices + k))
    }

    /// The copies' rest positions, after the vertices' own (`rest`).
    pub(super) fn with_copies(&self, rest: &[[f32; 3]]) -> Vec<[f32; 3]> {
        let copies = self.copies.iter().map(|&(v, _)| rest[v]);
        rest.iter().copied().chain(copies).collect()
    }

    /// Moves `positions` (the uncut organ deformed under `loads`, every hand's, one per
    /// surface vertex) as the cut organ deforms on each vertex's own side, and appends the
    /// copies, opened: the cut answers the loads together (one hand's traction opens the cut
    /// the other hand's blade made).
    pub(super) fn displace(
        &self,
        vademecum: &Vademecum,
        loads: &[PatchLoad],
        positions: &mut Vec<[f32; 3]>,
    ) {
        let view = &self.view;
        let node = |m: usize| vademecum.positions[m] as usize;
        let nodal: Vec<(usize, f64)> = (loads.iter())
            .flat_map(|load| {
                (load.shares.iter()).flat_map(move |&(m, share)| {
                    (0..3).map(move |c| (3 * node(m) + c, share * load.force_n[c]))
                })
            })
            .collect();
        let answer = view.answer(&nodal);
        for (k, position) in positions.iter_mut().enumerate() {
            let added = view.added_displacement(node(k), &answer);
            *position = add(*position, &added);
        }
        for &(v, j) in &self.copies {
            positions.push(add(positions[v], &view.opening(j, &answer)));
        }
    }

    /// The walls of the cut over the split surface's `positions`: from each lip's edge down
    /// to the cut's bottom, midway between the lips, as triangles (positions, indices).
    pub(super) fn walls(&self, positions: &[[f32; 3]]) -> (Vec<[f32; 3]>, Vec<u32>) {
        let mut points = Vec::with_capacity(6 * self.walls.len());
        let mut indices = Vec::with_capacity(12 * self.walls.len());
        for wall in &self.walls {
            let at = |v: usize| Vector3::from(positions[v]).cast::<f64>();
            let bottom =
                |end: usize| (at(wall.own[end]) + at(wall.across[end])) / 2.0 + wall.down_m[end];
            let base = points.len() as u32;
            for v in wall.own.iter().chain(&wall.across) {
                points.push(positions[*v]);
            }
            points.extend([bottom(0), bottom(1)].map(|b| -> [f32; 3] { b.cast::<f32>().into() }));
            // Own lip: own 0, own 1, bottom 1, bottom 0; across: the same with the copies.
            for [a, b] in [[0, 1], [2, 3]] {
                indices.extend([a, b, 5, a, 5, 4].map(|i| base + i));
            }
        }
        (points, indices)
    }

    /// Per surface vertex, the enriched functions of its node (indices into the view's).
    fn functions_at(&self, vademecum: &Vademecum) -> Vec<Vec<usize>> {
        let vertex_of: HashMap<usize, usize> = vademecum
            .positions
            .iter()
            .enumerate()
            .map(|(k, &node)| (node as usize, k))
            .collect();
        let mut at = vec![Vec::new(); vademecum.positions.len()];
        for (j, f) in self.view.functions.iter().enumerate() {
            if let Some(&k) = vertex_of.get(&f.node) {
                at[k].push(j);
            }
        }
        at
    }

    /// The first enriched function of vertex `v` whose face the triangle with corners at
    /// `rest` lies across from `v`'s node, within the face.
    fn across_function(
        &self,
        functions_at: &[Vec<usize>],
        v: usize,
        rest: &[Point3<f64>; 3],
    ) -> Option<usize> {
        let centroid = Point3::from((rest[0].coords + rest[1].coords + rest[2].coords) / 3.0);
        let size_m = (0..3)
            .map(|k| (rest[k] - rest[(k + 1) % 3]).norm())
            .fold(0.0, f64::max);
        functions_at[v].iter().copied().find(|&j| {
            let f = &self.view.functions[j];
            let face = &self.view.faces[f.face];
            let side = if face.signed_distance(&centroid) >= 0.0 {
                1
            } else {
                -1
            };
            side != f.node_side && face.covers(&centroid, size_m)
        })
    }

    /// The walls of the edges of `triangle` whose two ends both went across the same face.
    fn add_walls(
        &mut self,
        triangle: &[usize; 3],
        split: &[usize; 3],
        across: &[Option<usize>; 3],
        rest: &[Point3<f64>; 3],
    ) {
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (Some(ja), Some(jb)) = (across[a], across[b]) else {
                continue;
            };
            let face = self.view.functions[ja].face;
            if self.view.functions[jb].face != face {
                continue;
            }
            let down = |end: usize| {
                let (inward, depth_m) = self.view.faces[face].inward_at(&rest[end]);
                inward.into_inner() * depth_m
            };
            self.walls.push(Wall {
                own: [triangle[a], triangle[b]],
                across: [split[a], split[b]],
                down_m: [down(a), down(b)],
            });
        }
    }
}

fn rest_point(vademecum: &Vademecum, v: usize) -> Point3<f64> {
    Point3::from(Vector3::from(vademecum.position_coords_m[v]).cast::<f64>())
}

fn add(position: [f32; 3], by_m: &Vector3<f64>) -> [f32; 3] {
    (Vector3::from(position) + by_m.cast::<f32>()).into()
}

/// The walls' render mesh. No walls are one degenerate triangle, which draws nothing: Bevy
/// allocates no GPU room for a mesh without vertices, and then logs an error at each of its
/// uploads.
pub(super) fn walls_mesh(mut points: Vec<[f32; 3]>, mut indices: Vec<u32>) -> Mesh {
    if points.is_empty() || indices.is_empty() {
        points = vec![[0.0; 3]; 3];
        indices = vec![0, 1, 2];
    }
    let triangles: Vec<[usize; 3]> = indices
        .chunks_exact(3)
        .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
        .collect();
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_NORMAL,
        crate::mesh::vertex_normals(&triangles, &points),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, points)
    .with_inserted_indices(Indices::U32(indices))
}
