//! `pgd indent`: the full nonlinear force–depth curve of an organ pressed by the tool, one per
//! material law, printed as a table (or JSON) and drawn side by side in a PNG.

use std::path::Path;
use std::time::Instant;

use nalgebra::Point3;
use serde::Serialize;

use super::LoadedMesh;
use crate::fem::{FemModel, IndentationSettings, Material, SphereIndenter};
use crate::mesh::organs::region;
use crate::mesh::{Surface, TetMesh};
use crate::pgd::{Progress, organ};
use crate::report::{LineChart, Series, line_chart};

/// The default depth over the tool's radius: 25 mm under the abdominal 6 mm tool, the deepest
/// a trainee presses, and the same proportion for the cornea's 0.5 mm spatula.
const DEPTH_OVER_TOOL_RADIUS: f64 = 25.0 / 6.0;

/// Where and how deep to press.
pub struct IndentRequest<'a> {
    pub source: &'a str,
    /// The press point (mm), moved to the nearest accessible surface node; by default the
    /// accessible node nearest the accessible face's centroid.
    pub at_mm: Option<[f64; 3]>,
    /// Deepest depth (mm); by default the organ's `DEPTH_OVER_TOOL_RADIUS`.
    pub depth_mm: Option<f64>,
    pub steps: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct IndentReport {
    pub source: String,
    pub point_m: [f64; 3],
    /// Unit direction of the press (into the organ, against the surface's normal).
    pub direction: [f64; 3],
    pub tool_radius_m: f64,
    pub curves: Vec<LawCurve>,
}

#[derive(Clone, Debug, Serialize)]
pub struct LawCurve {
    pub law: &'static str,
    pub young_pa: f64,
    pub poisson: f64,
    pub depth_m: Vec<f64>,
    pub force_n: Vec<f64>,
    /// The depth (m) where Newton found no equilibrium, and why; the curve stops before it.
    pub stopped_at_m: Option<f64>,
    pub stop_reason: Option<String>,
    pub seconds: f64,
}

/// Presses the organ `mesh` (with `clamped` and `accessible` regions) with its tool, once per
/// material, from rest to the requested depth in `request.steps` equal steps.
pub fn indent_organ(
    LoadedMesh { organ, mesh, .. }: LoadedMesh,
    materials: &[Material],
    request: &IndentRequest,
    progress: &dyn Progress,
) -> Result<IndentReport, String> {
    let radius_m = organ::tool_radii_m(organ).tool_tip_m;
    let depth_m = request
        .depth_mm
        .map_or(DEPTH_OVER_TOOL_RADIUS * radius_m, |mm| mm * 1e-3);
    if !(depth_m.is_finite() && depth_m > 0.0) || request.steps == 0 {
        return Err(format!(
            "--depth-mm must be positive and --steps at least 1 (got {} mm, {} steps)",
            depth_m * 1e3,
            request.steps
        ));
    }
    let surface = Surface::extract(&mesh);
    let normals = surface.vertex_normals(&mesh);
    let (index, node) = press_node(&mesh, &surface, request.at_mm)?;
    let indenter = SphereIndenter::new(radius_m, mesh.nodes()[node], -normals[index])
        .map_err(|e| e.to_string())?;
    let depths: Vec<f64> = (1..=request.steps)
        .map(|k| depth_m * k as f64 / request.steps as f64)
        .collect();
    let mut curves = Vec::with_capacity(materials.len());
    for material in materials {
        let model = organ::clamped_model(mesh.clone(), *material).map_err(|e| e.to_string())?;
        progress.start(
            &format!("{} to {:.1} mm", material.law.name(), depth_m * 1e3),
            depths.len() as u64,
        );
        curves.push(law_curve(
            &model,
            &surface.triangles,
            &indenter,
            &depths,
            progress,
        )?);
    }
    Ok(IndentReport {
        source: request.source.to_owned(),
        point_m: indenter.contact_point.into(),
        direction: indenter.direction.into(),
        tool_radius_m: radius_m,
        curves,
    })
}

