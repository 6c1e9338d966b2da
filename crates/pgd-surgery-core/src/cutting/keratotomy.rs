//! Radial keratotomy: incisions along meridians of the cornea, from the optical zone's edge
//! towards the limbus, a fraction of its thickness deep. Under the intraocular pressure the
//! weakened periphery bulges and the centre flattens; the outcome is the change of the
//! central corneal power, in dioptres, read from the curvature of the deformed anterior
//! surface as a keratometer reads it.
//!
//! Solved by the full X-FEM of the cut cornea: a reference, not the 1 kHz path.

use std::sync::Arc;

use nalgebra::{Matrix2, Point3, Unit, Vector2, Vector3};
use serde::Serialize;

use super::enrichment::{Enrichment, Front};
use super::incision::CutFace;
use super::{CutError, xfem};
use crate::fem::{Dirichlet, FemModel, Law, Loads, Material, TISSUE_DENSITY_KG_M3};
use crate::mesh::organs::{
    CORNEA_CURVATURE_M, CORNEA_RIM_M, CORNEA_THICKNESS_M, Organ, OrganSettings, generate, region,
};
use crate::mesh::{Surface, TetMesh};

/// Intraocular pressure: 15 mmHg (Pa).
pub const IOP_PA: f64 = 15.0 * 133.322;

/// The keratometric index: a keratometer reads power as `(1.3375 − 1) / R`.
pub const KERATOMETRIC_INDEX: f64 = 1.3375;

/// Young's modulus of the human cornea in vivo, 0.29 ± 0.06 MPa: Pye, "A clinical method for
/// estimating the modulus of elasticity of the human cornea in vivo", PLoS ONE 15(1),
/// e0224824 (2020). Nearly incompressible, as soft tissue is.
pub const CORNEA_YOUNG_PA: f64 = 0.29e6;
pub const CORNEA_POISSON: f64 = 0.49;

/// The reference cornea's mesh: its resolution (a multiple of the generator's nodes per
/// layer) and its elements through the thickness. A keratotomy's correction depends on the
/// mesh (`docs/cutting.md`, Limits), so every prediction is made on this one.
pub const REFERENCE_MESH: (f64, usize) = (0.6, 8);

/// The central zone whose curvature a keratometer reads: 3 mm across.
const CENTRAL_ZONE_M: f64 = 1.5e-3;

/// Incisions stop this far inside the clamped rim (the limbus).
const LIMBUS_MARGIN_M: f64 = 0.5e-3;

/// One radial keratotomy: how many incisions, evenly spaced, starting at the optical zone's
/// edge (its diameter), how deep as a fraction of the cornea's thickness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Keratotomy {
    pub incisions: usize,
    pub optical_zone_m: f64,
    pub depth_fraction: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeratotomyReport {
    pub incisions: usize,
    pub optical_zone_mm: f64,
    pub depth_fraction: f64,
    /// Central power under the intraocular pressure, uncut and cut (D).
    pub central_power_before_d: f64,
    pub central_power_after_d: f64,
    pub central_power_change_d: f64,
    pub nodes: usize,
    pub enriched_nodes: usize,
}

impl std::fmt::Display for KeratotomyReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "radial keratotomy: {} incisions, optical zone {:.1} mm, {:.0} % deep ({} nodes, {} enriched)",
            self.incisions,
            self.optical_zone_mm,
            100.0 * self.depth_fraction,
            self.nodes,
            self.enriched_nodes
        )?;
        writeln!(
            f,
            "central power under 15 mmHg: {:.2} D before, {:.2} D after: change {:+.2} D",
            self.central_power_before_d, self.central_power_after_d, self.central_power_change_d
        )
    }
}

/// The cornea under intraocular pressure, ready to be cut.
pub struct Cornea {
    model: Arc<FemModel>,
    loads: Loads,
    /// Anterior nodes within the central zone.
    central: Vec<usize>,
    power_before_d: f64,
}

impl Cornea {
    /// The generated cornea (rim clamped) at `resolution` of its nodes per layer, with
    /// `layers` elements through its thickness, the intraocular pressure on its posterior
    /// face.
    pub fn new(resolution: f64, layers: usize) -> Result<Self, CutError> {
        let settings = OrganSettings {
            resolution,
            cornea_layers: layers,
            ..OrganSettings::default()
        };
        let mesh = generate(Organ::Cornea, &settings).map_err(solve_error)?;
        let material = Material::new(
            Law::Linear,
            CORNEA_YOUNG_PA,
            CORNEA_POISSON,
            TISSUE_DENSITY_KG_M3,
        )
        .map_err(solve_error)?;
        Self::from_mesh(mesh, material)
    }

    /// The reference cornea ([`REFERENCE_MESH`]) of the in-vivo modulus: the one `pgd cut
    /// cornea` cuts by default, and the trainer predicts every keratotomy's correction on,
    /// whatever detail it runs its organs at.
    pub fn reference() -> Result<Self, CutError> {
        Self::new(REFERENCE_MESH.0, REFERENCE_MESH.1)
    }

