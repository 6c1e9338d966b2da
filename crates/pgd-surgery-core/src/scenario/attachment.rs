//! Connective tissue a scenario puts between two organs, written `Attachment(…)`: the organ
//! to be freed, the organ it lies on, how close their surfaces must face each other to be
//! tied, and the tissue's cohesive law where not the gallbladder bed's.

use serde::Deserialize;

use super::scene::OrganEntry;
use super::units::{FractureEnergy, PeakTraction, TieGap, TieStiffness};
use crate::contact::ContactSurface;
use crate::dissection::{Bed, BedError, CohesiveError, CohesiveLaw, FreedSurface};
use crate::mesh::{Surface, TetMesh};

/// The gap the default scene's gallbladder bed ties within (mm).
pub const DEFAULT_TIE_GAP_MM: f64 = 3.0;

/// One organ bound to another where their surfaces face each other at rest.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Attachment", deny_unknown_fields)]
pub struct AttachmentEntry {
    /// The organ the trainee frees (the gallbladder).
    pub organ: String,
    /// The organ it lies on (the liver).
    pub to: String,
    /// Ties wherever the two surfaces face each other within this gap (mm, 0.5 to 10;
    /// 3 when left out).
    #[serde(default)]
    pub gap_mm: Option<TieGap>,
    /// The energy that frees a square metre (J/m², 1 to 1000; 50 when left out).
    #[serde(default)]
    pub fracture_energy_j_per_m2: Option<FractureEnergy>,
    /// The largest traction the tissue carries (Pa, 100 to 100000; 5000 when left out).
    #[serde(default)]
    pub peak_traction_pa: Option<PeakTraction>,
    /// Traction per metre of opening before damage (Pa/m, 1e5 to 1e9; 5e6 when left out).
    #[serde(default)]
    pub stiffness_pa_per_m: Option<TieStiffness>,
}

impl AttachmentEntry {
    /// The gallbladder in its bed on the liver, with the default tissue.
    pub fn gallbladder_bed() -> Self {
        Self {
            organ: "gallbladder".into(),
            to: "liver".into(),
            gap_mm: None,
            fracture_energy_j_per_m2: None,
            peak_traction_pa: None,
            stiffness_pa_per_m: None,
        }
    }

    pub fn gap_m(&self) -> f64 {
        self.gap_mm.map_or(DEFAULT_TIE_GAP_MM, |g| g.0) * 1e-3
    }

    /// The tissue's law: the gallbladder bed's, with what the entry sets in its place.
    pub fn law(&self) -> Result<CohesiveLaw, CohesiveError> {
        let bed = CohesiveLaw::gallbladder_bed();
        CohesiveLaw::new(
            self.stiffness_pa_per_m
                .map_or(bed.stiffness_pa_per_m, |k| k.0),
            self.peak_traction_pa.map_or(bed.peak_traction_pa, |t| t.0),
            (self.fracture_energy_j_per_m2).map_or(bed.fracture_energy_j_per_m2, |g| g.0),
        )
    }
}

/// Whether `freed`'s surface faces `base`'s within `gap_m` anywhere, on their outline meshes
/// ([`OrganEntry::outline_mesh`]); `None` when a mesh cannot be had.
pub(super) fn facing(
    freed: &OrganEntry,
    base: &OrganEntry,
    gap_m: f64,
) -> Option<Result<(), BedError>> {
    let (freed_mesh, base_mesh) = (freed.outline_mesh()?, base.outline_mesh()?);
    let freed_surface = Surface::extract(&freed_mesh);
    let coords = surface_coords(&freed_surface, &freed_mesh);
    let normals = freed_surface.vertex_normals(&freed_mesh);
    let areas: Vec<f32> = (freed_surface.vertex_areas(&freed_mesh).iter())
        .map(|&a| a as f32)
        .collect();
    let freed = FreedSurface {
        coords_m: &coords,
        normals: &normals,
        areas_m2: &areas,
    };
    let base_surface = Surface::extract(&base_mesh);
    let triangles = (base_surface.local_triangles().iter())
        .map(|t| t.map(|v| v as u32))
        .collect();
    let base = ContactSurface::of_triangles(
        &surface_coords(&base_surface, &base_mesh),
        triangles,
        base_surface.vertex_normals(&base_mesh),
    )
    .ok()?;
    let law = CohesiveLaw::gallbladder_bed();
    Some(Bed::between(law, &freed, |at| base.closest(at), gap_m).map(|_| ()))
}

/// The surface's vertices (m).
fn surface_coords(surface: &Surface, mesh: &TetMesh) -> Vec<[f32; 3]> {
    (surface.nodes.iter())
        .map(|&n| mesh.nodes()[n].cast::<f32>().into())
        .collect()
}
