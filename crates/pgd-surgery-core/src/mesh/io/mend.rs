//! Mending a surface as segmentation tools leave them before it is tetrahedralized: vertices
//! that coincide welded, triangles with no area dropped, triangles facing the wrong way turned
//! to agree with their neighbours, small holes closed. What cannot be mended is refused with
//! where it is.

use std::collections::{HashMap, HashSet};

use nalgebra::{Point3, Vector3};

use super::surface::SurfaceMesh;

/// Vertices closer than this fraction of the surface's size are one vertex.
const WELD_FRACTION: f64 = 1e-6;

/// Holes with at most this many boundary edges are closed by a fan about their centre;
/// larger ones are refused (a segmentation cut open, not a gap between triangles).
pub const MAX_HOLE_EDGES: usize = 12;

/// What was mended.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Mended {
    pub welded_vertices: usize,
    pub dropped_triangles: usize,
    pub turned_triangles: usize,
    pub closed_holes: usize,
}

impl Mended {
    pub fn is_nothing(&self) -> bool {
        *self == Self::default()
    }
}

impl std::fmt::Display for Mended {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} coincident vertices welded, {} triangles without area dropped, {} triangles \
             turned to face as their neighbours, {} holes of at most {MAX_HOLE_EDGES} edges closed",
            self.welded_vertices, self.dropped_triangles, self.turned_triangles, self.closed_holes
        )
    }
}

/// `surface` mended, with what was done; or why it cannot be, with where.
pub fn mend(surface: SurfaceMesh) -> Result<(SurfaceMesh, Mended), String> {
    let mut mended = Mended::default();
    let mut surface = weld(surface, &mut mended);
    drop_flat(&mut surface, &mut mended);
    orient(&mut surface, &mut mended)?;
    close_holes(&mut surface, &mut mended)?;
    Ok((surface, mended))
}

fn mm(p: &Point3<f64>) -> String {
    format!("({:.1}, {:.1}, {:.1}) mm", p.x * 1e3, p.y * 1e3, p.z * 1e3)
}

