//! The tool holding an organ where it presses, as the contact solve of one tick sees it.
//!
//! The tool holds the surface under its tip ([`super::press`]): when a contact force moves
//! that surface, the tool's load changes until the surface is back under the tip, and pushes
//! the organ back into whatever pushed it. Solved one after the other, tick by tick, the tool
//! and the contact fought: the contact pushed the organ away, the tool pushed it back on the
//! next tick, and on the coarse scene liver nodes sank 12 mm into the gallbladder. So the
//! contact solve takes the tool's answer into its compliance. A contact force's coefficients
//! `Δc` move the surface under the tool by `B Δc` (`B`: 3 × modes, each mode's displacement
//! averaged over the tool's patch); the tool takes that move back with the load
//! `−K B Δc` (`K`: the inverse of the patch compliance), whose coefficients are `−Y B Δc`
//! (`Y`: modes × 3, the coefficients of the loads `K e_a`). The organ's part of the normal
//! compliance becomes `D (I − Y B) Lᵀ`: the compliance of the organ with the patch held, the
//! Schur complement of the patch compliance, symmetric and positive because the patch
//! compliance holds the modal one and more. After the solve, the tool's load follows the
//! move the contact forces make in the same tick, so the trainee feels the organ behind at
//! once.

use nalgebra::{Matrix3, Vector3};

use super::ToolContact;
use crate::pgd::{PatchLoad, Vademecum};

/// One organ's hold by the tool this tick, linearized (see the module's documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolHold {
    held: bool,
    /// `Y`, direction after direction: the modal coefficients of `K e_a`, all load steps
    /// concatenated (per metre).
    pub(super) coefficients_per_m: [Vec<f32>; 3],
    /// `B`, direction after direction: per unit coefficient of each mode, how far the surface
    /// under the tool moves along `e_a`, averaged over the patch (m).
    pub(super) moved_per_coefficient_m: [Vec<f32>; 3],
    /// One load step's coefficients, before they are scaled.
    scratch: Vec<f64>,
}

impl ToolHold {
    pub fn is_held(&self) -> bool {
        self.held
    }

    /// The tool presses the organ as `contact` with `load`: takes its answer to a move of
    /// the surface under it. Allocates nothing once grown.
    pub fn hold(&mut self, vademecum: &Vademecum, contact: &ToolContact, load: &PatchLoad) {
        let stiffness = &contact.stiffness_n_per_m;
        self.held = load.is_active() && *stiffness != Matrix3::zeros();
        if !self.held {
            return;
        }
        for a in 0..3 {
            self.coefficients_per_m[a].clear();
            self.moved_per_coefficient_m[a].clear();
            self.gather_coefficients(vademecum, &stiffness.column(a).into(), a, load);
            self.gather_moves(vademecum, a, load);
        }
    }

    /// `Y e_a`. A KSV vademecum picks its load steps by the force's size, so the load `K e_a`
    /// is scaled to the tool's force and its coefficients back.
    fn gather_coefficients(
        &mut self,
        vademecum: &Vademecum,
        direction: &Vector3<f64>,
        a: usize,
        load: &PatchLoad,
    ) {
        let scale = match vademecum.steps.len() {
            1 => 1.0,
            _ => load.force_n.norm() / direction.norm(),
        };
        for step in 0..vademecum.steps.len() {
            self.scratch.clear();
            self.scratch.resize(vademecum.modes(step), 0.0);
            let force = direction * scale;
            vademecum.add_coefficients(step, &load.shares, &force, &mut self.scratch);
            let per_m = self.scratch.iter().map(|c| (c / scale) as f32);
            self.coefficients_per_m[a].extend(per_m);
        }
    }

    /// `B`'s row `a`: each mode's displacement along `e_a`, averaged over the patch.
    fn gather_moves(&mut self, vademecum: &Vademecum, a: usize, load: &PatchLoad) {
        for step in 0..vademecum.steps.len() {
            for mode in 0..vademecum.modes(step) {
                let moved: f64 = load
                    .shares
                    .iter()
                    .map(|&(position, share)| {
                        let node = vademecum.positions[position] as usize;
                        vademecum.mode_at_node(step, mode, node)[a] * share
                    })
                    .sum();
                self.moved_per_coefficient_m[a].push(moved as f32);
            }
        }
    }

    /// The tool does not press the organ.
    pub fn release(&mut self) {
        self.held = false;
    }
}
