//! Closed triangle surfaces (OBJ, STL) and their tetrahedralization by isosurface stuffing,
//! with parry3d answering "is this point inside the surface?".

use std::collections::HashMap;

use nalgebra::Point3;
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh, TriMeshFlags};

use super::ImportError;
use super::intersections::{Faces, self_crossing};
use super::tokens::Tokens;
use crate::mesh::{Implicit, MeshDensity, TetMesh, stuff_to};
use crate::parry_interop::to_parry;

/// A surface is refused as implausibly large for an organ beyond this size (m): it was most
/// likely written in millimetres.
const LARGEST_ORGAN_M: f64 = 2.0;

/// A triangle surface in metres.
#[derive(Clone, Debug, Default)]
pub struct SurfaceMesh {
    pub vertices: Vec<Point3<f64>>,
    pub triangles: Vec<[usize; 3]>,
}

impl SurfaceMesh {
    pub fn scaled(mut self, scale: f64) -> Self {
        for p in &mut self.vertices {
            *p = Point3::from(p.coords * scale);
        }
        self
    }

    /// Turned half a turn about z (x and y reversed): LPS to RAS, or back.
    pub fn turned_about_z(mut self) -> Self {
        for p in &mut self.vertices {
            *p = Point3::new(-p.x, -p.y, p.z);
        }
        self
    }
}

/// Reads a Wavefront OBJ: `v` vertices and `f` faces (polygons are fanned into triangles;
/// `i`, `i/t`, `i//n`, `i/t/n` and negative indices are understood). Other lines are ignored.
pub fn read_obj(file: &str, text: &str) -> Result<SurfaceMesh, ImportError> {
    let mut surface = SurfaceMesh::default();
    for (i, line) in text.lines().enumerate() {
        let mut t = Tokens::from_line(file, line, i + 1);
        match t.next("a keyword") {
            Ok("v") => {
                let p: [f64; 3] = [t.parse("x")?, t.parse("y")?, t.parse("z")?];
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(t.error("a vertex has a non-finite coordinate"));
                }
                surface.vertices.push(Point3::from(p));
            }
            Ok("f") => {
                let mut corners = Vec::new();
                while let Ok(token) = t.next("a vertex index") {
                    let index: i64 = token
                        .split('/')
                        .next()
                        .and_then(|s| s.parse().ok())
                        .ok_or_else(|| {
                            t.error(format!("expected a vertex index, found '{token}'"))
                        })?;
                    let count = surface.vertices.len() as i64;
                    let resolved = if index < 0 { count + index } else { index - 1 };
                    if !(0..count).contains(&resolved) {
                        return Err(t.error(format!("vertex index {index} is out of range (the file has {count} vertices so far)")));
                    }
                    corners.push(resolved as usize);
                }
                if corners.len() < 3 {
                    return Err(t.error("a face needs at least three vertices"));
                }
                for k in 1..corners.len() - 1 {
                    surface
                        .triangles
                        .push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(surface)
}

/// Reads an STL file, ASCII or binary; coincident vertices are merged.
pub fn read_stl(file: &str, bytes: &[u8]) -> Result<SurfaceMesh, ImportError> {
    let binary_size = |count: usize| 84 + 50 * count;
    let declared = bytes
        .get(80..84)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let looks_ascii =
        bytes.starts_with(b"solid") && declared.is_none_or(|c| binary_size(c) != bytes.len());
    let triangles = if looks_ascii {
        let text = std::str::from_utf8(bytes).map_err(|e| ImportError::Unsupported {
            file: file.to_owned(),
            message: format!(
                "an ASCII STL must be text (invalid byte at {})",
                e.valid_up_to()
            ),
        })?;
        ascii_stl(file, text)?
    } else {
        let count = declared.ok_or_else(|| ImportError::Unsupported {
            file: file.to_owned(),
            message: format!(
                "only {} bytes: too short for a binary STL header",
                bytes.len()
            ),
        })?;
        if bytes.len() != binary_size(count) {
            return Err(ImportError::Unsupported {
                file: file.to_owned(),
                message: format!(
                    "binary STL declares {count} triangles ({} bytes) but the file has {} bytes: truncated or not an STL",
                    binary_size(count),
                    bytes.len()
                ),
            });
        }
        (0..count)
            .map(|i| {
                let at = 84 + 50 * i + 12;
                std::array::from_fn(|v| {
                    Point3::from(std::array::from_fn(|c| {
                        let o = at + 12 * v + 4 * c;
                        f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]])
                            as f64
                    }))
                })
            })
            .collect()
    };
    Ok(merge_vertices(triangles))
}

