//! Attached organs (paper 000: gallbladder and pancreas on the duodenum). The attached organ's
//! vademecum holds its attachment clamped; online the attachment follows the carrier instead.
//! Each tick the carrier's displacement over the interface, fitted by a rigid motion, carries
//! the attached organ along. The fit is linear in the carrier's modal coefficients, so it is
//! precomputed per mode and a tick costs `6 × modes` products.
//!
//! One way only, for now: the force on the attached organ (which its clamp takes) does not load
//! the carrier. Fed back explicitly, tick by tick, that loop (tool → gallbladder → duodenum →
//! carry → tool) has a gain near 1 on these soft organs and oscillates; it needs the carrier's
//! interface compliance in series with the tool's patch compliance, solved within the tick.

use nalgebra::{Matrix3, Vector3};

use super::modal_rows::ModalRows;
use crate::pgd::{RigidCarry, Vademecum};

#[derive(Clone, Debug, PartialEq)]
pub struct Attachment {
    /// Organ indices (the scene's order).
    pub carrier: usize,
    pub carried: usize,
    /// Carrier positions at the interface.
    interface: Vec<usize>,
    centre_m: Vector3<f64>,
    /// Per carrier mode (load steps concatenated): the fitted translation and rotation.
    translation: Vec<Vector3<f64>>,
    rotation: Vec<Vector3<f64>>,
}

impl Attachment {
    /// The attachment over the carrier's load positions `interface`; `None` when it is empty.
    pub fn new(
        carrier: usize,
        carried: usize,
        carrier_vademecum: &Vademecum,
        interface: &[usize],
    ) -> Option<Self> {
        let v = carrier_vademecum;
        let point = |m: usize| Vector3::from(v.position_coords_m[m].map(f64::from));
        let area: f64 = interface
            .iter()
            .map(|&m| v.position_areas_m2[m] as f64)
            .sum();
        if interface.is_empty() || area <= 0.0 {
            return None;
        }
        let centre_m =
            interface.iter().map(|&m| point(m)).sum::<Vector3<f64>>() / interface.len() as f64;
        let arms: Vec<Vector3<f64>> = interface.iter().map(|&m| point(m) - centre_m).collect();
        let inertia: Matrix3<f64> = arms
            .iter()
            .map(|r| Matrix3::identity() * r.norm_squared() - r * r.transpose())
            .sum();
        let inverse = inertia.try_inverse().unwrap_or_else(Matrix3::zeros);
        let rows = ModalRows::displacements(v, interface.iter().map(|&m| [(m, 1.0)]));
        let modes = v.total_modes();
        let mut translation = vec![Vector3::zeros(); modes];
        let mut rotation = vec![Vector3::zeros(); modes];
        for k in 0..modes {
            let mut unit = vec![0.0f32; modes];
            unit[k] = 1.0;
            let moved: Vec<Vector3<f64>> = (0..interface.len())
                .map(|i| rows.apply(i, &unit).map(f64::from))
                .collect();
            let mean = moved.iter().sum::<Vector3<f64>>() / moved.len() as f64;
            translation[k] = mean;
            let torque: Vector3<f64> = arms
                .iter()
                .zip(&moved)
                .map(|(r, u)| r.cross(&(u - mean)))
                .sum();
            rotation[k] = inverse * torque;
        }
        Some(Self {
            carrier,
            carried,
            interface: interface.to_vec(),
            centre_m,
            translation,
            rotation,
        })
    }

    /// The rigid motion that carries the attached organ, for carrier coefficients `alpha`.
    pub fn carry(&self, alpha: &[f32]) -> RigidCarry {
        let sum = |per_mode: &[Vector3<f64>]| -> Vector3<f64> {
            per_mode.iter().zip(alpha).map(|(v, &a)| v * a as f64).sum()
        };
        RigidCarry {
            translation_m: sum(&self.translation),
            rotation_rad: sum(&self.rotation),
            centre_m: self.centre_m,
        }
    }

    /// The carrier positions of the interface.
    pub fn interface(&self) -> &[usize] {
        &self.interface
    }
}
