//! Isosurface stuffing: tetrahedralizes the inside of an implicit solid on a body-centred
//! cubic (BCC) lattice (after Labelle & Shewchuk, SIGGRAPH 2007).
//!
//! The BCC lattice is a cubic grid plus the cube centres; its tetrahedra are all congruent and
//! well shaped. Lattice vertices that lie too close to the surface along an edge are *warped*
//! onto it, which removes the slivers that clipping would otherwise create; the remaining
//! lattice tetrahedra are clipped by the surface and the clipped pieces split into tetrahedra.
//! Pieces with quadrilateral faces are split by [`split::pull`], which gives neighbouring pieces
//! the same diagonal on a shared face, so the mesh is conforming.
//! The method is pure Rust and permissively licensed; it needs only the sign of the implicit
//! function, so any continuous function that is negative inside works, not just true distances.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Point3, Vector3};

use super::{MeshError, Regions, TetMesh, split};

/// Warp thresholds, as a fraction of the edge length from the vertex: a vertex closer than this
/// to a cut point on one of its edges is moved onto the surface. Labelle & Shewchuk's values for
/// the long (axis-aligned, length h) and short (centre-to-corner, length √3/2 h) lattice edges.
const ALPHA_LONG: f64 = 0.24999;
const ALPHA_SHORT: f64 = 0.41189;

/// Bisection steps for a cut point: 2⁻⁴⁰ of an edge is far below round-off of the mesh scale.
const CUT_ITERATIONS: usize = 40;

/// An implicit solid: `value` is negative inside, positive outside; `min`/`max` bound the solid.
pub struct Implicit<'a> {
    pub value: &'a dyn Fn(&Point3<f64>) -> f64,
    pub min: Point3<f64>,
    pub max: Point3<f64>,
}

/// Tetrahedralizes `solid` with lattice spacing `spacing_m` (the edge length of the cubes).
pub fn stuff(name: &str, solid: &Implicit, spacing_m: f64) -> Result<TetMesh, MeshError> {
    let lattice = Lattice::new(solid, spacing_m);
    let lattice_tets = lattice.tets();
    let mut values: Vec<f64> = lattice.points.iter().map(|p| (solid.value)(p)).collect();
    let mut points = lattice.points.clone();
    let cuts = cut_points(solid, &lattice_tets, &points, &values);
    warp(&cuts, &lattice, &mut points, &mut values);
    let mut pieces = Pieces {
        sides: values.iter().map(|&v| side(v)).collect(),
        points,
        cuts,
        cut_vertex: HashMap::new(),
        tets: Vec::new(),
    };
    for tet in &lattice_tets {
        pieces.clip(tet);
    }
    let (nodes, tets) = compact(&pieces.points, &pieces.tets);
    TetMesh::new(name, nodes, tets, Regions::default())
}

/// How finely a solid is meshed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshDensity {
    /// About this many nodes: the lattice spacing found by [`stuff_to_node_count`].
    Nodes(usize),
    /// Elements of about this size (m): the lattice spacing itself. The lattice's edges are
    /// the spacing and √3/2 of it; the surface's warped and clipped ones are shorter.
    ElementSize { size_m: f64 },
}

/// The most nodes an element size may ask for: an organ meshed finer would take hours to
/// build and gigabytes to hold.
pub const MOST_NODES: usize = 200_000;

/// Lattice points in a solid's bounding box per node of its mesh, at most: an organ fills a
/// quarter of its box or more.
const LATTICE_PER_NODE: f64 = 4.0;

/// Stuffs `solid` as finely as `density` asks; an element size that would give more than
/// [`MOST_NODES`] nodes is refused with the size that would not.
pub fn stuff_to(name: &str, solid: &Implicit, density: MeshDensity) -> Result<TetMesh, MeshError> {
    match density {
        MeshDensity::Nodes(target) => stuff_to_node_count(name, solid, target),
        MeshDensity::ElementSize { size_m } => {
            // A BCC lattice holds two points per cube; the solid fills part of its box.
            let extent = solid.max - solid.min;
            let box_m3 = extent.x * extent.y * extent.z;
            let finest_m = libm::cbrt(2.0 * box_m3 / (LATTICE_PER_NODE * MOST_NODES as f64));
            if size_m.is_nan() || size_m < finest_m {
                return Err(MeshError::TooFine {
                    mesh: name.to_owned(),
                    size_mm: size_m * 1e3,
                    finest_mm: finest_m * 1e3,
                    most: MOST_NODES,
                });
            }
            stuff(name, solid, size_m)
        }
    }
}

/// Stuffs a solid, choosing the lattice spacing so the node count lands near `target`: a
/// first pass from a rough estimate, then one correction by the cube root of the miss.
pub fn stuff_to_node_count(
    name: &str,
    solid: &Implicit,
    target: usize,
) -> Result<TetMesh, MeshError> {
    let extent = solid.max - solid.min;
    let guess = libm::cbrt(extent.x * extent.y * extent.z * 0.6 / target as f64);
    let first = stuff(name, solid, guess)?;
    let spacing = guess * libm::cbrt(first.node_count() as f64 / target as f64);
    stuff(name, solid, spacing)
}

