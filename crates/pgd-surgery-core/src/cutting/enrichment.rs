//! Which nodes a set of cut faces enriches, and how each element is integrated.
//!
//! Heaviside enrichment, shifted: a node `i` enriched by face `k` adds the function
//! `N_i(x) (H_k(x) − H_k(x_i))`, with `H_k = ±1` the side of the face's plane. It vanishes at
//! every node, so the nodal values stay the displacements, and inside the support it opens the
//! jump across the face.
//!
//! **The cut front** ([`Front`]). By default a node is enriched only when the face cuts its
//! whole support: the support reaches both sides, and wherever it meets the plane, it meets it
//! inside the face. The discontinuity therefore ends on the boundary of the last supports it
//! crosses whole: the front is snapped to element faces, no tip enrichment. A crack is short
//! of its true length by up to about one element, which converges away as the mesh is refined
//! (the edge-crack test measures it), and costs no singular functions in the reduced basis.
//! On a mesh whose elements are as large as the cut, that leaves the cut all but unfelt; the
//! trainer's scalpel snaps the front to the nearest element faces instead. A node whose
//! support the plane only grazes (less than [`SLIVER`] of its volume on one side) is not
//! enriched: its enriched function would be all but null, and the system near singular.

use std::collections::HashMap;

use nalgebra::Point3;

use super::clip::{self, Tet};
use super::incision::CutFace;
use crate::mesh::TetMesh;

/// Where a cut's front falls, between element faces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Front {
    /// On the boundary of the last supports the face cuts whole: the cut is short of the
    /// face by up to an element (the reference solvers' choice, validated in `docs/cutting.md`).
    #[default]
    Inward,
    /// On the nearest element faces: a node is enriched when at least half of the points
    /// where its support meets the plane lie inside the face. The cut then ends within about
    /// half an element of the face, either way; what the trainer's scalpel uses.
    Nearest,
}

/// The smallest share of a support's volume on its smaller side for the node to be enriched.
pub const SLIVER: f64 = 1e-4;

/// Signed distances below this share of the mesh's size count as on the plane.
const SNAP: f64 = 1e-9;

/// One enriched function: node `node`, opened by face `face`, whose side of the plane is
/// `node_side` (`+1` on the normal side or on the plane, `−1` otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Enriched {
    pub node: usize,
    pub face: usize,
    pub node_side: i8,
}

/// One piece of an element, where each face's Heaviside function is constant.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub volume_m3: f64,
    /// Per face the element's enriched functions name, in [`ElementCut::faces`]' order.
    pub sides: Vec<i8>,
}

/// How one element is cut: the faces its enriched functions name, and its pieces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementCut {
    pub faces: Vec<usize>,
    /// Indices into [`Enrichment::functions`] whose node is a corner of the element, with
    /// that corner (0–3).
    pub functions: Vec<(usize, usize)>,
    pub pieces: Vec<Piece>,
}

/// The enrichment of a mesh by cut faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Enrichment {
    pub functions: Vec<Enriched>,
    /// Per element: its cut, empty where no enriched function reaches it.
    pub elements: Vec<ElementCut>,
}

impl Enrichment {
    pub fn new(mesh: &TetMesh, faces: &[CutFace]) -> Self {
        Self::with_front(mesh, faces, Front::Inward)
    }

    /// The enrichment with the cut's front placed as `front` says.
    pub fn with_front(mesh: &TetMesh, faces: &[CutFace], front: Front) -> Self {
        Self::over(mesh, &Supports::new(mesh), faces, front)
    }