fn law_curve(
    model: &FemModel,
    surface: &[[usize; 3]],
    indenter: &SphereIndenter,
    depths: &[f64],
    progress: &dyn Progress,
) -> Result<LawCurve, String> {
    let clock = Instant::now();
    let settings = IndentationSettings::default();
    let indentation = model
        .indent(surface, indenter, depths, &settings, &mut |_| {
            progress.advance(1)
        })
        .map_err(|e| e.to_string())?;
    let material = model.material();
    Ok(LawCurve {
        law: material.law.name(),
        young_pa: material.young_pa,
        poisson: material.poisson,
        depth_m: indentation.curve.iter().map(|p| p.depth_m).collect(),
        force_n: indentation.curve.iter().map(|p| p.force_n).collect(),
        stopped_at_m: indentation.stopped.as_ref().map(|(depth, _)| *depth),
        stop_reason: indentation.stopped.map(|(_, error)| error.to_string()),
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// The accessible surface node to press: nearest `at_mm`, or nearest the accessible nodes'
/// centroid. Returns its index in the surface and its node number.
fn press_node(
    mesh: &TetMesh,
    surface: &Surface,
    at_mm: Option<[f64; 3]>,
) -> Result<(usize, usize), String> {
    let mut accessible: Vec<usize> = mesh
        .face_set(region::ACCESSIBLE)
        .map_err(|e| e.to_string())?
        .iter()
        .flatten()
        .copied()
        .collect();
    accessible.sort_unstable();
    accessible.dedup();
    let candidates: Vec<(usize, usize)> = surface
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| accessible.binary_search(n).is_ok())
        .map(|(i, &n)| (i, n))
        .collect();
    if candidates.is_empty() {
        return Err("the mesh has no accessible surface node to press".into());
    }
    let target = match at_mm {
        Some(mm) => Point3::from(mm.map(|c| c * 1e-3)),
        None => Point3::from(
            candidates
                .iter()
                .map(|&(_, n)| mesh.nodes()[n].coords)
                .sum::<nalgebra::Vector3<f64>>()
                / candidates.len() as f64,
        ),
    };
    let distance = |n: usize| (mesh.nodes()[n] - target).norm();
    Ok(*candidates
        .iter()
        .min_by(|a, b| distance(a.1).total_cmp(&distance(b.1)))
        .expect("not empty"))
}

/// The curves as a table: force at each depth, one column per law.
pub fn print_indentation(report: &IndentReport) {
    let p = report.point_m.map(|c| c * 1e3);
    println!(
        "{}: tool of radius {:.1} mm pressed at ({:.1}, {:.1}, {:.1}) mm",
        report.source,
        report.tool_radius_m * 1e3,
        p[0],
        p[1],
        p[2]
    );
    let mut header = format!("{:>10}", "depth mm");
    for curve in &report.curves {
        header += &format!(" {:>14}", format!("{} N", curve.law));
    }
    println!("{header}");
    // Every curve shares the depths; the longest lists the most of them.
    let depths = report
        .curves
        .iter()
        .map(|c| &c.depth_m)
        .max_by_key(|d| d.len())
        .map_or(&[][..], |d| &d[..]);
    for (row, depth) in depths.iter().enumerate() {
        let mut line = format!("{:>10.2}", depth * 1e3);
        for curve in &report.curves {
            line += &match curve.force_n.get(row) {
                Some(force) => format!(" {force:>14.5}"),
                None => format!(" {:>14}", "-"),
            };
        }
        println!("{line}");
    }
    for curve in &report.curves {
        if let (Some(depth), Some(reason)) = (curve.stopped_at_m, &curve.stop_reason) {
            println!("{} stops before {:.2} mm: {reason}", curve.law, depth * 1e3);
        }
    }
}

/// Draws every law's force against depth on one chart.
pub fn plot_indentation(report: &IndentReport, path: &Path) -> Result<(), String> {
    let series = report
        .curves
        .iter()
        .map(|curve| Series {
            name: curve.law.to_owned(),
            points: std::iter::once((0.0, 0.0))
                .chain(
                    curve
                        .depth_m
                        .iter()
                        .zip(&curve.force_n)
                        .map(|(d, f)| (d * 1e3, *f)),
                )
                .collect(),
        })
        .collect();
    line_chart(
        path,
        &LineChart {
            title: format!("{}: force against depth", report.source),
            x_label: "depth (mm)",
            y_label: "force (N)",
            series,
        },
    )
}