/// Which side of the surface a lattice vertex is on; warped vertices are exactly on it.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Side {
    In,
    On,
    Out,
}

fn side(value: f64) -> Side {
    if value < 0.0 {
        Side::In
    } else if value > 0.0 {
        Side::Out
    } else {
        Side::On
    }
}

struct Lattice {
    /// Grid vertices first, then cube centres.
    points: Vec<Point3<f64>>,
    cells: [usize; 3],
}

impl Lattice {
    /// A grid one cell wider than the solid's bounds on every side, so no lattice tetrahedron
    /// needed for the solid is missing at the grid's edge.
    fn new(solid: &Implicit, spacing: f64) -> Self {
        let origin = solid.min - Vector3::repeat(spacing);
        let extent = solid.max - solid.min + Vector3::repeat(2.0 * spacing);
        let cells = [0, 1, 2].map(|a| (extent[a] / spacing).ceil().max(1.0) as usize);
        let mut points = Vec::new();
        for (offset, count) in [(0.0, 1), (0.5, 0)] {
            for k in 0..cells[2] + count {
                for j in 0..cells[1] + count {
                    for i in 0..cells[0] + count {
                        let ijk = Vector3::new(i as f64, j as f64, k as f64).add_scalar(offset);
                        points.push(origin + ijk * spacing);
                    }
                }
            }
        }
        Self { points, cells }
    }

    fn grid(&self, i: usize, j: usize, k: usize) -> usize {
        let [nx, ny, _] = self.cells;
        i + (nx + 1) * (j + (ny + 1) * k)
    }

    fn centre(&self, i: usize, j: usize, k: usize) -> usize {
        let [nx, ny, nz] = self.cells;
        (nx + 1) * (ny + 1) * (nz + 1) + i + nx * (j + ny * k)
    }

    fn is_centre(&self, v: usize) -> bool {
        let [nx, ny, nz] = self.cells;
        v >= (nx + 1) * (ny + 1) * (nz + 1)
    }

    /// The lattice tetrahedra: for every pair of face-adjacent cubes, the two centres and each
    /// of the four edges of the shared square face.
    fn tets(&self) -> Vec<[usize; 4]> {
        let [nx, ny, nz] = self.cells;
        let mut tets = Vec::with_capacity(12 * nx * ny * nz);
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for k in 0..nz {
                for j in 0..ny {
                    for i in 0..nx {
                        let c = [i, j, k];
                        if c[axis] + 1 >= self.cells[axis] {
                            continue;
                        }
                        let mut next = c;
                        next[axis] += 1;
                        // Corners of the shared face, in cyclic order around it.
                        let corner = |du: usize, dv: usize| {
                            let mut g = next;
                            g[u] += du;
                            g[v] += dv;
                            self.grid(g[0], g[1], g[2])
                        };
                        let square = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        let (a, b) = (self.centre(i, j, k), self.centre(next[0], next[1], next[2]));
                        for e in 0..4 {
                            tets.push([a, b, square[e], square[(e + 1) % 4]]);
                        }
                    }
                }
            }
        }
        tets
    }

    /// The warp threshold of a lattice edge, by its kind.
    fn alpha(&self, a: usize, b: usize) -> f64 {
        if self.is_centre(a) == self.is_centre(b) {
            ALPHA_LONG
        } else {
            ALPHA_SHORT
        }
    }
}

/// The six edges of a tetrahedron, as local vertex pairs.
const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

