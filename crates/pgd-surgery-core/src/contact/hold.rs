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

/// One organ's hold by the tool this tick, linearized (see the module's documentation): the
/// press it answers, its rows (computed only when a contact pair pushes, as most ticks that
/// press an organ have no contact to answer), and how far the contact forces moved the patch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolHold {
    held: bool,
    /// Whether the rows are those of this tick's press.
    ready: bool,
    /// `K`: the tool's load per metre the patch is moved (N/m).
    stiffness_n_per_m: Matrix3<f64>,
    /// The tool's load (a copy, its buffer kept from tick to tick).
    load: PatchLoad,
    /// `Y`, direction after direction: the modal coefficients of `K e_a`, all load steps
    /// concatenated (per metre).
    pub(super) coefficients_per_m: [Vec<f32>; 3],
    /// `B`, direction after direction: per unit coefficient of each mode, how far the surface
    /// under the tool moves along `e_a`, averaged over the patch (m).
    pub(super) moved_per_coefficient_m: [Vec<f32>; 3],
    /// One load step's coefficients, before they are scaled.
    scratch: Vec<f64>,
    /// How far this tick's contact forces moved the patch (m).
    pub(super) moved_m: Vector3<f64>,
}

impl ToolHold {
    /// Room for a load on every position of `vademecum` and for its rows, so that holding
    /// it allocates nothing.
    pub(super) fn reserve(&mut self, vademecum: &Vademecum) {
        self.load.shares.reserve(vademecum.positions.len());
        let modes = vademecum.total_modes();
        for a in 0..3 {
            self.coefficients_per_m[a].reserve(modes);
            self.moved_per_coefficient_m[a].reserve(modes);
        }
        let most = (0..vademecum.steps.len()).map(|k| vademecum.modes(k));
        self.scratch.reserve(most.max().unwrap_or(0));
    }

    /// Whether the tool holds the organ and the rows are ready.
    pub fn is_ready(&self) -> bool {
        self.held && self.ready
    }

    /// How far this tick's contact forces moved the surface under the tool (m).
    pub fn moved_m(&self) -> Vector3<f64> {
        self.moved_m
    }

    /// The tool presses the organ as `contact` with `load` this tick. Allocates nothing once
    /// grown.
    pub fn hold(&mut self, contact: &ToolContact, load: &PatchLoad) {
        self.stiffness_n_per_m = contact.stiffness_n_per_m;
        self.held = load.is_active() && self.stiffness_n_per_m != Matrix3::zeros();
        self.ready = false;
        self.load.clone_from(load);
    }

    /// The tool does not press the organ this tick.
    pub fn release(&mut self) {
        self.held = false;
        self.ready = false;
    }

    /// Computes the rows of this tick's press, once.
    pub(super) fn prepare(&mut self, vademecum: &Vademecum) {
        if !self.held || self.ready {
            return;
        }
        for a in 0..3 {
            self.coefficients_per_m[a].clear();
            self.moved_per_coefficient_m[a].clear();
            let direction = self.stiffness_n_per_m.column(a).into();
            self.gather_coefficients(vademecum, &direction, a);
            self.gather_moves(vademecum, a);
        }
        self.ready = true;
    }

    /// `Y e_a`. A KSV vademecum picks its load steps by the force's size, so the load `K e_a`
    /// is scaled to the tool's force and its coefficients back.
    fn gather_coefficients(&mut self, vademecum: &Vademecum, direction: &Vector3<f64>, a: usize) {
        let scale = match vademecum.steps.len() {
            1 => 1.0,
            _ => self.load.force_n.norm() / direction.norm(),
        };
        for step in 0..vademecum.steps.len() {
            self.scratch.clear();
            self.scratch.resize(vademecum.modes(step), 0.0);
            let force = direction * scale;
            vademecum.add_coefficients(step, &self.load.shares, &force, &mut self.scratch);
            let per_m = self.scratch.iter().map(|c| (c / scale) as f32);
            self.coefficients_per_m[a].extend(per_m);
        }
    }

    /// `B`'s row `a`: each mode's displacement along `e_a`, averaged over the patch.
    fn gather_moves(&mut self, vademecum: &Vademecum, a: usize) {
        for step in 0..vademecum.steps.len() {
            for mode in 0..vademecum.modes(step) {
                let moved: f64 = self
                    .load
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
}