    /// [`Self::with_front`] with the mesh's `supports` at hand (a cut state keeps them, as
    /// its cuts grow over the same mesh).
    pub fn over(mesh: &TetMesh, supports: &Supports, faces: &[CutFace], front: Front) -> Self {
        let Supports {
            elements: supports,
            reach_m: reach,
            snap_m,
        } = supports;
        let snap_m = *snap_m;
        let mut functions = Vec::new();
        for (k, face) in faces.iter().enumerate() {
            let phi: Vec<f64> = mesh
                .nodes()
                .iter()
                .map(|p| snapped(face.signed_distance(p), snap_m))
                .collect();
            for (node, support) in supports.iter().enumerate() {
                // A plane farther from the node than its support reaches leaves the support
                // on one side.
                if phi[node].abs() > reach[node] {
                    continue;
                }
                if cuts_support(mesh, face, front, &phi, support, snap_m) {
                    functions.push(Enriched {
                        node,
                        face: k,
                        node_side: if phi[node] >= 0.0 { 1 } else { -1 },
                    });
                }
            }
        }
        let elements = element_cuts(mesh, faces, &functions, snap_m);
        Self {
            functions,
            elements,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.functions.is_empty()
    }

    /// Whether the cuts leave a chunk of tissue that no held node holds (`held(node)`): its
    /// stiffness would be singular. Each piece of an element sees each corner as that node
    /// from the piece's side of every face enriching it; pieces that see a node the same way
    /// share it, as elements of a mesh share nodes, and a chunk is a connected set of them.
    pub fn detaches(&self, mesh: &TetMesh, held: impl Fn(usize) -> bool) -> bool {
        // A corner no enriched function names is its node, as in the uncut mesh (ids
        // `0..n`); the others are keyed by how their piece sees the faces.
        let n = mesh.node_count();
        let mut anchored: Vec<bool> = (0..n).map(&held).collect();
        let mut used = vec![false; n];
        let mut seen: HashMap<(usize, Vec<(usize, i8)>), usize> = HashMap::new();
        let mut chunks = UnionFind::default();
        chunks.grow(n);
        for (tet, cut) in mesh.tets().iter().zip(&self.elements) {
            if cut.functions.is_empty() || cut.pieces.is_empty() {
                tet.iter().for_each(|&node| used[node] = true);
                for w in tet.windows(2) {
                    chunks.join(w[0], w[1]);
                }
                continue;
            }
            for piece in &cut.pieces {
                let ids: Vec<usize> = (0..4)
                    .map(|a| {
                        let view = self.corner_view(cut, piece, a);
                        if view.is_empty() {
                            used[tet[a]] = true;
                            return tet[a];
                        }
                        *seen.entry((tet[a], view)).or_insert_with(|| {
                            anchored.push(held(tet[a]));
                            chunks.grow(anchored.len());
                            anchored.len() - 1
                        })
                    })
                    .collect();
                for w in ids.windows(2) {
                    chunks.join(w[0], w[1]);
                }
            }
        }
        let mut held_chunk = vec![false; anchored.len()];
        for (id, &a) in anchored.iter().enumerate() {
            if a {
                held_chunk[chunks.root(id)] = true;
            }
        }
        (0..anchored.len()).any(|id| (id >= n || used[id]) && !held_chunk[chunks.root(id)])
    }

    /// How `piece` sees corner `a` of its element: the side of every face enriching that
    /// corner's node, by face.
    fn corner_view(&self, cut: &ElementCut, piece: &Piece, a: usize) -> Vec<(usize, i8)> {
        cut.functions
            .iter()
            .filter(|&&(_, corner)| corner == a)
            .map(|&(j, _)| {
                let k = self.functions[j].face;
                let slot = cut.faces.iter().position(|&f| f == k).expect("named");
                (k, piece.sides[slot])
            })
            .collect()
    }
}

/// Disjoint sets over `0..n`, grown on demand.
#[derive(Default)]
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn grow(&mut self, n: usize) {
        while self.parent.len() < n {
            self.parent.push(self.parent.len());
        }
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        self.parent[a] = b;
    }
}

/// What enriching a mesh needs of it whatever the cut: each node's support and its reach.
#[derive(Clone, Debug)]
pub struct Supports {
    /// Each node's elements.
    elements: Vec<Vec<usize>>,
    /// Per node, the farthest any corner of its elements lies from it (m).
    reach_m: Vec<f64>,
    /// Distances to a face's plane this small count as on it (m).
    snap_m: f64,
}

impl Supports {
    pub fn new(mesh: &TetMesh) -> Self {
        let mut elements = vec![Vec::new(); mesh.node_count()];
        for (t, tet) in mesh.tets().iter().enumerate() {
            for &n in tet {
                elements[n].push(t);
            }
        }
        let nodes = mesh.nodes();
        let reach_m = elements
            .iter()
            .enumerate()
            .map(|(n, support): (usize, &Vec<usize>)| {
                let corners = support.iter().flat_map(|&t| mesh.tets()[t]);
                corners
                    .map(|m| (nodes[m] - nodes[n]).norm())
                    .fold(0.0, f64::max)
            })
            .collect();
        Self {
            elements,
            reach_m,
            snap_m: SNAP * mesh_size_m(mesh),
        }
    }
}

fn mesh_size_m(mesh: &TetMesh) -> f64 {
    let (mut lo, mut hi) = (Point3::origin(), Point3::origin());
    for (i, p) in mesh.nodes().iter().enumerate() {
        lo = if i == 0 { *p } else { lo.inf(p) };
        hi = if i == 0 { *p } else { hi.sup(p) };
    }
    (hi - lo).norm()
}