/// Welds vertices within [`WELD_FRACTION`] of the surface's size (a grid of that spacing,
/// each vertex compared with those in its own and the 26 neighbouring cells).
fn weld(surface: SurfaceMesh, mended: &mut Mended) -> SurfaceMesh {
    let (lo, hi) = surface.vertices.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    let tolerance = ((hi - lo).norm() * WELD_FRACTION).max(f64::MIN_POSITIVE);
    let cell = |p: &Point3<f64>| (p.coords / tolerance).map(|c| c.floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut kept: Vec<Point3<f64>> = Vec::new();
    let mut index = Vec::with_capacity(surface.vertices.len());
    for p in &surface.vertices {
        let c = cell(p);
        let near = (-1..=1).flat_map(|i| {
            (-1..=1).flat_map(move |j| (-1..=1).map(move |k| [c.x + i, c.y + j, c.z + k]))
        });
        let found = near
            .filter_map(|key| grid.get(&key))
            .flatten()
            .find(|&&v| (kept[v] - p).norm() <= tolerance)
            .copied();
        index.push(found.unwrap_or_else(|| {
            kept.push(*p);
            grid.entry([c.x, c.y, c.z])
                .or_default()
                .push(kept.len() - 1);
            kept.len() - 1
        }));
    }
    mended.welded_vertices = surface.vertices.len() - kept.len();
    SurfaceMesh {
        vertices: kept,
        triangles: surface
            .triangles
            .iter()
            .map(|f| f.map(|v| index[v]))
            .collect(),
    }
}

/// Drops triangles with a repeated corner or no area, and repeats of a triangle.
fn drop_flat(surface: &mut SurfaceMesh, mended: &mut Mended) {
    let before = surface.triangles.len();
    let mut seen = HashSet::new();
    let vertices = &surface.vertices;
    surface.triangles.retain(|f| {
        let [a, b, c] = f.map(|v| vertices[v]);
        let mut key = *f;
        key.sort_unstable();
        (b - a).cross(&(c - a)).norm() > 0.0 && seen.insert(key)
    });
    mended.dropped_triangles = before - surface.triangles.len();
}

/// The triangles on each undirected edge.
fn edge_triangles(triangles: &[[usize; 3]]) -> HashMap<(usize, usize), Vec<usize>> {
    let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (t, f) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    edges
}

/// Whether triangle `f` runs along the edge from `a` to `b`.
fn runs(f: &[usize; 3], a: usize, b: usize) -> bool {
    (0..3).any(|k| f[k] == a && f[(k + 1) % 3] == b)
}

/// Turns triangles to agree with their neighbours across shared edges (breadth-first from
/// one triangle of each connected part); an edge with more than two triangles, or a part that
/// cannot agree (one-sided, like a Möbius strip), is refused with where.
fn orient(surface: &mut SurfaceMesh, mended: &mut Mended) -> Result<(), String> {
    let edges = edge_triangles(&surface.triangles);
    if let Some((&(a, _), _)) = edges.iter().find(|(_, ts)| ts.len() > 2) {
        return Err(format!(
            "an edge shared by more than two triangles (not a surface) at {}",
            mm(&surface.vertices[a])
        ));
    }
    let mut done = vec![false; surface.triangles.len()];
    for start in 0..surface.triangles.len() {
        if done[start] {
            continue;
        }
        done[start] = true;
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(t) = queue.pop_front() {
            let f = surface.triangles[t];
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                for &u in &edges[&(a.min(b), a.max(b))] {
                    if u == t {
                        continue;
                    }
                    let agrees = runs(&surface.triangles[u], b, a);
                    match (done[u], agrees) {
                        (true, true) => {}
                        (true, false) => {
                            return Err(format!(
                                "the surface is one-sided near {}: its triangles cannot all face out",
                                mm(&surface.vertices[a])
                            ));
                        }
                        (false, agrees) => {
                            if !agrees {
                                surface.triangles[u].swap(1, 2);
                                mended.turned_triangles += 1;
                            }
                            done[u] = true;
                            queue.push_back(u);
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

/// Closes each hole of at most [`MAX_HOLE_EDGES`] edges by a fan from a new vertex at its
/// centre; refuses a larger one with its size and where it is.
fn close_holes(surface: &mut SurfaceMesh, mended: &mut Mended) -> Result<(), String> {
    let edges = edge_triangles(&surface.triangles);
    // Each open edge, in the direction its triangle runs it; the hole runs the other way.
    let mut next: HashMap<usize, usize> = HashMap::new();
    for (&(a, b), ts) in &edges {
        if ts.len() == 1 {
            let (from, to) = match runs(&surface.triangles[ts[0]], a, b) {
                true => (b, a),
                false => (a, b),
            };
            if next.insert(from, to).is_some() {
                return Err(format!(
                    "two holes meet at a vertex at {}",
                    mm(&surface.vertices[from])
                ));
            }
        }
    }
    while let Some(&start) = next.keys().next() {
        let mut hole = vec![start];
        let mut at = next.remove(&start).expect("a key");
        while at != start {
            hole.push(at);
            at = next
                .remove(&at)
                .ok_or_else(|| format!("a hole's edge ends at {}", mm(&surface.vertices[at])))?;
        }
        let centre = Point3::from(
            hole.iter()
                .map(|&v| surface.vertices[v].coords)
                .sum::<Vector3<f64>>()
                / hole.len() as f64,
        );
        if hole.len() > MAX_HOLE_EDGES {
            return Err(format!(
                "a hole of {} edges around {} (holes of up to {MAX_HOLE_EDGES} edges are closed; \
                 close this one in the segmentation tool, or export a closed surface)",
                hole.len(),
                mm(&centre)
            ));
        }
        surface.vertices.push(centre);
        let c = surface.vertices.len() - 1;
        for k in 0..hole.len() {
            surface
                .triangles
                .push([hole[k], hole[(k + 1) % hole.len()], c]);
        }
        mended.closed_holes += 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed octahedron of radius 10 mm.
    fn octahedron() -> SurfaceMesh {
        let r = 0.01;
        let vertices = vec![
            Point3::new(r, 0.0, 0.0),
            Point3::new(-r, 0.0, 0.0),
            Point3::new(0.0, r, 0.0),
            Point3::new(0.0, -r, 0.0),
            Point3::new(0.0, 0.0, r),
            Point3::new(0.0, 0.0, -r),
        ];
        let triangles = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        SurfaceMesh {
            vertices,
            triangles,
        }
    }

    fn closed_and_agreeing(surface: &SurfaceMesh) -> bool {
        let edges = edge_triangles(&surface.triangles);
        edges.iter().all(|(&(a, b), ts)| {
            ts.len() == 2
                && runs(&surface.triangles[ts[0]], a, b) != runs(&surface.triangles[ts[1]], a, b)
        })
    }

    #[test]
    fn a_sound_surface_is_left_as_it_is() {
        let (surface, mended) = mend(octahedron()).unwrap();
        assert!(mended.is_nothing(), "{mended}");
        assert_eq!(surface.triangles, octahedron().triangles);
    }

    #[test]
    fn flipped_triangles_are_turned_and_split_corners_welded() {
        let mut surface = octahedron();
        surface.triangles[1].swap(1, 2);
        surface.triangles[6].swap(0, 1);
        // Triangle 7's first corner stored apart, a nanometre off.
        surface.vertices.push(Point3::new(0.01 + 1e-9, 0.0, 0.0));
        surface.triangles[7][0] = 6;
        let (surface, mended) = mend(surface).unwrap();
        assert_eq!((mended.turned_triangles, mended.welded_vertices), (2, 1));
        assert!(closed_and_agreeing(&surface));
    }

    #[test]
    fn a_small_hole_is_closed_and_a_large_one_refused_with_where() {
        let mut surface = octahedron();
        surface.triangles.remove(0);
        let (surface, mended) = mend(surface).unwrap();
        assert_eq!((mended.closed_holes, surface.triangles.len()), (1, 10));
        assert!(closed_and_agreeing(&surface));
        // A ring of 40 quads, open at both ends: its rims have 40 edges each.
        let n = 40;
        let ring = |z: f64| {
            (0..n).map(move |k| {
                let a = k as f64 * std::f64::consts::TAU / n as f64;
                Point3::new(0.02 * a.cos(), 0.02 * a.sin(), z)
            })
        };
        let vertices: Vec<Point3<f64>> = ring(0.0).chain(ring(0.01)).collect();
        let triangles = (0..n)
            .flat_map(|k| {
                let (a, b) = (k, (k + 1) % n);
                [[a, b, n + b], [a, n + b, n + a]]
            })
            .collect();
        let error = mend(SurfaceMesh {
            vertices,
            triangles,
        })
        .unwrap_err();
        assert!(error.contains("a hole of 40 edges around ("), "{error}");
    }

    #[test]
    fn an_edge_of_three_triangles_is_refused() {
        let mut surface = octahedron();
        surface.vertices.push(Point3::new(0.0, 0.0, 0.02));
        surface.triangles.push([0, 2, 6]);
        let error = mend(surface).unwrap_err();
        assert!(error.contains("more than two triangles"), "{error}");
    }
}
