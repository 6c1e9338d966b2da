//! The vademecums the trainer runs on: found in `vademecums/`, checked against the organ's
//! mesh and material, and rebuilt (with progress shown) when missing or stale, so that the
//! trainer never runs on a vademecum built for something else.

use std::path::{Path, PathBuf};

use crate::fem::{Law, Material};
use crate::mesh::organs::{self, Organ, OrganSettings, region};
use crate::pgd::{self, BuildSettings, OrganModel, Vademecum, VademecumError};

use super::Bar;

/// What to do with a missing or stale vademecum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnStale {
    /// Build it now and save it, showing progress.
    Rebuild,
    /// Fail with the command that builds it.
    Refuse,
}

/// Where the vademecum of a generated organ lives, under `dir`.
pub fn vademecum_path(dir: &Path, organ: Organ) -> PathBuf {
    dir.join(format!("{}.vdm", organ.name()))
}

/// The command a user runs to build what [`ensure_vademecum`] wants.
pub fn build_command(organ: Organ, law: Law, file: &Path) -> String {
    let law = match law {
        Law::Linear => "linear",
        Law::KirchhoffSaintVenant => "ksv",
    };
    format!(
        "cargo run --release --bin pgd -- build {} --law {law} --out {}",
        organ.name(),
        file.display()
    )
}

/// The vademecum of `organ` (default mesh, its material under `law`) from `dir`, checked for
/// its mesh and material; a missing or stale one is rebuilt or refused per `on_stale`.
pub fn ensure_vademecum(
    dir: &Path,
    organ: Organ,
    law: Law,
    on_stale: OnStale,
) -> Result<Vademecum, String> {
    let file = vademecum_path(dir, organ);
    let mesh = organs::generate(organ, &OrganSettings::default())
        .map_err(|e| format!("{}: {e}", organ.name()))?;
    let material = pgd::organ::material(organ, law);
    let why = match checked(&file, &mesh, &material) {
        Ok(vademecum) => return Ok(vademecum),
        Err(why) => why,
    };
    let command = build_command(organ, law, &file);
    if on_stale == OnStale::Refuse {
        return Err(format!("{why}\nbuild it with:\n  {command}"));
    }
    eprintln!("{why}\nbuilding it now (the same as `{command}`):");
    let model =
        pgd::organ::clamped_model(mesh, material).map_err(|e| format!("{}: {e}", organ.name()))?;
    let organ_model = OrganModel {
        source: organ.name().into(),
        model: &model,
        clamped_region: region::CLAMPED.into(),
        accessible_region: region::ACCESSIBLE.into(),
    };
    let (vademecum, _) = pgd::build(&organ_model, &BuildSettings::default(), &Bar::default())
        .map_err(|e| format!("{}: {e}", organ.name()))?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    pgd::save(&file, &vademecum).map_err(|e| e.to_string())?;
    let [csv, png] = super::write_of_header(&file, &vademecum.header)?;
    eprintln!(
        "wrote {} (convergence curves: {} and {})",
        file.display(),
        csv.display(),
        png.display()
    );
    Ok(vademecum)
}

/// Loads `file` and refuses it unless it was built for `mesh` and `material`.
fn checked(
    file: &Path,
    mesh: &crate::mesh::TetMesh,
    material: &Material,
) -> Result<Vademecum, VademecumError> {
    let vademecum = pgd::load(file)?;
    vademecum.check_mesh(file, mesh)?;
    vademecum.check_material(file, material)?;
    Ok(vademecum)
}
