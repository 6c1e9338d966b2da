//! A pointshell: the points of one organ's surface that probe the master's distance field
//! (its boundary nodes, denser or sparser), with what the contact stage needs of each,
//! gathered once (rest position and distance, area, the organ's modes there, and the master
//! position that takes the reaction). Everywhere below, "node" means a point of the pointshell.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::modal_rows::ModalRows;
use super::{ContactSurface, DistanceField};
use crate::pgd::Vademecum;

/// Nodes per block: the pointshell's nodes, nearest the master first, are taken in blocks
/// this long wherever a tick passes over many of them at once (the clearance's wakes, the
/// dimples' readers): small enough that a block holding a node to measure costs little to
/// scan, large enough that the blocks are few.
pub(super) const BLOCK: usize = 64;

/// The nodes are kept in order of their rest distance to the master, nearest first: those
/// that can touch this tick are a leading run (found with one binary search), and the
/// contact's per-node arrays are read in runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Pointshell {
    /// The shell organ's load positions each node blends, with their weights (a boundary
    /// node: itself alone; a triangle's centre: its corners): where its force is shared.
    pub blends: Vec<Vec<(usize, f64)>>,
    pub rest_m: Vec<Vector3<f32>>,
    /// The master's rest distance at each node (m), from the lattice.
    pub rest_distance_m: Vec<f32>,
    /// The rest field's outward direction at each node: the direction its penalty pushes
    /// and `A` is projected on, fixed so that the two agree (read each tick where the
    /// master's displacement brought the node from, it tilted up to about 10° from `A`'s,
    /// and the sideways part of the force sent the tool-held gallbladder 13 mm into the liver).
    pub rest_normal: Vec<Vector3<f64>>,
    /// Lumped surface area of each node (m²): what it covers of the surface, summed into the
    /// area in contact.
    pub area_m2: Vec<f32>,
    /// The shell organ's displacement modes at each node (its load modes, needed only along
    /// the node's normal, are kept by the pair's compliance).
    pub displacement: ModalRows,
    /// The master position nearest each node at rest: where the reaction goes.
    pub master_positions: Vec<u32>,
    /// Per shell mode, the largest displacement of any node.
    pub mode_bounds: Vec<f32>,
}

/// How densely a pointshell samples its organ's surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum PointshellDensity {
    /// The accessible load positions (the boundary nodes).
    #[default]
    Nodes,
    /// The positions and the centre of every accessible triangle: about three times as many
    /// points, so that contact is felt between nodes and more nodes push at once.
    Dense,
    /// Every accessible triangle cut into `n²` equal triangles (`n` along each edge), one point
    /// at each one's centre: as fine as asked, each point blending its triangle's corners.
    Subdivided(u8),
    /// The boundary nodes thinned to at least this many millimetres apart, each node kept
    /// taking the area of those left out nearest it, so that the surface is still covered
    /// once: fewer points where the mesh is finer than the contact needs.
    Sparse(u8),
}

impl PointshellDensity {
    /// Itself where its count is within range, or what is wrong with it: the one check the
    /// scenario and the command line share.
    pub fn check(self) -> Result<Self, String> {
        match self {
            Self::Subdivided(n) => check_subdivisions(n).map(Self::Subdivided),
            Self::Sparse(mm) => check_spacing(mm).map(Self::Sparse),
            Self::Nodes | Self::Dense => Ok(self),
        }
    }
}

/// How many times a [`PointshellDensity::Subdivided`] pointshell may cut each edge: 8 gives
/// 64 points a triangle, some 50 per node of the surface.
pub const SUBDIVISIONS: std::ops::RangeInclusive<u8> = 1..=8;

/// How far apart (mm) a [`PointshellDensity::Sparse`] pointshell may keep its nodes: at 1 mm
/// it keeps every node of these meshes, at 50 mm a few per organ.
pub const SPARSE_SPACINGS_MM: std::ops::RangeInclusive<u8> = 1..=50;

/// `mm` itself where a [`PointshellDensity::Sparse`] pointshell may keep its nodes `mm`
/// millimetres apart, or what is wrong with it.
pub fn check_spacing(mm: u8) -> Result<u8, String> {
    match SPARSE_SPACINGS_MM.contains(&mm) {
        true => Ok(mm),
        false => Err(format!(
            "nodes kept {mm} mm apart: keep them {} to {} mm apart",
            SPARSE_SPACINGS_MM.start(),
            SPARSE_SPACINGS_MM.end()
        )),
    }
}

