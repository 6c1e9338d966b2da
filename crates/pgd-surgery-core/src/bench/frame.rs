//! `pgd bench frame`: the render side's CPU work per frame for the four organs, each pressed
//! by the tool, timed frame by frame two ways in the same run: the baseline forms each organ's
//! whole displacement field and picks the surface vertices from it; the trainer's path forms
//! the surface vertices only ([`SurfaceModes`]). Both then recompute the vertex normals on the
//! deformed surface. Medians and p99 of the per-frame time, their ratio, and the largest
//! difference between the two paths' vertices (they must agree).

use std::fmt;
use std::time::Instant;

use nalgebra::Vector3;
use serde::Serialize;

use crate::contact::ContactSurface;
use crate::mesh::vertex_normals;
use crate::pgd::{Deformation, PatchLoad, SurfaceModes, Vademecum};

/// Per-frame time quantiles (ms).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct FrameTimes {
    pub p50_ms: f64,
    pub p99_ms: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FrameBenchReport {
    pub organs: Vec<String>,
    /// Surface vertices drawn over all organs.
    pub vertices: usize,
    pub frames: usize,
    /// Whole field, then the surface picked from it, then normals: the baseline.
    pub whole_field: FrameTimes,
    /// The surface vertices only, then normals: what the trainer does.
    pub surface_only: FrameTimes,
    /// `whole_field.p50_ms / surface_only.p50_ms`.
    pub speedup_p50: f64,
    /// The largest difference (m) between the two paths' deformed vertices.
    pub max_difference_m: f64,
}

/// One organ as a frame sees it: its vademecum, its deformation under a press, the triangles
/// drawn and scratch space for both paths.
struct Organ<'a> {
    vademecum: &'a Vademecum,
    deformation: Deformation,
    surface: SurfaceModes,
    triangles: Vec<[usize; 3]>,
    field: Vec<f64>,
    at_positions: Vec<f64>,
}

impl<'a> Organ<'a> {
    /// `vademecum` pressed by `force_n` on the tool's patch at the surface point nearest
    /// `point_m`.
    fn pressed(vademecum: &'a Vademecum, point_m: &Vector3<f64>, force_n: Vector3<f64>) -> Self {
        let mut deformation = Deformation::new(vademecum, 1);
        if let Some(hit) = ContactSurface::new(vademecum)
            .ok()
            .and_then(|s| s.closest(point_m))
        {
            deformation.loads[0] = PatchLoad {
                shares: vademecum.patch(&hit.at).shares,
                force_n,
            };
        }
        deformation.evaluate(vademecum);
        Self {
            vademecum,
            deformation,
            surface: SurfaceModes::new(vademecum),
            triangles: vademecum
                .triangles
                .iter()
                .map(|t| t.map(|m| m as usize))
                .collect(),
            field: vec![0.0; vademecum.dof_count()],
            at_positions: vec![0.0; 3 * vademecum.positions.len()],
        }
    }

    /// The baseline: the whole field, the surface vertices picked from it.
    fn whole_field(&mut self, positions: &mut Vec<[f32; 3]>) {
        let (v, d) = (self.vademecum, &self.deformation);
        d.field_into(v, &mut self.field);
        positions.clear();
        positions.extend(
            v.positions
                .iter()
                .zip(&v.position_coords_m)
                .map(|(&n, rest)| {
                    d.drawn_vertex(rest, &self.field[3 * n as usize..3 * n as usize + 3])
                }),
        );
    }

    fn surface_only(&mut self, positions: &mut Vec<[f32; 3]>) {
        let (v, d) = (self.vademecum, &self.deformation);
        d.deformed_surface(v, &self.surface, &mut self.at_positions, positions);
    }
}

/// Times `frames` frames of each path over `organs` (name, vademecum, the press's point and
/// outward normal), each organ pressed with `force_n` newtons into its surface.
pub fn run(
    organs: &[(String, &Vademecum, Vector3<f64>, Vector3<f64>)],
    force_n: f64,
    frames: usize,
) -> FrameBenchReport {
    let mut pressed: Vec<Organ> = organs
        .iter()
        .map(|(_, v, point, normal)| Organ::pressed(v, point, -normal * force_n))
        .collect();
    let mut positions = Vec::new();
    let mut reference = Vec::new();
    let mut max_difference_m: f64 = 0.0;
    for organ in &mut pressed {
        organ.whole_field(&mut reference);
        organ.surface_only(&mut positions);
        for (a, b) in reference.iter().zip(&positions) {
            for c in 0..3 {
                max_difference_m = max_difference_m.max((a[c] - b[c]).abs() as f64);
            }
        }
    }
    let mut time = |path: &dyn Fn(&mut Organ<'_>, &mut Vec<[f32; 3]>)| {
        let mut samples: Vec<f64> = (0..frames.max(1))
            .map(|_| {
                let started = Instant::now();
                for organ in &mut pressed {
                    path(organ, &mut positions);
                    std::hint::black_box(vertex_normals(&organ.triangles, &positions));
                }
                started.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        samples.sort_by(f64::total_cmp);
        let at = |q: f64| samples[((samples.len() - 1) as f64 * q).round() as usize];
        FrameTimes {
            p50_ms: at(0.5),
            p99_ms: at(0.99),
        }
    };
    let whole_field = time(&|o, p| o.whole_field(p));
    let surface_only = time(&|o, p| o.surface_only(p));
    FrameBenchReport {
        organs: organs.iter().map(|o| o.0.clone()).collect(),
        vertices: organs.iter().map(|o| o.1.positions.len()).sum(),
        frames,
        speedup_p50: whole_field.p50_ms / surface_only.p50_ms,
        whole_field,
        surface_only,
        max_difference_m,
    }
}

impl fmt::Display for FrameBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "render side's CPU work per frame: {} ({} surface vertices), {} frames each way",
            self.organs.join(", "),
            self.vertices,
            self.frames
        )?;
        writeln!(f, "{:<34} {:>9} {:>9}", "", "p50 ms", "p99 ms")?;
        for (name, t) in [
            ("whole field, surface picked", self.whole_field),
            ("surface vertices only (trainer)", self.surface_only),
        ] {
            writeln!(f, "{name:<34} {:>9.3} {:>9.3}", t.p50_ms, t.p99_ms)?;
        }
        writeln!(
            f,
            "surface only is {:.2}x faster at p50; the two agree to {:.1e} m",
            self.speedup_p50, self.max_difference_m
        )
    }
}
