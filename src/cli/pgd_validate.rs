//! `pgd validate`: a vademecum against full FEM on its own mesh, at random loads it was not
//! built on, printed as a table.

use std::path::{Path, PathBuf};

use super::LoadedMesh;
use super::pgd_build::write_convergence;
use crate::cutting::keratotomy::Cornea;
use crate::cutting::{
    CutPattern, CutValidationReport, CutValidationSettings, ExactResponse, UncutResponse,
    validate_incisions, validate_keratotomy,
};
use crate::fem::FemModel;
use crate::mesh::organs::Organ;
use crate::pgd::{self, ValidationReport, ValidationSettings};
use crate::report::{LineChart, Series, line_chart};
use crate::store::Bar;

/// Checks the vademecum in `file` against full FEM on `mesh` (the organ `source` names, if it
/// names one), at the random loads `settings` draws for that organ; writes its convergence
/// curves beside it first.
pub fn validate_vademecum(
    source: &str,
    LoadedMesh { organ, mesh, .. }: LoadedMesh,
    file: &Path,
    settings: impl Fn(Option<Organ>) -> ValidationSettings,
) -> Result<ValidationReport, String> {
    let vademecum = pgd::load(file).map_err(|e| e.to_string())?;
    write_convergence(file, &vademecum.header)?;
    vademecum
        .check_mesh(file, &mesh)
        .map_err(|e| e.to_string())?;
    let model = pgd::organ::clamped_model(mesh, vademecum.header.material)
        .and_then(|model| model.with_inclusions(&vademecum.header.inclusions))
        .map_err(|e| format!("{source}: {e}"))?;
    pgd::validate(&model, &vademecum, &settings(organ), &Bar::default())
        .map_err(|e| format!("{source}: {e}"))
}

/// The validation's errors as a table: felt force, whole field, near field.
pub fn print_validation(report: &ValidationReport) {
    if report.beyond_range {
        println!("pressed beyond the vademecum's range, from each point's edge (--beyond-range)");
    }
    let title = format!("{} random loads against full FEM", report.samples.len());
    println!(
        "{title:<38}{:>8}{:>10}{:>10}{:>10}",
        "mean", "p50", "p95", "max"
    );
    let near = format!(
        "displacement field, within {} mm",
        report.near_radius_m * 1e3
    );
    for (name, s) in [
        ("felt force for the same indentation", &report.force_error),
        ("displacement field, whole organ", &report.field_error),
        (near.as_str(), &report.near_field_error),
    ] {
        println!(
            "  {name:<36} {:>7.3} % {:>7.3} % {:>7.3} % {:>7.3} %",
            100.0 * s.mean,
            100.0 * s.p50,
            100.0 * s.p95,
            100.0 * s.max
        );
    }
    if let Some(edge) = &report.range_edge_m {
        let least_m = report
            .samples
            .iter()
            .map(|s| s.range_edge_m)
            .fold(f64::INFINITY, f64::min);
        println!(
            "  the load steps answer the tool's linear depth to {:.1} mm at these points (p50; \
             {:.1} mm at the least, {:.1} mm at the most); deeper, the felt force is \
             extrapolated from the last load-step interval (--beyond-range measures it)",
            edge.p50 * 1e3,
            least_m * 1e3,
            edge.max * 1e3
        );
    }
}

/// Each force–depth curve of `report` as a table: full FEM's indentation and force, the
/// vademecum's force for that indentation.
pub fn print_force_depth(report: &ValidationReport) {
    for (k, curve) in report.curves.iter().enumerate() {
        let [x, y, z] = curve.point_m.map(|c| c * 1e3);
        println!(
            "press {} along the normal at ({x:.1}, {y:.1}, {z:.1}) mm: largest force error {:.1} %",
            k + 1,
            100.0 * curve.max_force_error()
        );
        println!("  depth (mm)   full FEM (N)   vademecum (N)");
        for ((d, f), v) in curve
            .depth_m
            .iter()
            .zip(&curve.fem_force_n)
            .zip(&curve.vademecum_force_n)
        {
            println!("  {:>10.2} {:>14.5} {:>15.5}", d * 1e3, f, v);
        }
        if let Some(reason) = &curve.stopped {
            println!("  full FEM stops there: {reason}");
        }
    }
}