fn snapped(d: f64, snap_m: f64) -> f64 {
    if d.abs() <= snap_m { 0.0 } else { d }
}

/// Whether `face` cuts the whole support of a node: volume on both sides, more than a sliver
/// on the smaller, and every point where an element of it meets the plane inside the face.
fn cuts_support(
    mesh: &TetMesh,
    face: &CutFace,
    front: Front,
    phi: &[f64],
    support: &[usize],
    snap_m: f64,
) -> bool {
    let (mut plus, mut minus, mut total) = (0.0, 0.0, 0.0);
    let (mut inside, mut meets) = (0, 0);
    for &t in support {
        let tet = mesh.tets()[t];
        let corners = tet.map(|n| phi[n]);
        if corners.iter().all(|&d| d > 0.0) || corners.iter().all(|&d| d < 0.0) {
            let v = mesh.tet_volume(t);
            total += v;
            *(if corners[0] > 0.0 {
                &mut plus
            } else {
                &mut minus
            }) += v;
            continue;
        }
        let (points_inside, points) = plane_points_inside(mesh, face, &tet, &corners, snap_m);
        if front == Front::Inward && points_inside < points {
            return false;
        }
        (inside, meets) = (inside + points_inside, meets + points);
        let (p, m) = clip::split(&mesh.tet_points(t), corners);
        let (vp, vm) = (sum_volume(&p), sum_volume(&m));
        plus += vp;
        minus += vm;
        total += vp + vm;
    }
    2 * inside >= meets && plus.min(minus) > SLIVER * total
}

/// How many of the points where the element meets the plane (its corners on the plane, its
/// edges' crossings) lie inside the face, of how many.
fn plane_points_inside(
    mesh: &TetMesh,
    face: &CutFace,
    tet: &[usize; 4],
    phi: &[f64; 4],
    snap_m: f64,
) -> (usize, usize) {
    let p = |i: usize| mesh.nodes()[tet[i]];
    let on_plane = (0..4).filter(|&i| phi[i] == 0.0).map(p);
    let crossings = (0..4)
        .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
        .filter(|&(i, j)| phi[i] * phi[j] < 0.0)
        .map(|(i, j)| p(i) + (p(j) - p(i)) * (phi[i] / (phi[i] - phi[j])));
    let points: Vec<Point3<f64>> = on_plane.chain(crossings).collect();
    let inside = points.iter().filter(|x| face.covers(x, snap_m)).count();
    (inside, points.len())
}

fn sum_volume(tets: &[Tet]) -> f64 {
    tets.iter().map(clip::volume).sum()
}

/// Per element, the enriched functions at its corners and its pieces, split by each face
/// they name.
fn element_cuts(
    mesh: &TetMesh,
    faces: &[CutFace],
    functions: &[Enriched],
    snap_m: f64,
) -> Vec<ElementCut> {
    let mut by_node: Vec<Vec<usize>> = vec![Vec::new(); mesh.node_count()];
    for (j, f) in functions.iter().enumerate() {
        by_node[f.node].push(j);
    }
    mesh.tets()
        .iter()
        .enumerate()
        .map(|(t, tet)| {
            let mut cut = ElementCut::default();
            for (corner, &n) in tet.iter().enumerate() {
                for &j in &by_node[n] {
                    cut.functions.push((j, corner));
                    if !cut.faces.contains(&functions[j].face) {
                        cut.faces.push(functions[j].face);
                    }
                }
            }
            if !cut.functions.is_empty() {
                cut.pieces = pieces(&mesh.tet_points(t), &cut.faces, faces, snap_m);
            }
            cut
        })
        .collect()
}

/// The element split by each face's plane in turn, each piece with its side of each.
fn pieces(tet: &Tet, named: &[usize], faces: &[CutFace], snap_m: f64) -> Vec<Piece> {
    let mut parts = vec![*tet];
    for &k in named {
        parts = parts
            .iter()
            .flat_map(|part| {
                let phi = part.map(|p| snapped(faces[k].signed_distance(&p), snap_m));
                let (plus, minus) = clip::split(part, phi);
                plus.into_iter().chain(minus)
            })
            .collect();
    }
    parts
        .iter()
        .map(|part| {
            let centre = clip::centroid(part);
            Piece {
                volume_m3: clip::volume(part),
                sides: named
                    .iter()
                    .map(|&k| {
                        if faces[k].signed_distance(&centre) >= 0.0 {
                            1
                        } else {
                            -1
                        }
                    })
                    .collect(),
            }
        })
        .filter(|piece| piece.volume_m3 > 0.0)
        .collect()
}
