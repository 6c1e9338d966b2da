//! Heterogeneous tissue: a stiffer (or softer) spherical inclusion in an organ, such as a
//! tumour a trainee must find by palpation. Inside it Young's modulus is the organ's times a
//! ratio (Poisson's ratio and density unchanged), element by element.

use nalgebra::Point3;
use serde::{Deserialize, Serialize};

use super::FemError;
use crate::mesh::TetMesh;

/// A sphere of tissue `stiffness_ratio` times as stiff as the rest of the organ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Inclusion {
    pub centre_m: [f64; 3],
    pub radius_m: f64,
    /// Young's modulus inside over Young's modulus outside.
    pub stiffness_ratio: f64,
}

impl Inclusion {
    /// Refuses a non-finite centre, a radius or ratio that is not positive and finite.
    pub fn validate(&self) -> Result<(), FemError> {
        let bad = |what, value| {
            Err(FemError::InvalidInput {
                what,
                value,
                problem: "not a positive, finite number",
            })
        };
        if let Some(&c) = self.centre_m.iter().find(|c| !c.is_finite()) {
            return Err(FemError::InvalidInput {
                what: "inclusion centre (m)",
                value: c,
                problem: "not finite",
            });
        }
        if !(self.radius_m.is_finite() && self.radius_m > 0.0) {
            return bad("inclusion radius (m)", self.radius_m);
        }
        if !(self.stiffness_ratio.is_finite() && self.stiffness_ratio > 0.0) {
            return bad("inclusion stiffness ratio", self.stiffness_ratio);
        }
        Ok(())
    }

    /// Whether the element with these corners belongs to the inclusion: its centroid is inside.
    fn holds(&self, corners: [&Point3<f64>; 4]) -> bool {
        let centroid = corners
            .iter()
            .fold(Point3::origin(), |acc, p| acc + p.coords)
            / 4.0;
        (centroid - Point3::from(self.centre_m)).norm() <= self.radius_m
    }
}

/// Per element of `mesh`, the factor on Young's modulus the inclusions give it (1 outside them;
/// where two overlap, the later one's ratio). An inclusion that holds no element's centroid is
/// refused: it would change nothing, and the trainee would search for a nodule that is not there.
pub fn modulus_scale(mesh: &TetMesh, inclusions: &[Inclusion]) -> Result<Vec<f64>, FemError> {
    let mut scale = vec![1.0; mesh.tet_count()];
    for inclusion in inclusions {
        inclusion.validate()?;
        let mut held = 0;
        for (tet, factor) in mesh.tets().iter().zip(&mut scale) {
            if inclusion.holds(tet.map(|n| &mesh.nodes()[n])) {
                *factor = inclusion.stiffness_ratio;
                held += 1;
            }
        }
        if held == 0 {
            return Err(FemError::InvalidInput {
                what: "inclusion radius (m)",
                value: inclusion.radius_m,
                problem: "too small to hold any element of the mesh, or its centre lies outside the organ",
            });
        }
    }
    Ok(scale)
}
