//! The mechanical model of each generated organ: its material and its clamped region, as in
//! paper 000 (see `../shared/BRIEF.md`), ready for a vademecum build.

use crate::fem::{Dirichlet, FemError, FemModel, Law, Material, TISSUE_DENSITY_KG_M3};
use crate::mesh::TetMesh;
use crate::mesh::organs::{Organ, region};

/// Young's modulus (Pa) of each organ. Liver and gallbladder: paper 000. Pancreas: shear
/// modulus 1.2 kPa by elastography, so E = 2G(1 + ν). Duodenum: no figure in the papers; it is
/// attached to the pancreas and taken as stiff as it. Cornea: papers give no modulus; 0.3 MPa
/// is mid-range of published in-vivo values (0.1–1 MPa).
pub fn young_pa(organ: Organ) -> f64 {
    match organ {
        Organ::Liver => 1600.0,
        Organ::Gallbladder => 1150.0,
        Organ::Pancreas | Organ::Duodenum => 2.0 * 1200.0 * (1.0 + POISSON),
        Organ::Cornea => 3.0e5,
    }
}

/// Nearly incompressible soft tissue, as in paper 000.
pub const POISSON: f64 = 0.48;

pub fn material(organ: Organ, law: Law) -> Material {
    Material {
        law,
        young_pa: young_pa(organ),
        poisson: POISSON,
        density_kg_m3: TISSUE_DENSITY_KG_M3,
    }
}

/// A model of `mesh` with `material`, its `clamped` node set held fixed.
pub fn clamped_model(mesh: TetMesh, material: Material) -> Result<FemModel, FemError> {
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set(region::CLAMPED)?)?;
    FemModel::new(mesh, material, dirichlet)
}
