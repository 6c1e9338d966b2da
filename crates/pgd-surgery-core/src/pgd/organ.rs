//! The mechanical model of each generated organ: its material and its clamped region, as in
//! paper 000, ready for a vademecum build.

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

/// The tool an organ is pressed with and the region around it the trainee watches.
///
/// The abdominal organs are pressed by laparoscopic instruments (a 12 mm tip) and watched over
/// 2 cm around it (the dimple and its rim). The cornea (11.5 mm across, 0.5 mm thick) is
/// pressed by a 1 mm ophthalmic spatula and watched over the bending length of its shell,
/// `√(R t) ≈ √(7.8 mm × 0.5 mm) ≈ 2 mm`, beyond which a load on a thin shell is felt only
/// through its global shape. With the abdominal radii the cornea lay wholly inside every
/// load's near field: one mode, a 3.7 GB file (docs/pgd.md).
pub fn tool_radii_m(organ: Option<Organ>) -> ToolRadii {
    match organ {
        Some(Organ::Cornea) => ToolRadii {
            tool_tip_m: 0.5e-3,
            watched_m: 2e-3,
        },
        _ => ToolRadii {
            tool_tip_m: 6e-3,
            watched_m: 0.02,
        },
    }
}

/// See [`tool_radii_m`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolRadii {
    pub tool_tip_m: f64,
    /// The field is watched within this distance (m) of the tool's centre.
    pub watched_m: f64,
}

impl ToolRadii {
    /// The radius (m) around each loaded node within which the vademecum keeps the exact
    /// response: the watched region plus the patch, so that the nodes a tool's patch loads,
    /// up to a tool radius from its centre, all carry their exact response over the whole
    /// watched region, and the field there is exact by linearity.
    pub fn near_field_m(&self) -> f64 {
        self.watched_m + self.tool_tip_m
    }
}

/// How deep nonlinear load steps press an organ, against the liver: the smallest side of its
/// generated mesh's bounding box (its thickness, how far a tool pressed into it can go before
/// it meets the organ's other side) over the liver's 100 mm, so that each abdominal organ is
/// pressed to the same share of its thickness: 25 mm of the liver is 10.5 mm of the
/// pancreas (42 mm thick), 6 mm of the duodenum (24 mm). 1 for a mesh file, taken as liver,
/// and for the cornea, whose steps follow its own tool.
pub fn press_scale(organ: Option<Organ>) -> f64 {
    match organ {
        Some(Organ::Gallbladder) => 0.39,
        Some(Organ::Pancreas) => 0.42,
        Some(Organ::Duodenum) => 0.24,
        Some(Organ::Liver | Organ::Cornea) | None => 1.0,
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
        stiffening: law.default_stiffening(),
    }
}

/// A model of `mesh` with `material`, its `clamped` node set held fixed.
pub fn clamped_model(mesh: TetMesh, material: Material) -> Result<FemModel, FemError> {
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set(region::CLAMPED)?)?;
    FemModel::new(mesh, material, dirichlet)
}
