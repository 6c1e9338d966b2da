//! The import benchmark (`pgd bench import`): an organ as a segmentation tool gives it, the
//! generated liver's boundary in millimetres as binary STL, read, mended, checked for
//! crossings and tetrahedralized at the node count asked; once as the liver's own surface
//! (the baseline) and once subdivided (each triangle into four, its corners and edge middles
//! on the same planes) until it has the triangles asked (49,312 by default). Per surface:
//! the whole import's time (median and slowest of the repeats) and the crossing check's.

use std::collections::HashMap;
use std::fmt;
use std::path::Path;
use std::time::Instant;

use nalgebra::Point3;
use serde::Serialize;

use super::fem::{median, quantile};
use crate::mesh::io::{Faces, ImportOptions, SurfaceMesh, parse, self_crossing};
use crate::mesh::organs::{Organ, OrganSettings, generate};
use crate::mesh::{MeshDensity, Surface, TetMesh};

#[derive(Clone, Debug, Serialize)]
pub struct ImportFigures {
    pub triangles: usize,
    pub stl_bytes: usize,
    pub import_p50_s: f64,
    pub import_max_s: f64,
    pub crossing_check_p50_s: f64,
    pub nodes: usize,
    pub tets: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct ImportBenchReport {
    pub repeats: usize,
    pub target_nodes: usize,
    /// The liver's own surface.
    pub baseline: ImportFigures,
    pub subdivided: ImportFigures,
    /// The subdivided surface's import time over the baseline's (medians).
    pub ratio: f64,
}

/// Imports the liver's surface and the surface subdivided to at least `triangles` triangles,
/// `repeats` times each, at `target_nodes` nodes; writes the subdivided one to `stl_out` if
/// given.
pub fn run(
    triangles: usize,
    target_nodes: usize,
    repeats: usize,
    stl_out: Option<&Path>,
) -> Result<ImportBenchReport, String> {
    let liver = generate(Organ::Liver, &OrganSettings::default()).map_err(|e| e.to_string())?;
    let mut surface = surface_mm(&liver);
    let baseline = time_import(&surface, target_nodes, repeats)?;
    while surface.triangles.len() < triangles {
        surface = subdivided(&surface);
    }
    let subdivided = time_import(&surface, target_nodes, repeats)?;
    if let Some(file) = stl_out {
        std::fs::write(file, binary_stl(&surface))
            .map_err(|e| format!("{}: {e}", file.display()))?;
    }
    Ok(ImportBenchReport {
        repeats,
        target_nodes,
        ratio: subdivided.import_p50_s / baseline.import_p50_s,
        baseline,
        subdivided,
    })
}

/// `mesh`'s boundary in millimetres, in single precision as segmentation tools write it.
fn surface_mm(mesh: &TetMesh) -> SurfaceMesh {
    let surface = Surface::extract(mesh);
    SurfaceMesh {
        vertices: (mesh.nodes().iter())
            .map(|p| p.map(|c| f64::from((c * 1e3) as f32)))
            .collect(),
        triangles: surface.triangles,
    }
}

/// Each triangle into four through its edges' middles (each middle made once).
fn subdivided(surface: &SurfaceMesh) -> SurfaceMesh {
    let mut vertices = surface.vertices.clone();
    let mut middles: HashMap<(usize, usize), usize> = HashMap::new();
    let mut middle = |a: usize, b: usize, vertices: &mut Vec<Point3<f64>>| {
        *middles.entry((a.min(b), a.max(b))).or_insert_with(|| {
            vertices.push(nalgebra::center(&vertices[a], &vertices[b]));
            vertices.len() - 1
        })
    };
    let mut triangles = Vec::with_capacity(4 * surface.triangles.len());
    for &[a, b, c] in &surface.triangles {
        let ab = middle(a, b, &mut vertices);
        let bc = middle(b, c, &mut vertices);
        let ca = middle(c, a, &mut vertices);
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    SurfaceMesh {
        vertices,
        triangles,
    }
}

/// `surface` as binary STL.
fn binary_stl(surface: &SurfaceMesh) -> Vec<u8> {
    let mut stl = vec![0u8; 80];
    stl.extend((surface.triangles.len() as u32).to_le_bytes());
    for face in &surface.triangles {
        stl.extend([0u8; 12]);
        for &v in face {
            stl.extend((surface.vertices[v].iter()).flat_map(|&c| (c as f32).to_le_bytes()));
        }
        stl.extend([0u8; 2]);
    }
    stl
}

fn time_import(
    surface: &SurfaceMesh,
    target_nodes: usize,
    repeats: usize,
) -> Result<ImportFigures, String> {
    let stl = binary_stl(surface);
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(target_nodes),
        ..ImportOptions::default()
    };
    let mut imports = Vec::new();
    let mut checks = Vec::new();
    let mut mesh = None;
    for _ in 0..repeats.max(1) {
        let started = Instant::now();
        let imported = parse(Path::new("bench.stl"), stl.clone(), &options);
        imports.push(started.elapsed().as_secs_f64());
        mesh = Some(imported.map_err(|e| e.to_string())?);
        let started = Instant::now();
        let faces = Faces {
            vertices: &surface.vertices,
            triangles: &surface.triangles,
        };
        if self_crossing(faces).is_some() {
            return Err("the benchmark's surface crosses itself".into());
        }
        checks.push(started.elapsed().as_secs_f64());
    }
    let mesh = mesh.expect("at least one import");
    Ok(ImportFigures {
        triangles: surface.triangles.len(),
        stl_bytes: stl.len(),
        import_p50_s: median(imports.clone()),
        import_max_s: quantile(&imports, 1.0),
        crossing_check_p50_s: median(checks),
        nodes: mesh.node_count(),
        tets: mesh.tet_count(),
    })
}

impl fmt::Display for ImportBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "import benchmark: the liver's surface as binary STL in mm, mended, checked for \
             crossings and stuffed at {} nodes; {} repeats",
            self.target_nodes, self.repeats
        )?;
        writeln!(
            f,
            "{:>12} {:>10} {:>11} {:>11} {:>14} {:>7} {:>7}",
            "surface", "triangles", "import p50", "import max", "crossings p50", "nodes", "tets"
        )?;
        for (name, r) in [("liver", &self.baseline), ("subdivided", &self.subdivided)] {
            writeln!(
                f,
                "{name:>12} {:>10} {:>10.2}s {:>10.2}s {:>13.3}s {:>7} {:>7}",
                r.triangles,
                r.import_p50_s,
                r.import_max_s,
                r.crossing_check_p50_s,
                r.nodes,
                r.tets
            )?;
        }
        write!(f, "subdivided over liver: {:.2}x", self.ratio)
    }
}