    /// The generated cornea `mesh` (any resolution and layers) of `material`, rim clamped,
    /// under the intraocular pressure: as a cornea vademecum was built.
    pub fn from_mesh(mesh: TetMesh, material: Material) -> Result<Self, CutError> {
        let mut dirichlet = Dirichlet::new(mesh.node_count());
        let rim = mesh
            .node_set(region::CLAMPED)
            .map_err(solve_error)?
            .to_vec();
        dirichlet.clamp(&rim).map_err(solve_error)?;
        let model = FemModel::new(mesh, material, dirichlet).map_err(solve_error)?;
        Self::from_model(Arc::new(model))
    }

    /// The generated cornea's `model` (its rim clamped, as the trainer's cut cornea is) under
    /// the intraocular pressure.
    pub fn from_model(model: Arc<FemModel>) -> Result<Self, CutError> {
        let mesh = model.mesh();
        let mut loads = Loads::new(mesh.node_count());
        loads
            .add_pressure(mesh, &posterior_faces(mesh), IOP_PA)
            .map_err(solve_error)?;
        let central = anterior_nodes(mesh)
            .into_iter()
            .filter(|&n| {
                let p = mesh.nodes()[n];
                p.x.hypot(p.y) <= CENTRAL_ZONE_M
            })
            .collect();
        let mut cornea = Self {
            model,
            loads,
            central,
            power_before_d: 0.0,
        };
        let uncut = Enrichment::new(cornea.model.mesh(), &[]);
        cornea.power_before_d = cornea.central_power_d(&uncut)?;
        Ok(cornea)
    }

    /// The intraocular pressure's nodal forces (N).
    pub fn pressure(&self) -> &Loads {
        &self.loads
    }

    pub fn model(&self) -> &FemModel {
        &self.model
    }

    /// The faces of a keratotomy's incisions: meridians at even angles.
    pub fn faces(&self, plan: &Keratotomy) -> Result<Vec<CutFace>, CutError> {
        if plan.incisions == 0 || !(0.0..=1.0).contains(&plan.depth_fraction) {
            return Err(CutError::Degenerate(format!(
                "{} incisions {} deep (at least one, at most the whole thickness)",
                plan.incisions, plan.depth_fraction
            )));
        }
        (0..plan.incisions)
            .map(|k| {
                let angle = std::f64::consts::TAU * k as f64 / plan.incisions as f64;
                let reach = (plan.optical_zone_m / 2.0, INCISION_END_M);
                incision(angle, reach, plan.depth_fraction)
            })
            .collect()
    }

    /// The keratotomy's outcome under the intraocular pressure.
    pub fn cut(&self, plan: &Keratotomy) -> Result<KeratotomyReport, CutError> {
        let enrichment = Enrichment::new(self.model.mesh(), &self.faces(plan)?);
        let after = self.central_power_d(&enrichment)?;
        let mut enriched: Vec<usize> = enrichment.functions.iter().map(|f| f.node).collect();
        enriched.sort_unstable();
        enriched.dedup();
        Ok(KeratotomyReport {
            incisions: plan.incisions,
            optical_zone_mm: plan.optical_zone_m * 1e3,
            depth_fraction: plan.depth_fraction,
            central_power_before_d: self.power_before_d,
            central_power_after_d: after,
            central_power_change_d: after - self.power_before_d,
            nodes: self.model.mesh().node_count(),
            enriched_nodes: enriched.len(),
        })
    }

    /// The change of central power (D) that incisions along `faces` make, their fronts
    /// snapped as `front` says (as the cut state that made them snaps them).
    pub fn power_change_d(&self, faces: &[CutFace], front: Front) -> Result<f64, CutError> {
        let enrichment = Enrichment::with_front(self.model.mesh(), faces, front);
        Ok(self.central_power_d(&enrichment)? - self.power_before_d)
    }

    /// The keratometric power of the deformed anterior centre (D).
    fn central_power_d(&self, enrichment: &Enrichment) -> Result<f64, CutError> {
        let solution = xfem::solve(&self.model, enrichment, &self.loads)?;
        let mesh = self.model.mesh();
        let deformed: Vec<Point3<f64>> = self
            .central
            .iter()
            .map(|&n| {
                mesh.nodes()[n] + Vector3::from_column_slice(&solution.nodes_m[3 * n..3 * n + 3])
            })
            .collect();
        Ok((KERATOMETRIC_INDEX - 1.0) / sphere_radius_on_axis(&deformed))
    }
}

/// Where radial incisions end: 0.5 mm inside the limbus (m off the axis).
pub const INCISION_END_M: f64 = CORNEA_RIM_M - LIMBUS_MARGIN_M;

/// A radial incision at `angle_rad` round the axis, from `reach.0` to `reach.1` off it (m),
/// `depth_fraction` of the thickness deep.
pub fn incision(
    angle_rad: f64,
    reach: (f64, f64),
    depth_fraction: f64,
) -> Result<CutFace, CutError> {
    CutFace::meridian(
        Point3::new(0.0, 0.0, -CORNEA_CURVATURE_M),
        ANTERIOR_RADIUS_M,
        Unit::new_unchecked(Vector3::z()),
        angle_rad,
        reach.0,
        reach.1,
        depth_fraction * CORNEA_THICKNESS_M,
    )
}