/// `n` itself where a [`PointshellDensity::Subdivided`] pointshell may cut each edge `n`
/// times, or what is wrong with it.
pub fn check_subdivisions(n: u8) -> Result<u8, String> {
    match SUBDIVISIONS.contains(&n) {
        true => Ok(n),
        false => Err(format!(
            "a triangle cut {n} times along each edge: cut it {} to {} times (n² points a triangle)",
            SUBDIVISIONS.start(),
            SUBDIVISIONS.end()
        )),
    }
}

/// A candidate point: where it is at rest, and the positions it blends.
#[derive(Clone)]
struct Candidate {
    rest_m: Vector3<f64>,
    blend: Vec<(usize, f64)>,
    area_m2: f64,
}

impl Pointshell {
    /// The points of `shell` inside the master's lattice, at `density`: those that can meet
    /// the master at all.
    pub fn new(
        shell: &Vademecum,
        master: &Vademecum,
        master_surface: &ContactSurface,
        field: &DistanceField,
        density: PointshellDensity,
    ) -> Self {
        let mut inside: Vec<(Candidate, f64, Vector3<f64>)> = candidates(shell, density)
            .into_iter()
            .filter_map(|c| {
                let sample = field.at_rest(&c.rest_m)?;
                Some((c, sample.distance_m, sample.normal))
            })
            .collect();
        inside.sort_by(|a, b| a.1.total_cmp(&b.1));
        let rest_m: Vec<Vector3<f32>> = inside
            .iter()
            .map(|n| n.0.rest_m.map(|c| c as f32))
            .collect();
        let master_positions: Vec<u32> = inside
            .iter()
            .map(|n| nearest_corner(master, master_surface, &n.0.rest_m))
            .collect();
        let displacement = ModalRows::displacements(shell, inside.iter().map(|n| &n.0.blend));
        Self {
            blends: inside.iter().map(|n| n.0.blend.clone()).collect(),
            rest_distance_m: inside.iter().map(|n| n.1 as f32).collect(),
            rest_normal: inside.iter().map(|n| n.2).collect(),
            area_m2: inside.iter().map(|n| n.0.area_m2 as f32).collect(),
            mode_bounds: displacement.bounds(),
            displacement,
            rest_m,
            master_positions,
        }
    }

    pub fn len(&self) -> usize {
        self.blends.len()
    }

    pub fn is_empty(&self) -> bool {
        self.blends.is_empty()
    }

    /// The shell organ's load position that weighs most in node `i` (the node itself, or a
    /// corner of the triangle it lies in): where its load steps are read.
    pub fn position(&self, i: usize) -> usize {
        dominant(&self.blends[i])
    }

    /// The master position that takes node `i`'s reaction, as a blend.
    pub fn master_blend(&self, i: usize) -> [(usize, f64); 1] {
        master_blend(self.master_positions[i])
    }

    /// `Σ_k |α_k| max|X^k|`: no node moves farther than this (m).
    pub fn movement_bound_m(&self, alpha: &[f32]) -> f32 {
        super::modal_rows::movement_bound(alpha, &self.mode_bounds)
    }
}

/// The points a pointshell at `density` may take from `shell`: each accessible position with
/// its lumped area, and (dense) each accessible triangle's centre, which then takes half the
/// triangle's area from its corners, so that the whole surface is covered once; subdivided,
/// the centres of each triangle's pieces alone; sparse, the positions thinned.
fn candidates(shell: &Vademecum, density: PointshellDensity) -> Vec<Candidate> {
    let at = |m: usize| Vector3::from(shell.position_coords_m[m].map(f64::from));
    if let PointshellDensity::Subdivided(n) = density {
        return shell
            .triangles
            .iter()
            .flat_map(|t| subdivided(t.map(|m| m as usize), at, n.max(1)))
            .collect();
    }
    let mut points: Vec<Candidate> = (0..shell.positions.len())
        .map(|m| Candidate {
            rest_m: at(m),
            blend: vec![(m, 1.0)],
            area_m2: shell.position_areas_m2[m] as f64,
        })
        .collect();
    if let PointshellDensity::Sparse(mm) = density {
        return thinned(points, f64::from(mm) * 1e-3);
    }
    if density == PointshellDensity::Dense {
        for triangle in &shell.triangles {
            let [a, b, c] = triangle.map(|m| m as usize);
            let area_m2 = 0.5 * (at(b) - at(a)).cross(&(at(c) - at(a))).norm();
            for m in [a, b, c] {
                points[m].area_m2 -= area_m2 / 6.0;
            }
            points.push(Candidate {
                rest_m: (at(a) + at(b) + at(c)) / 3.0,
                blend: [a, b, c].map(|m| (m, 1.0 / 3.0)).to_vec(),
                area_m2: area_m2 / 2.0,
            });
        }
    }
    points
}

