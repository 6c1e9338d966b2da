//! `pgd validate`: a vademecum against full FEM on its own mesh, at random loads it was not
//! built on, printed as a table.

use std::path::Path;

use super::pgd_build::write_convergence;
use crate::cutting::keratotomy::Cornea;
use crate::cutting::{
    CutPattern, CutValidationReport, CutValidationSettings, ExactResponse, UncutResponse,
    validate_incisions, validate_keratotomy,
};
use crate::fem::FemModel;
use crate::mesh::TetMesh;
use crate::mesh::organs::Organ;
use crate::pgd::{self, ValidationReport, ValidationSettings};
use crate::store::Bar;

/// Checks the vademecum in `file` against full FEM on `mesh` (the organ `source` names, if it
/// names one), at the random loads `settings` draws for that organ; writes its convergence
/// curves beside it first.
pub fn validate_vademecum(
    source: &str,
    (organ, mesh): (Option<Organ>, TetMesh),
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
    println!(
        "{} random loads against full FEM       mean       p50       p95       max",
        report.samples.len()
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
}

/// Checks the cut section of the vademecum in `file` against full X-FEM on `mesh` (as it was
/// built), on the random patterns `settings` draws: radial keratotomies of the cornea under the
/// intraocular pressure, straight incisions into another organ's accessible face under the
/// tool. With `exact`, the cut state runs on the factorized stiffness instead (the reference
/// path).
pub fn validate_cuts(
    source: &str,
    (organ, mesh): (Option<Organ>, TetMesh),
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
