//! Element quality and surface topology: what a user needs to trust a mesh, computed on raw
//! arrays so that it can also describe a mesh that is about to be refused.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::{DEGENERATE_QUALITY, quality};

/// Below (above) this dihedral angle a mesh is refused: stiffness matrices of such elements
/// are so ill-conditioned that solves lose most of their digits.
pub const REFUSED_MIN_DIHEDRAL_DEG: f64 = 1.0;
pub const REFUSED_MAX_DIHEDRAL_DEG: f64 = 179.0;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct QualityReport {
    pub nodes: usize,
    pub tets: usize,
    pub volume_m3: f64,
    pub min_dihedral_deg: f64,
    pub max_dihedral_deg: f64,
    /// The tetrahedra with the smallest and the largest dihedral angle.
    pub min_dihedral_tet: Option<usize>,
    pub max_dihedral_tet: Option<usize>,
    /// Longest edge over the inradius, normalized to 1 for the regular tetrahedron.
    pub max_aspect_ratio: f64,
    pub mean_aspect_ratio: f64,
    /// Tetrahedra with negative volume, and the first of them.
    pub inverted: usize,
    pub first_inverted: Option<usize>,
    /// Tetrahedra of (nearly) zero volume, and the first of them.
    pub degenerate: usize,
    pub first_degenerate: Option<usize>,
    pub surface_triangles: usize,
    /// Surface edges used by one boundary triangle only (holes in the surface).
    pub open_edges: usize,
    /// Surface edges shared by more than two boundary triangles.
    pub non_manifold_edges: usize,
}

impl QualityReport {
    /// Measures a mesh given as raw arrays; indices must be in range.
    pub fn measure(nodes: &[Point3<f64>], tets: &[[usize; 4]]) -> Self {
        let mut report = Self {
            nodes: nodes.len(),
            tets: tets.len(),
            volume_m3: 0.0,
            min_dihedral_deg: f64::INFINITY,
            max_dihedral_deg: 0.0,
            min_dihedral_tet: None,
            max_dihedral_tet: None,
            max_aspect_ratio: 0.0,
            mean_aspect_ratio: 0.0,
            inverted: 0,
            first_inverted: None,
            degenerate: 0,
            first_degenerate: None,
            surface_triangles: 0,
            open_edges: 0,
            non_manifold_edges: 0,
        };
        for (t, tet) in tets.iter().enumerate() {
            let p = tet.map(|n| nodes[n]);
            let q = quality(&p);
            if q.abs() < DEGENERATE_QUALITY {
                report.degenerate += 1;
                report.first_degenerate.get_or_insert(t);
                continue;
            }
            if q < 0.0 {
                report.inverted += 1;
                report.first_inverted.get_or_insert(t);
            }
            report.volume_m3 += super::signed_volume(&p);
            let (lo, hi) = dihedral_range_deg(&p);
            if lo < report.min_dihedral_deg {
                (report.min_dihedral_deg, report.min_dihedral_tet) = (lo, Some(t));
            }
            if hi > report.max_dihedral_deg {
                (report.max_dihedral_deg, report.max_dihedral_tet) = (hi, Some(t));
            }
            let aspect = aspect_ratio(&p);
            report.max_aspect_ratio = report.max_aspect_ratio.max(aspect);
            report.mean_aspect_ratio += aspect / tets.len() as f64;
        }
        report.measure_surface(tets);
        report
    }

    fn measure_surface(&mut self, tets: &[[usize; 4]]) {
        let mut faces: HashMap<[usize; 3], u32> = HashMap::new();
        for tet in tets {
            for skip in 0..4 {
                let mut f = [0; 3];
                let mut k = 0;
                for (i, &n) in tet.iter().enumerate() {
                    if i != skip {
                        f[k] = n;
                        k += 1;
                    }
                }
                f.sort_unstable();
                *faces.entry(f).or_default() += 1;
            }
        }
        let mut edges: HashMap<(usize, usize), u32> = HashMap::new();
        for (f, _) in faces.iter().filter(|&(_, &count)| count == 1) {
            self.surface_triangles += 1;
            for (a, b) in [(f[0], f[1]), (f[1], f[2]), (f[0], f[2])] {
                *edges.entry((a, b)).or_default() += 1;
            }
        }
        self.open_edges = edges.values().filter(|&&c| c == 1).count();
        self.non_manifold_edges = edges.values().filter(|&&c| c > 2).count();
    }

    /// Closed and edge-manifold: every surface edge joins exactly two boundary triangles.
    pub fn watertight(&self) -> bool {
        self.open_edges == 0 && self.non_manifold_edges == 0
    }

