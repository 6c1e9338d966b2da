//! Thin-walled solids by extrusion: a triangulated mid-surface is offset along its normals into
//! layers, and each triangular prism between layers is split into three tetrahedra.
//!
//! Walls of 0.5–2.5 mm (cornea, gallbladder) are far thinner than the element size an organ of
//! a few thousand nodes allows, so a volume mesher would put less than one element through the
//! wall; extrusion puts `layers` elements through it by construction.

use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};

use super::{MeshError, Regions, TetMesh, split};

/// A triangulated surface with a unit normal per vertex.
#[derive(Clone, Debug)]
pub struct MidSurface {
    pub points: Vec<Point3<f64>>,
    pub normals: Vec<Vector3<f64>>,
    pub triangles: Vec<[usize; 3]>,
}

/// Extrudes `surface` into a wall of `thickness_m` centred on it, with `layers` elements
/// through the thickness. Node `k · n + v` is surface vertex `v` offset to layer `k`; layer 0
/// lies on the side opposite the normals.
pub fn extrude(
    name: &str,
    surface: &MidSurface,
    thickness_m: f64,
    layers: usize,
) -> Result<TetMesh, MeshError> {
    let n = surface.points.len();
    let layers = layers.max(1);
    let mut nodes = Vec::with_capacity(n * (layers + 1));
    for k in 0..=layers {
        let offset = thickness_m * (k as f64 / layers as f64 - 0.5);
        nodes.extend(
            surface
                .points
                .iter()
                .zip(&surface.normals)
                .map(|(p, normal)| p + normal * offset),
        );
    }
    let mut tets = Vec::with_capacity(3 * layers * surface.triangles.len());
    for k in 0..layers {
        for &[a, b, c] in &surface.triangles {
            let [a0, b0, c0] = [a, b, c].map(|v| k * n + v);
            let [a1, b1, c1] = [a, b, c].map(|v| (k + 1) * n + v);
            let faces: [&[usize]; 5] = [
                &[a0, b0, c0],
                &[a1, b1, c1],
                &[a0, b0, b1, a1],
                &[b0, c0, c1, b1],
                &[c0, a0, a1, c1],
            ];
            split::pull(&faces, &nodes, &mut tets);
        }
    }
    TetMesh::new(name, nodes, tets, Regions::default())
}

/// A closed surface of revolution about the axis from `start` to `end`, with radius
/// `radius_m(t)` at `t ∈ [0, 1]` along it (zero at both poles), `rings` rings of `segments`
/// vertices between two pole vertices. Normals point outward.
pub fn revolution(
    start: Point3<f64>,
    end: Point3<f64>,
    radius_m: &dyn Fn(f64) -> f64,
    rings: usize,
    segments: usize,
) -> MidSurface {
    let axis = (end - start).normalize();
    let u = axis.cross(&any_perpendicular(&axis)).normalize();
    let v = axis.cross(&u);
    let stations = arc_length_stations(&|t| radius_m(t), (end - start).norm(), rings);
    let mut points = vec![start];
    for &t in &stations {
        let centre = start + (end - start) * t;
        let r = radius_m(t);
        points.extend((0..segments).map(|j| {
            let phi = 2.0 * PI * j as f64 / segments as f64;
            centre + (u * libm::cos(phi) + v * libm::sin(phi)) * r
        }));
    }
    points.push(end);
    let ring = |i: usize, j: usize| 1 + (i - 1) * segments + j % segments;
    let last = points.len() - 1;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j + 1), ring(1, j)]);
        for i in 1..rings {
            let (a, b) = (ring(i, j), ring(i, j + 1));
            let (c, d) = (ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
        triangles.push([ring(rings, j), ring(rings, j + 1), last]);
    }
    with_normals(points, triangles)
}

