//! `pgd validate`: a vademecum against full FEM on its own mesh, at random loads it was not
//! built on, printed as a table.

use std::path::Path;

use super::pgd_build::write_convergence;
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