    /// Why the mesh cannot be simulated, if it cannot.
    pub fn refusal(&self) -> Option<String> {
        if let Some(t) = self.first_inverted {
            return Some(format!(
                "{} inverted tetrahedra (first: tetrahedron {t})",
                self.inverted
            ));
        }
        if let Some(t) = self.first_degenerate {
            return Some(format!(
                "{} degenerate (zero-volume) tetrahedra (first: tetrahedron {t})",
                self.degenerate
            ));
        }
        if !self.watertight() {
            return Some(format!(
                "the boundary surface is not watertight and manifold ({} open edges, {} edges shared by more than two faces)",
                self.open_edges, self.non_manifold_edges
            ));
        }
        if self.poorly_shaped() {
            let tet = |t: Option<usize>| t.map_or(String::new(), |t| format!(" (tetrahedron {t})"));
            return Some(format!(
                "dihedral angles from {:.2}°{} to {:.2}°{} (accepted: {REFUSED_MIN_DIHEDRAL_DEG}° to {REFUSED_MAX_DIHEDRAL_DEG}°)",
                self.min_dihedral_deg,
                tet(self.min_dihedral_tet),
                self.max_dihedral_deg,
                tet(self.max_dihedral_tet)
            ));
        }
        None
    }

    /// Slivers or needles: a dihedral angle outside what is accepted.
    pub fn poorly_shaped(&self) -> bool {
        self.min_dihedral_deg < REFUSED_MIN_DIHEDRAL_DEG
            || self.max_dihedral_deg > REFUSED_MAX_DIHEDRAL_DEG
    }
}

impl std::fmt::Display for QualityReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{} nodes, {} tetrahedra, {} surface triangles, volume {:.2} cm³",
            self.nodes,
            self.tets,
            self.surface_triangles,
            self.volume_m3 * 1e6
        )?;
        writeln!(
            f,
            "dihedral angles {:.1}° – {:.1}°, aspect ratio max {:.2} (mean {:.2}; 1 is a regular tetrahedron)",
            self.min_dihedral_deg,
            self.max_dihedral_deg,
            self.max_aspect_ratio,
            self.mean_aspect_ratio
        )?;
        writeln!(
            f,
            "inverted: {}, degenerate: {}, surface: {}",
            self.inverted,
            self.degenerate,
            if self.watertight() {
                "watertight and manifold".to_owned()
            } else {
                format!(
                    "{} open edges, {} non-manifold edges",
                    self.open_edges, self.non_manifold_edges
                )
            }
        )?;
        match self.refusal() {
            Some(why) => write!(f, "REFUSED: {why}"),
            None => write!(f, "usable for simulation"),
        }
    }
}

/// Smallest and largest of the six dihedral angles, in degrees.
pub fn dihedral_range_deg(p: &[Point3<f64>; 4]) -> (f64, f64) {
    // Normal of the face opposite each vertex, pointing away from that vertex.
    let normals: [Vector3<f64>; 4] = std::array::from_fn(|k| {
        let [a, b, c] = [(k + 1) % 4, (k + 2) % 4, (k + 3) % 4].map(|i| p[i]);
        let n = (b - a).cross(&(c - a)).normalize();
        if n.dot(&(p[k] - a)) > 0.0 { -n } else { n }
    });
    let mut range = (f64::INFINITY, 0.0_f64);
    for k in 0..4 {
        for l in k + 1..4 {
            let angle = std::f64::consts::PI - normals[k].dot(&normals[l]).clamp(-1.0, 1.0).acos();
            let deg = angle.to_degrees();
            range = (range.0.min(deg), range.1.max(deg));
        }
    }
    range
}

/// Longest edge over (2√6 × inradius): 1 for the regular tetrahedron, large for slivers.
pub fn aspect_ratio(p: &[Point3<f64>; 4]) -> f64 {
    let mut longest = 0.0_f64;
    for i in 0..4 {
        for j in i + 1..4 {
            longest = longest.max((p[i] - p[j]).norm());
        }
    }
    let area: f64 = (0..4)
        .map(|k| {
            let [a, b, c] = [(k + 1) % 4, (k + 2) % 4, (k + 3) % 4].map(|i| p[i]);
            (b - a).cross(&(c - a)).norm() / 2.0
        })
        .sum();
    let inradius = 3.0 * super::signed_volume(p).abs() / area;
    longest / (2.0 * 6.0_f64.sqrt() * inradius)
}