fn edge_key(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

/// Cut points by lattice edge, ordered: [`warp`] walks them and keeps the first of equally near
/// ones, so a hash map's per-process order would make the mesh differ from run to run (and
/// every vademecum built on it look stale).
type Cuts = BTreeMap<(usize, usize), Point3<f64>>;

/// Where each lattice edge with one end inside and one outside crosses the surface, found by
/// bisection on the implicit function.
fn cut_points(
    solid: &Implicit,
    tets: &[[usize; 4]],
    points: &[Point3<f64>],
    values: &[f64],
) -> Cuts {
    let mut cuts = Cuts::new();
    for tet in tets {
        for [i, j] in TET_EDGES {
            let key = edge_key(tet[i], tet[j]);
            let (a, b) = key;
            let crosses = matches!(
                (side(values[a]), side(values[b])),
                (Side::In, Side::Out) | (Side::Out, Side::In)
            );
            if crosses && !cuts.contains_key(&key) {
                cuts.insert(key, bisect(solid, points[a], values[a], points[b]));
            }
        }
    }
    cuts
}

fn bisect(solid: &Implicit, mut a: Point3<f64>, value_a: f64, mut b: Point3<f64>) -> Point3<f64> {
    let inside_a = value_a < 0.0;
    for _ in 0..CUT_ITERATIONS {
        let mid = nalgebra::center(&a, &b);
        if ((solid.value)(&mid) < 0.0) == inside_a {
            a = mid;
        } else {
            b = mid;
        }
    }
    nalgebra::center(&a, &b)
}

/// Moves each lattice vertex that lies closer than the warp threshold to a cut point on one of
/// its edges onto the nearest such cut point, and marks it as on the surface.
fn warp(cuts: &Cuts, lattice: &Lattice, points: &mut [Point3<f64>], values: &mut [f64]) {
    let mut nearest: BTreeMap<usize, (f64, Point3<f64>)> = BTreeMap::new();
    for (&(a, b), &cut) in cuts {
        let length = (points[b] - points[a]).norm();
        let alpha = lattice.alpha(a, b);
        for v in [a, b] {
            let distance = (cut - points[v]).norm();
            if distance < alpha * length {
                let entry = nearest.entry(v).or_insert((f64::INFINITY, cut));
                if distance < entry.0 {
                    *entry = (distance, cut);
                }
            }
        }
    }
    for (v, (_, cut)) in nearest {
        points[v] = cut;
        values[v] = 0.0;
    }
}

/// Clips lattice tetrahedra against the surface and splits the pieces into tetrahedra.
struct Pieces {
    points: Vec<Point3<f64>>,
    sides: Vec<Side>,
    cuts: Cuts,
    /// Cut points turned into mesh vertices, by lattice edge.
    cut_vertex: HashMap<(usize, usize), usize>,
    tets: Vec<[usize; 4]>,
}

impl Pieces {
    fn clip(&mut self, tet: &[usize; 4]) {
        let of = |side: Side| -> Vec<usize> {
            tet.iter()
                .copied()
                .filter(|&v| self.sides[v] == side)
                .collect()
        };
        let (ins, ons, outs) = (of(Side::In), of(Side::On), of(Side::Out));
        match (ins.len(), ons.len(), outs.len()) {
            (0, _, _) => {}
            (_, _, 0) => self.emit(*tet),
            (1, _, _) => {
                let mut corners = vec![ins[0]];
                corners.extend(&ons);
                corners.extend(outs.iter().map(|&o| self.cut(ins[0], o)));
                self.emit([corners[0], corners[1], corners[2], corners[3]]);
            }
            (2, 0, 2) => {
                let (a, b, c, d) = (ins[0], ins[1], outs[0], outs[1]);
                let (ac, ad, bc, bd) = (
                    self.cut(a, c),
                    self.cut(a, d),
                    self.cut(b, c),
                    self.cut(b, d),
                );
                let faces: [&[usize]; 5] = [
                    &[a, ac, ad],
                    &[b, bc, bd],
                    &[a, b, bc, ac],
                    &[a, b, bd, ad],
                    &[ac, ad, bd, bc],
                ];
                self.pull(&faces);
            }
            (2, 1, 1) => {
                let (a, b, z, d) = (ins[0], ins[1], ons[0], outs[0]);
                let (ad, bd) = (self.cut(a, d), self.cut(b, d));
                let faces: [&[usize]; 5] = [
                    &[a, b, z],
                    &[a, b, bd, ad],
                    &[a, z, ad],
                    &[b, z, bd],
                    &[ad, bd, z],
                ];
                self.pull(&faces);
            }
            (3, 0, 1) => {
                let (a, b, c, d) = (ins[0], ins[1], ins[2], outs[0]);
                let (ad, bd, cd) = (self.cut(a, d), self.cut(b, d), self.cut(c, d));
                let faces: [&[usize]; 5] = [
                    &[a, b, c],
                    &[ad, bd, cd],
                    &[a, b, bd, ad],
                    &[b, c, cd, bd],
                    &[c, a, ad, cd],
                ];
                self.pull(&faces);
            }
            other => unreachable!("a tetrahedron has four vertices, got {other:?}"),
        }
    }

    /// The mesh vertex of the cut point on lattice edge (a, b).
    fn cut(&mut self, a: usize, b: usize) -> usize {
        let key = edge_key(a, b);
        if let Some(&v) = self.cut_vertex.get(&key) {
            return v;
        }
        let point = self.cuts[&key];
        self.points.push(point);
        self.cut_vertex.insert(key, self.points.len() - 1);
        self.points.len() - 1
    }

    fn pull(&mut self, faces: &[&[usize]]) {
        split::pull(faces, &self.points, &mut self.tets);
    }

    fn emit(&mut self, tet: [usize; 4]) {
        split::push_oriented(tet, &self.points, &mut self.tets);
    }
}

/// Keeps only the vertices some tetrahedron uses, renumbered in order.
fn compact(points: &[Point3<f64>], tets: &[[usize; 4]]) -> (Vec<Point3<f64>>, Vec<[usize; 4]>) {
    const UNUSED: usize = usize::MAX;
    let mut new_index = vec![UNUSED; points.len()];
    let mut nodes = Vec::new();
    let tets = tets
        .iter()
        .map(|tet| {
            tet.map(|v| {
                if new_index[v] == UNUSED {
                    new_index[v] = nodes.len();
                    nodes.push(points[v]);
                }
                new_index[v]
            })
        })
        .collect();
    (nodes, tets)
}
