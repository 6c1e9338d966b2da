//! An organ's dynamic model, made once when its scene is set up: its lowest modes from its
//! vademecum, its reduced KSV energy in them, and the tissue's damping.

use nalgebra::{Matrix3, Vector3};

use super::{
    DynamicsError, EnergyMomentum, GraspPoint, GraspSettings, GraspedOrgan, ModalBasis, ModeFit,
    RayleighDamping, ReducedKsv,
};
use crate::fem::FemModel;
use crate::pgd::Vademecum;

/// Modes kept per organ in the trainer: the four organs step in 21 µs p99 at 8 modes
/// (`pgd bench dynamics`), beside the rest of the tick.
pub const TRAINER_MODES: usize = 8;

/// The damping ratio of liver tissue at the kept modes' ends (`docs/dynamics.md`).
pub const TISSUE_DAMPING_RATIO: f64 = 0.1;

/// What an organ needs to move: shared by its haptic state and the window (which draws the
/// kept modes on the surface).
pub struct DynamicModel {
    pub basis: ModalBasis,
    pub reduced: ReducedKsv,
    pub damping: RayleighDamping,
    /// The kept modes in the vademecum's modes: how contact and attachments see the motion.
    pub fit: ModeFit,
}

impl DynamicModel {
    /// The model of `model` (under the KSV law) in the `modes` lowest modes found from
    /// `vademecum`, damped at [`TISSUE_DAMPING_RATIO`].
    pub fn new(
        model: &FemModel,
        vademecum: &Vademecum,
        modes: usize,
    ) -> Result<Self, DynamicsError> {
        let basis = ModalBasis::of_vademecum(model, vademecum, modes)?;
        let reduced = ReducedKsv::new(model, &basis)?;
        let omega = |k: usize| basis.omega2[k].sqrt();
        let damping =
            RayleighDamping::with_ratio(TISSUE_DAMPING_RATIO, omega(0), omega(basis.len() - 1));
        let fit = ModeFit::new(&basis, vademecum);
        Ok(Self {
            basis,
            reduced,
            damping,
            fit,
        })
    }

    /// Adds the kept modes times `correction` (m) to the surface `positions`, vertex `k` being
    /// volume node `nodes[k]`: what the organ's motion adds to the vademecum's static field.
    pub fn add_to_surface(&self, nodes: &[u32], correction: &[f64], positions: &mut [[f32; 3]]) {
        for (k, &c) in correction.iter().enumerate() {
            let mode = self.basis.mode(k);
            for (p, &node) in positions.iter_mut().zip(nodes) {
                let at = 3 * node as usize;
                for (axis, v) in p.iter_mut().enumerate() {
                    *v += (c * mode[at + axis]) as f32;
                }
            }
        }
    }

    /// The organ at rest with open jaws, stepped at `step_s`.
    pub fn at_rest(&self, step_s: f64, settings: GraspSettings) -> GraspedOrgan {
        let step = EnergyMomentum::new(&self.reduced, &self.basis.omega2, step_s, self.damping);
        let nowhere = GraspPoint::at_patch(&self.basis, &[], Vector3::zeros(), &Matrix3::zeros());
        GraspedOrgan::new(self.reduced.clone(), step, nowhere, settings)
    }
}