/// The points, in order, that lie at least `spacing_m` from every point kept before them;
/// each point left out gives its area to the nearest point kept, which lies within
/// `spacing_m` of it. Neighbours are looked up in a grid of `spacing_m` cells.
fn thinned(points: Vec<Candidate>, spacing_m: f64) -> Vec<Candidate> {
    let mut grid = SpacingGrid::new(spacing_m);
    let mut kept: Vec<Candidate> = Vec::new();
    let mut left_out = Vec::new();
    for point in points {
        match grid.nearest(&kept, &point.rest_m) {
            Some(_) => left_out.push(point),
            None => {
                grid.insert(&point.rest_m, kept.len());
                kept.push(point);
            }
        }
    }
    for point in left_out {
        let k = grid
            .nearest(&kept, &point.rest_m)
            .expect("a point was left out for a kept one within the spacing");
        kept[k].area_m2 += point.area_m2;
    }
    kept
}

/// Kept points by cell of a cubic grid as wide as the spacing: the points within the
/// spacing of any point lie in its cell or the 26 around it.
struct SpacingGrid {
    spacing_m: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<usize>>,
}

impl SpacingGrid {
    fn new(spacing_m: f64) -> Self {
        Self {
            spacing_m,
            cells: std::collections::HashMap::new(),
        }
    }

    fn cell(&self, p: &Vector3<f64>) -> [i64; 3] {
        [0, 1, 2].map(|c| (p[c] / self.spacing_m).floor() as i64)
    }

    fn insert(&mut self, p: &Vector3<f64>, index: usize) {
        self.cells.entry(self.cell(p)).or_default().push(index);
    }

    /// The kept point nearest `p` closer than the spacing, if any.
    fn nearest(&self, kept: &[Candidate], p: &Vector3<f64>) -> Option<usize> {
        let [x, y, z] = self.cell(p);
        let around = (-1..=1)
            .flat_map(|i| (-1..=1).flat_map(move |j| (-1..=1).map(move |k| [x + i, y + j, z + k])));
        around
            .filter_map(|cell| self.cells.get(&cell))
            .flatten()
            .map(|&k| (k, (kept[k].rest_m - p).norm()))
            .filter(|&(_, d)| d < self.spacing_m)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(k, _)| k)
    }
}

/// The centres of the `n²` triangles that cut triangle `corners` `n` times along each edge:
/// per row `i` of the cut, `n − i` triangles pointing like the whole and `n − i − 1` turned
/// over, each a `1/n²` of its area.
fn subdivided(
    corners: [usize; 3],
    at: impl Fn(usize) -> Vector3<f64>,
    n: u8,
) -> impl Iterator<Item = Candidate> {
    let [a, b, c] = corners;
    let (pa, pb, pc) = (at(a), at(b), at(c));
    let cuts = f64::from(n);
    let area_m2 = 0.5 * (pb - pa).cross(&(pc - pa)).norm() / cuts.powi(2);
    let upright = (0..n).flat_map(move |i| (0..n - i).map(move |j| (i, j, 1.0)));
    let turned = (0..n).flat_map(move |i| (0..n - i - 1).map(move |j| (i, j, 2.0)));
    upright.chain(turned).map(move |(i, j, thirds)| {
        // The centre's barycentric weights on `b` and `c`.
        let along = |k: u8| (f64::from(k) + thirds / 3.0) / cuts;
        let (s, t) = (along(i), along(j));
        let weights = [1.0 - s - t, s, t];
        Candidate {
            rest_m: pa * weights[0] + pb * weights[1] + pc * weights[2],
            blend: vec![(a, weights[0]), (b, weights[1]), (c, weights[2])],
            area_m2,
        }
    })
}

/// The position that weighs most in `blend`: where a point's load steps are read.
fn dominant(blend: &[(usize, f64)]) -> usize {
    blend
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |&(m, _)| m)
}