/// Draws the force–depth curves of full FEM and the vademecum side by side, beside the
/// vademecum (`FILE.force-depth.png`), and returns where; nothing when there are no curves
/// (`--curves 0`), which would leave the chart without a range.
pub fn plot_force_depth(
    report: &ValidationReport,
    vademecum: &Path,
) -> Result<Option<PathBuf>, String> {
    if report.curves.is_empty() {
        return Ok(None);
    }
    let path = vademecum.with_extension("force-depth.png");
    let curve_points = |depths: &[f64], forces: &[f64]| {
        std::iter::once((0.0, 0.0))
            .chain(depths.iter().zip(forces).map(|(d, f)| (d * 1e3, *f)))
            .collect()
    };
    let series = report
        .curves
        .iter()
        .enumerate()
        .flat_map(|(k, curve)| {
            [
                Series {
                    name: format!("press {}: full FEM", k + 1),
                    points: curve_points(&curve.depth_m, &curve.fem_force_n),
                },
                Series {
                    name: format!("press {}: vademecum", k + 1),
                    points: curve_points(&curve.depth_m, &curve.vademecum_force_n),
                },
            ]
        })
        .collect();
    let name = vademecum.file_name().unwrap_or_default().to_string_lossy();
    line_chart(
        &path,
        &LineChart {
            title: format!("{name}: force against depth under the tool"),
            x_label: "indentation under the tool (mm)",
            y_label: "force (N)",
            series,
        },
    )?;
    Ok(Some(path))
}

/// Checks the cut section of the vademecum in `file` against full X-FEM on `mesh` (as it was
/// built), on the random patterns `settings` draws: radial keratotomies of the cornea under the
/// intraocular pressure, straight incisions into another organ's accessible face under the
/// tool. With `exact`, the cut state runs on the factorized stiffness instead (the reference
/// path).
pub fn validate_cuts(
    source: &str,
    LoadedMesh { organ, mesh, .. }: LoadedMesh,
    file: &Path,
    settings: &CutValidationSettings,
    exact: bool,
) -> Result<CutValidationReport, String> {
    let vademecum = pgd::load(file).map_err(|e| e.to_string())?;
    vademecum
        .check_mesh(file, &mesh)
        .map_err(|e| e.to_string())?;
    let Some(cuts) = &vademecum.cuts else {
        return Err(format!(
            "{}: built without a cut section; rebuild it with `pgd build {source} --cuts` \
             (and the mesh options it was built with)",
            file.display()
        ));
    };
    let in_source = |e: &dyn std::fmt::Display| format!("{source}: {e}");
    let material = vademecum.header.material;
    let site = match (settings.pattern, organ) {
        (CutPattern::Radial(_), Some(Organ::Cornea)) => {
            Site::Cornea(Cornea::from_mesh(mesh, material).map_err(|e| in_source(&e))?)
        }
        (CutPattern::Straight(_), organ) if organ != Some(Organ::Cornea) => Site::Organ(Box::new(
            pgd::organ::clamped_model(mesh, material)
                .and_then(|model| model.with_inclusions(&vademecum.header.inclusions))
                .map_err(|e| in_source(&e))?,
        )),
        (pattern, _) => {
            return Err(format!(
                "{source}: {pattern} does not apply (radial:N cuts the cornea, straight:N the \
                 other organs)"
            ));
        }
    };
    let model = match &site {
        Site::Cornea(cornea) => cornea.model(),
        Site::Organ(model) => model,
    };
    let factorized = match exact {
        true => Some(ExactResponse::new(model).map_err(|e| in_source(&e))?),
        false => None,
    };
    let response: &dyn UncutResponse = match &factorized {
        Some(exact) => exact,
        None => cuts,
    };
    let validated = match &site {
        Site::Cornea(cornea) => validate_keratotomy(cornea, &response, settings),
        Site::Organ(model) => validate_incisions(model, &response, settings),
    };
    validated.map_err(|e| in_source(&e))
}

/// What a cut pattern is validated on.
enum Site {
    Cornea(Cornea),
    Organ(Box<FemModel>),
}

/// The cut validation as a table.
pub fn print_cut_validation(report: &CutValidationReport) {
    println!(
        "{} random patterns of {} against full X-FEM ({} nodes), {} refused   mean       p95       max",
        report.cases.len(),
        report.pattern,
        report.nodes,
        report.failed
    );
    for (name, s) in [
        (
            "displacement under the load (rel. L2)",
            &report.cut_l2_error,
        ),
        ("force felt beside an incision", &report.force_error),
    ] {
        println!(
            "  {name:<52} {:>9.2e} {:>9.2e} {:>9.2e}",
            s.mean, s.p95, s.max
        );
    }
    for case in report.cases.iter().filter(|c| c.failed.is_some()) {
        println!(
            "  refused: {} ({})",
            case.pattern,
            case.failed.as_deref().unwrap_or_default()
        );
    }
    println!(
        "one incision segment online: {:.2} ms median; full X-FEM solve: {:.0} ms median",
        report.segment_ms.p50, report.full_xfem_ms.p50
    );
}