/// The `rings` values of `t` that split the profile curve `(t·length, radius(t))` into equal
/// arc lengths, so rings are evenly spaced along the surface even where the radius changes
/// fast (near the poles), which keeps the triangles there from becoming slivers.
fn arc_length_stations(radius: &dyn Fn(f64) -> f64, length: f64, rings: usize) -> Vec<f64> {
    const SAMPLES: usize = 4096;
    let mut cumulative = vec![0.0; SAMPLES + 1];
    for k in 1..=SAMPLES {
        let (t0, t1) = ((k - 1) as f64 / SAMPLES as f64, k as f64 / SAMPLES as f64);
        let step = libm::hypot((t1 - t0) * length, radius(t1) - radius(t0));
        cumulative[k] = cumulative[k - 1] + step;
    }
    let total = cumulative[SAMPLES];
    (1..=rings)
        .map(|i| {
            let target = total * i as f64 / (rings + 1) as f64;
            let k = cumulative
                .partition_point(|&s| s < target)
                .clamp(1, SAMPLES);
            let fraction = (target - cumulative[k - 1]) / (cumulative[k] - cumulative[k - 1]);
            (k - 1) as f64 / SAMPLES as f64 + fraction / SAMPLES as f64
        })
        .collect()
}

/// A spherical cap of curvature radius `curvature_m` and aperture (rim) radius `rim_m`, bulging
/// towards +z with its apex at the origin, triangulated as a hexagonal disc of
/// `rings` rings (1 + 3·rings·(rings+1) vertices). Normals point away from the sphere's centre.
pub fn spherical_cap(curvature_m: f64, rim_m: f64, rings: usize) -> MidSurface {
    let centre = Point3::new(0.0, 0.0, -curvature_m);
    let on_sphere = |x: f64, y: f64| {
        Point3::new(
            x,
            y,
            (curvature_m * curvature_m - x * x - y * y).sqrt() - curvature_m,
        )
    };
    let mut points = vec![on_sphere(0.0, 0.0)];
    for i in 1..=rings {
        let r = rim_m * i as f64 / rings as f64;
        points.extend((0..6 * i).map(|j| {
            let phi = 2.0 * PI * j as f64 / (6 * i) as f64;
            on_sphere(r * libm::cos(phi), r * libm::sin(phi))
        }));
    }
    // Vertex j of ring i (indices wrap around the ring); ring 0 is the apex.
    let vertex = |i: usize, j: usize| {
        if i == 0 {
            0
        } else {
            1 + 3 * i * (i - 1) + j % (6 * i)
        }
    };
    let mut triangles = Vec::with_capacity(6 * rings * rings);
    for i in 1..=rings {
        for sector in 0..6 {
            let (outer, inner) = (sector * i, sector * (i - 1));
            for j in 0..i {
                triangles.push([
                    vertex(i, outer + j),
                    vertex(i, outer + j + 1),
                    vertex(i - 1, inner + j),
                ]);
                if j + 1 < i {
                    triangles.push([
                        vertex(i - 1, inner + j),
                        vertex(i, outer + j + 1),
                        vertex(i - 1, inner + j + 1),
                    ]);
                }
            }
        }
    }
    let normals = points.iter().map(|p| (p - centre).normalize()).collect();
    let mut surface = MidSurface {
        points,
        normals,
        triangles,
    };
    orient_along_normals(&mut surface);
    surface
}

fn any_perpendicular(v: &Vector3<f64>) -> Vector3<f64> {
    if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    }
}

/// Area-weighted normals, with the triangles flipped first if the surface encloses a
/// negative volume (so normals point outward).
fn with_normals(points: Vec<Point3<f64>>, mut triangles: Vec<[usize; 3]>) -> MidSurface {
    let enclosed: f64 = triangles
        .iter()
        .map(|f| {
            points[f[0]]
                .coords
                .dot(&points[f[1]].coords.cross(&points[f[2]].coords))
        })
        .sum();
    if enclosed < 0.0 {
        for f in &mut triangles {
            f.swap(1, 2);
        }
    }
    let as_arrays: Vec<[f64; 3]> = points.iter().map(|p| p.coords.into()).collect();
    let normals = super::vertex_normals(&triangles, &as_arrays)
        .into_iter()
        .map(Vector3::from)
        .collect();
    MidSurface {
        points,
        normals,
        triangles,
    }
}

/// Flips triangles whose winding disagrees with the prescribed vertex normals.
fn orient_along_normals(surface: &mut MidSurface) {
    for f in &mut surface.triangles {
        let [a, b, c] = f.map(|v| surface.points[v]);
        if (b - a).cross(&(c - a)).dot(&surface.normals[f[0]]) < 0.0 {
            f.swap(1, 2);
        }
    }
}