/// Master position `m` alone, as a blend.
fn master_blend(m: u32) -> [(usize, f64); 1] {
    [(m as usize, 1.0)]
}

/// The master position nearest `p` on its rest surface: the corner of the closest triangle
/// with the largest barycentric weight.
fn nearest_corner(master: &Vademecum, surface: &ContactSurface, p: &Vector3<f64>) -> u32 {
    let hit = surface
        .closest(p)
        .expect("a finite point always has a closest surface point");
    let corners = master.triangles[hit.at.triangle];
    let best = (0..3)
        .max_by(|&a, &b| hit.at.barycentric[a].total_cmp(&hit.at.barycentric[b]))
        .expect("three corners");
    corners[best]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thinned, a grid of points 1 mm apart keeps points no two closer than the spacing,
    /// leaves none out farther than the spacing from a kept one, and keeps the area whole.
    /// Brute force over every pair is the reference the grid's lookups are checked against.
    #[test]
    fn a_thinned_pointshell_keeps_points_apart_and_the_area_whole() {
        let grid: Vec<Candidate> = (0..15)
            .flat_map(|i| (0..12).map(move |j| (i, j)))
            .map(|(i, j)| Candidate {
                rest_m: Vector3::new(i as f64, j as f64, 0.1 * (i * j) as f64) * 1e-3,
                blend: vec![(i * 12 + j, 1.0)],
                area_m2: 1e-6 * (1.0 + (i + j) as f64 / 10.0),
            })
            .collect();
        let whole_m2: f64 = grid.iter().map(|p| p.area_m2).sum();
        for spacing_mm in [0.5, 1.5, 3.0, 7.0] {
            let spacing_m = spacing_mm * 1e-3;
            let rest: Vec<Vector3<f64>> = grid.iter().map(|p| p.rest_m).collect();
            let kept = thinned(grid.clone(), spacing_m);
            for (k, p) in kept.iter().enumerate() {
                for q in &kept[..k] {
                    assert!((p.rest_m - q.rest_m).norm() >= spacing_m, "{spacing_mm} mm");
                }
            }
            for r in &rest {
                let nearest = kept
                    .iter()
                    .map(|p| (p.rest_m - r).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(nearest < spacing_m, "{spacing_mm} mm: {r}");
            }
            let kept_m2: f64 = kept.iter().map(|p| p.area_m2).sum();
            assert!(
                (kept_m2 - whole_m2).abs() < 1e-12 * whole_m2,
                "{spacing_mm} mm"
            );
            match spacing_mm < 1.0 {
                true => assert_eq!(kept.len(), grid.len(), "points 1 mm apart are all kept"),
                false => assert!(kept.len() < grid.len(), "{spacing_mm} mm"),
            }
        }
    }

    /// Cut `n` times along each edge, a triangle gives `n²` points, each inside it with
    /// weights that sum to one and place it where it is, covering the triangle's area once,
    /// no two at the same place.
    #[test]
    fn a_subdivided_triangle_is_covered_once_by_points_inside_it() {
        let corners = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.03, 0.0, 0.0),
            Vector3::new(0.01, 0.02, 0.005),
        ];
        let whole_m2 = 0.5
            * (corners[1] - corners[0])
                .cross(&(corners[2] - corners[0]))
                .norm();
        for n in 1..=5u8 {
            let points: Vec<Candidate> = subdivided([0, 1, 2], |m| corners[m], n).collect();
            assert_eq!(points.len(), usize::from(n).pow(2), "n = {n}");
            let area_m2: f64 = points.iter().map(|p| p.area_m2).sum();
            assert!((area_m2 - whole_m2).abs() < 1e-12 * whole_m2, "n = {n}");
            for p in &points {
                let weights: f64 = p.blend.iter().map(|b| b.1).sum();
                assert!((weights - 1.0).abs() < 1e-12);
                assert!(p.blend.iter().all(|b| b.1 > 0.0), "inside: {:?}", p.blend);
                let at: Vector3<f64> = p.blend.iter().map(|&(m, w)| corners[m] * w).sum();
                assert!((at - p.rest_m).norm() < 1e-15);
            }
            for (k, p) in points.iter().enumerate() {
                assert!(
                    points[..k]
                        .iter()
                        .all(|q| (q.rest_m - p.rest_m).norm() > 1e-6),
                    "n = {n}: two points at {:?}",
                    p.rest_m
                );
            }
        }
    }
}