fn ascii_stl(file: &str, text: &str) -> Result<Vec<[Point3<f64>; 3]>, ImportError> {
    let mut t = Tokens::new(file, text);
    t.expect("solid")?;
    // The rest of the first line is the solid's name.
    t.rest_of_line();
    let mut triangles = Vec::new();
    loop {
        match t.next("'facet' or 'endsolid'")? {
            "facet" => {}
            "endsolid" => return Ok(triangles),
            other => {
                return Err(t.error(format!("expected 'facet' or 'endsolid', found '{other}'")));
            }
        }
        t.expect("normal")?;
        for _ in 0..3 {
            t.parse::<f64>("a normal component")?;
        }
        t.expect("outer")?;
        t.expect("loop")?;
        let mut corners = [Point3::origin(); 3];
        for corner in &mut corners {
            t.expect("vertex")?;
            let p: [f64; 3] = [t.parse("x")?, t.parse("y")?, t.parse("z")?];
            if !p.iter().all(|c| c.is_finite()) {
                return Err(t.error("a vertex has a non-finite coordinate"));
            }
            *corner = Point3::from(p);
        }
        t.expect("endloop")?;
        t.expect("endfacet")?;
        triangles.push(corners);
    }
}

/// Shares vertices with bit-identical coordinates (STL stores each triangle's corners apart).
fn merge_vertices(triangles: Vec<[Point3<f64>; 3]>) -> SurfaceMesh {
    let mut index: HashMap<[u64; 3], usize> = HashMap::new();
    let mut surface = SurfaceMesh::default();
    for corners in triangles {
        let ids = corners.map(|p| {
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            *index.entry(key).or_insert_with(|| {
                surface.vertices.push(p);
                surface.vertices.len() - 1
            })
        });
        surface.triangles.push(ids);
    }
    surface
}

/// Tetrahedralizes the inside of a closed, manifold, consistently oriented surface, as finely
/// as `density` asks. The lattice's own surface replaces the file's: a segmentation's fine
/// triangles are remeshed to the elements' size.
pub fn tetrahedralize(
    file: &str,
    mut surface: SurfaceMesh,
    density: MeshDensity,
) -> Result<TetMesh, ImportError> {
    let refuse = |reason: String| ImportError::Unusable {
        file: file.to_owned(),
        reason,
    };
    check_closed(&surface).map_err(refuse)?;
    let faces = Faces {
        vertices: &surface.vertices,
        triangles: &surface.triangles,
    };
    if let Some((crossing, pairs)) = self_crossing(faces) {
        let [i, j] = crossing.triangles;
        let p = crossing.near_m.coords * 1e3;
        return Err(refuse(format!(
            "the surface crosses itself: triangles {i} and {j} cross near ({:.1}, {:.1}, {:.1}) mm \
             ({pairs} crossing pairs in all); mend it in the segmentation tool",
            p.x, p.y, p.z
        )));
    }
    let (min, max) = bounds(&surface.vertices);
    let size = (max - min).norm();
    if size > LARGEST_ORGAN_M {
        return Err(refuse(format!(
            "the surface is {size:.1} m across, too large for an organ; if the file is in millimetres, scale it by 0.001"
        )));
    }
    let enclosed: f64 = surface
        .triangles
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| surface.vertices[i].coords);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    if enclosed < 0.0 {
        for f in &mut surface.triangles {
            f.swap(1, 2);
        }
    }
    let vertices = surface.vertices.iter().map(to_parry).collect();
    let indices = surface
        .triangles
        .iter()
        .map(|f| f.map(|i| i as u32))
        .collect();
    let trimesh = TriMesh::with_flags(vertices, indices, TriMeshFlags::ORIENTED)
        .map_err(|e| refuse(format!("the surface cannot be used as a solid: {e:?}")))?;
    let inside = |p: &Point3<f64>| {
        if trimesh.contains_local_point(to_parry(p)) {
            -1.0
        } else {
            1.0
        }
    };
    let solid = Implicit {
        value: &inside,
        min,
        max,
    };
    Ok(stuff_to(file, &solid, density)?)
}

fn bounds(points: &[Point3<f64>]) -> (Point3<f64>, Point3<f64>) {
    let mut min = Point3::from([f64::INFINITY; 3]);
    let mut max = Point3::from([f64::NEG_INFINITY; 3]);
    for p in points {
        min = min.inf(p);
        max = max.sup(p);
    }
    (min, max)
}

/// Every directed edge must appear once and its reverse once, and no triangle may be flat.
fn check_closed(surface: &SurfaceMesh) -> Result<(), String> {
    if surface.triangles.is_empty() {
        return Err("the surface has no triangles".into());
    }
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, f) in surface.triangles.iter().enumerate() {
        let [a, b, c] = f.map(|i| surface.vertices[i]);
        if (b - a).cross(&(c - a)).norm() == 0.0 {
            return Err(format!("triangle {t} (vertices {f:?}) has zero area"));
        }
        for k in 0..3 {
            *directed.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    let open = directed
        .keys()
        .filter(|&&(a, b)| !directed.contains_key(&(b, a)))
        .count();
    let flipped = directed.values().filter(|&&n| n > 1).count();
    if open > 0 || flipped > 0 {
        return Err(format!(
            "the surface is not closed and consistently oriented: {open} edges without a twin (holes), \
             {flipped} edges used twice in the same direction (flipped triangles or non-manifold edges)"
        ));
    }
    Ok(())
}