/// The point of the anterior surface `r_m` off the axis at `azimuth_rad` round it (from +x
/// towards +y), in the generated cornea's frame.
pub fn anterior_point(azimuth_rad: f64, r_m: f64) -> Point3<f64> {
    let height = (ANTERIOR_RADIUS_M.powi(2) - r_m.powi(2)).max(0.0).sqrt();
    let (sin, cos) = azimuth_rad.sin_cos();
    Point3::new(r_m * cos, r_m * sin, height - CORNEA_CURVATURE_M)
}

/// [`incision`] at `azimuth_rad` round the axis from the scene's +x towards +y (where
/// [`CutFace::meridian`] counts its angle from −x).
pub fn azimuth_incision(
    azimuth_rad: f64,
    reach: (f64, f64),
    depth_fraction: f64,
) -> Result<CutFace, CutError> {
    incision(azimuth_rad + std::f64::consts::PI, reach, depth_fraction)
}

/// The anterior and posterior spheres' radii (m), about the cornea's centre of curvature.
pub const ANTERIOR_RADIUS_M: f64 = CORNEA_CURVATURE_M + CORNEA_THICKNESS_M / 2.0;
const POSTERIOR_RADIUS_M: f64 = CORNEA_CURVATURE_M - CORNEA_THICKNESS_M / 2.0;

/// The boundary nodes on the sphere of `radius_m` (within a hundredth of the thickness).
fn nodes_on_sphere(mesh: &TetMesh, radius_m: f64) -> impl Fn(usize) -> bool + '_ {
    let centre = Point3::new(0.0, 0.0, -CORNEA_CURVATURE_M);
    move |n| ((mesh.nodes()[n] - centre).norm() - radius_m).abs() <= CORNEA_THICKNESS_M / 100.0
}

/// The anterior face's nodes: where the tool presses and the keratometer reads.
pub fn anterior_nodes(mesh: &TetMesh) -> Vec<usize> {
    let on = nodes_on_sphere(mesh, ANTERIOR_RADIUS_M);
    Surface::extract(mesh)
        .nodes
        .into_iter()
        .filter(|&n| on(n))
        .collect()
}

/// The posterior face: the boundary triangles on the posterior sphere.
fn posterior_faces(mesh: &TetMesh) -> Vec<[usize; 3]> {
    let on = nodes_on_sphere(mesh, POSTERIOR_RADIUS_M);
    Surface::extract(mesh)
        .triangles
        .into_iter()
        .filter(|t| t.iter().all(|&n| on(n)))
        .collect()
}

fn solve_error(e: impl std::fmt::Display) -> CutError {
    CutError::Solve(e.to_string())
}

/// The radius of the sphere centred on the z axis that fits `points` best: the least squares
/// of `x² + y² + z² = 2 h z + k`, linear in the centre's height `h` and `k = R² − h²`.
fn sphere_radius_on_axis(points: &[Point3<f64>]) -> f64 {
    let (mut normal, mut rhs) = (Matrix2::zeros(), Vector2::zeros());
    for p in points {
        let row = Vector2::new(2.0 * p.z, 1.0);
        normal += row * row.transpose();
        rhs += row * p.coords.norm_squared();
    }
    let solution = normal.lu().solve(&rhs).unwrap_or_else(Vector2::zeros);
    let (h, k) = (solution.x, solution.y);
    (k + h * h).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An incision at 60° from +x covers the anterior point 3 mm off the axis at 60°, 0.1 mm
    /// under the surface, and not the one at 240°.
    #[test]
    fn an_incision_by_azimuth_lies_at_that_azimuth() {
        let face = azimuth_incision(60f64.to_radians(), (1.5e-3, 5e-3), 0.8).unwrap();
        let under = |azimuth_deg: f64| {
            let on_surface = anterior_point(azimuth_deg.to_radians(), 3e-3);
            let centre = Point3::new(0.0, 0.0, -CORNEA_CURVATURE_M);
            assert!(((on_surface - centre).norm() - ANTERIOR_RADIUS_M).abs() < 1e-15);
            on_surface - (on_surface - centre).normalize() * 1e-4
        };
        assert!(face.covers(&under(60.0), 1e-9));
        assert!(!face.covers(&under(240.0), 1e-9));
    }

    /// Points on a sphere of radius 8 mm centred 7.8 mm below the origin, as a cap 3 mm across:
    /// the fit returns its radius.
    #[test]
    fn the_fit_reads_a_sphere_s_radius() {
        let (radius, centre) = (8.0e-3, Point3::new(0.0, 0.0, -7.8e-3));
        let points: Vec<Point3<f64>> = (0..50)
            .map(|i| {
                let (theta, phi) = (0.18 * (i % 7) as f64 / 7.0, 0.7 * i as f64);
                centre
                    + Vector3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    ) * radius
            })
            .collect();
        assert!((sphere_radius_on_axis(&points) - radius).abs() < 1e-12);
    }
}
