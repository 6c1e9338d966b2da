//! The deformation state of one organ online: the loads on it and the modal coefficients they
//! sum to. Several loads superpose through the vademecum; the whole field is only formed
//! where someone needs it (the renderer), the coefficients every haptic tick.

use nalgebra::Vector3;

use super::{Patch, SurfaceModes, SurfacePoint, Vademecum};

/// A force on a tool-sized patch of the accessible surface.
#[derive(Debug, Default, PartialEq)]
pub struct PatchLoad {
    /// Load positions and their shares of the force (summing to one).
    pub shares: Vec<(usize, f64)>,
    pub force_n: Vector3<f64>,
}

/// `clone_from` reuses the buffers: the haptic tick copies loads into its snapshot every
/// millisecond, and a derived `Clone` would allocate each time. A clone keeps the room as well
/// as the contents, so that a copy made once (a snapshot) never grows either.
impl Clone for PatchLoad {
    fn clone(&self) -> Self {
        Self {
            shares: with_room_of(&self.shares),
            force_n: self.force_n,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.shares.clone_from(&source.shares);
        self.force_n = source.force_n;
    }
}

impl PatchLoad {
    /// No load, its buffer room for `positions` shares: a patch can hold no more, so the
    /// haptic tick never grows it.
    pub fn reserved(positions: usize) -> Self {
        Self {
            shares: Vec::with_capacity(positions),
            force_n: Vector3::zeros(),
        }
    }

    pub fn is_active(&self) -> bool {
        self.force_n != Vector3::zeros() && !self.shares.is_empty()
    }

    /// Removes the load, keeping its buffer.
    pub fn release(&mut self) {
        self.shares.clear();
        self.force_n = Vector3::zeros();
    }
}

/// A force on one load position: organ contact's loads, whose modes are in the coupling's
/// coefficients and whose near-field correction is added where the field is formed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLoad {
    pub position: usize,
    pub force_n: Vector3<f64>,
}

impl PointLoad {
    fn shares(&self) -> [(usize, f64); 1] {
        [(self.position, 1.0)]
    }
}

/// A small rigid motion: `u(p) = t + ω × (p − c)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RigidCarry {
    pub translation_m: Vector3<f64>,
    /// Small-angle rotation vector (rad).
    pub rotation_rad: Vector3<f64>,
    pub centre_m: Vector3<f64>,
}

impl RigidCarry {
    /// The displacement (m) it gives the point `p`.
    pub fn at(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.translation_m + self.rotation_rad.cross(&(p - self.centre_m))
    }

    /// The point that the carry moves to `x`: `p` with `p + at(p) = x`. With `W = [ω]×`,
    /// `p − c = (I + W)⁻¹ (x − c − t)`, and `(I + W)⁻¹ = I − (W − W²) / (1 + |ω|²)`. Taken as
    /// `x − at(x)` instead, a carry turned by 0.09 rad left errors of a millimetre 5 cm away.
    pub fn pull_back(&self, x: &Vector3<f64>) -> Vector3<f64> {
        let w = &self.rotation_rad;
        let v = x - self.centre_m - self.translation_m;
        let wv = w.cross(&v);
        self.centre_m + v - (wv - w.cross(&wv)) / (1.0 + w.norm_squared())
    }
}

/// The loads on an organ and, per load step, the modal coefficients of their sum.
#[derive(Debug, Default, PartialEq)]
pub struct Deformation {
    pub loads: Vec<PatchLoad>,
    /// `coefficients[step][mode]`: the loads' and the coupling's together.
    pub coefficients: Vec<Vec<f64>>,
    /// The coefficients of the loads other organs put on this one (organ contact, an
    /// attached organ's pull), set by the contact stage each tick.
    pub coupling: Vec<Vec<f64>>,
    /// The contact loads among them, for their near-field corrections: the dimple each
    /// contact force makes, which its modes are too smooth to show.
    pub coupling_points: Vec<PointLoad>,
    /// The total force (N) of those loads.
    pub coupling_force_n: Vector3<f64>,
    /// How the organ it is attached to carries it along.
    pub carry: RigidCarry,
}

/// `clone_from` reuses the buffers, as for [`PatchLoad`].
impl Clone for Deformation {
    fn clone(&self) -> Self {
        Self {
            loads: self.loads.clone(),
            coefficients: self.coefficients.clone(),
            coupling: self.coupling.clone(),
            coupling_points: with_room_of(&self.coupling_points),
            coupling_force_n: self.coupling_force_n,
            carry: self.carry,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.loads.clone_from(&source.loads);
        self.coefficients.clone_from(&source.coefficients);
        self.coupling.clone_from(&source.coupling);
        self.coupling_points.clone_from(&source.coupling_points);
        self.coupling_force_n = source.coupling_force_n;
        self.carry = source.carry;
    }
}

/// A copy of `items` with the same room.
fn with_room_of<T: Clone>(items: &Vec<T>) -> Vec<T> {
    let mut copy = Vec::with_capacity(items.capacity());
    copy.extend_from_slice(items);
    copy
}

impl Deformation {
    /// An unloaded organ with `load_slots` loads (released) ready to be set.
    pub fn new(vademecum: &Vademecum, load_slots: usize) -> Self {
        let zeros: Vec<Vec<f64>> = (0..vademecum.steps.len())
            .map(|k| vec![0.0; vademecum.modes(k)])
            .collect();
        Self {
            loads: (0..load_slots)
                .map(|_| PatchLoad::reserved(vademecum.positions.len()))
                .collect(),
            coefficients: zeros.clone(),
            coupling: zeros,
            coupling_points: Vec::new(),
            coupling_force_n: Vector3::zeros(),
            carry: RigidCarry::default(),
        }
    }

    /// Recomputes the modal coefficients from the loads and the coupling: O(modes × patch)
    /// per load.
    pub fn evaluate(&mut self, vademecum: &Vademecum) {
        for (step, coefficients) in self.coefficients.iter_mut().enumerate() {
            coefficients.copy_from_slice(&self.coupling[step]);
            for load in self.loads.iter().filter(|l| l.is_active()) {
                vademecum.add_coefficients(step, &load.shares, &load.force_n, coefficients);
            }
        }
    }

    /// The whole displacement field (m, `3 × nodes`) into `u`: the modes with the current
    /// coefficients plus each load's near-field correction, the contact loads' included.
    pub fn field_into(&self, vademecum: &Vademecum, u: &mut [f64]) {
        self.sum_into(
            u,
            |step, c, u| vademecum.add_modes(step, c, u),
            |step, (shares, force_n), u| vademecum.add_corrections(step, shares, force_n, u),
        );
    }

    /// The displacement (m) at the load positions (`3 × positions`) into `u`: what
    /// [`Self::field_into`] gives at their nodes, from the modes and corrections there only.
    pub fn surface_into(&self, vademecum: &Vademecum, surface: &SurfaceModes, u: &mut [f64]) {
        self.sum_into(
            u,
            |step, c, u| surface.add_modes(step, c, u),
            |step, load, u| surface.add_corrections(vademecum, step, load, u),
        );
    }

    /// `u` anew: per load step, the modes with the current coefficients, then the near-field
    /// correction of each active load and contact point, each added by the given function.
    fn sum_into(
        &self,
        u: &mut [f64],
        add_modes: impl Fn(usize, &[f64], &mut [f64]),
        add_corrections: impl Fn(usize, (&[(usize, f64)], &Vector3<f64>), &mut [f64]),
    ) {
        u.fill(0.0);
        for (step, coefficients) in self.coefficients.iter().enumerate() {
            add_modes(step, coefficients, u);
            for load in self.loads.iter().filter(|l| l.is_active()) {
                add_corrections(step, (&load.shares, &load.force_n), u);
            }
            for point in &self.coupling_points {
                add_corrections(step, (&point.shares(), &point.force_n), u);
            }
        }
    }

    /// Surface vertex at rest `rest` moved by `u` (m) and by the carry, ready to draw.
    pub fn drawn_vertex(&self, rest: &[f32; 3], u: &[f64]) -> [f32; 3] {
        let carried = self.carry.at(&Vector3::from(rest.map(f64::from)));
        [0, 1, 2].map(|c| rest[c] + (u[c] + carried[c]) as f32)
    }

    /// The accessible surface's vertices, deformed, into `positions` (f32, ready to draw):
    /// the visual model mapped from the mechanical one through the load positions' nodes.
    /// `u` is scratch space for the displacement there (`3 × positions`).
    pub fn deformed_surface(
        &self,
        vademecum: &Vademecum,
        surface: &SurfaceModes,
        u: &mut [f64],
        positions: &mut Vec<[f32; 3]>,
    ) {
        self.surface_into(vademecum, surface, u);
        positions.clear();
        positions.extend(
            vademecum
                .position_coords_m
                .iter()
                .zip(u.chunks_exact(3))
                .map(|(rest, u)| self.drawn_vertex(rest, u)),
        );
    }

    /// Displacement (m) of the surface point `at` under every load but the one in slot `skip`,
    /// the coupling's and the carry included: how far other loads have already moved the
    /// surface a tool is about to touch.
    pub fn displacement_without(
        &self,
        vademecum: &Vademecum,
        at: &SurfacePoint,
        skip: usize,
    ) -> Vector3<f64> {
        let corners = vademecum.triangles[at.triangle];
        let nodes: [(usize, f64); 3] = std::array::from_fn(|k| {
            let node = vademecum.positions[corners[k] as usize] as usize;
            (node, at.barycentric[k])
        });
        self.nodes_displacement_without(vademecum, &vademecum.point(at), &nodes, skip)
    }

    /// [`Self::displacement_without`] averaged over `patch` by its shares, read at its blend
    /// of nodes at once: each other load's modal coefficients are computed once for the
    /// patch, not once for each of its positions.
    pub fn patch_displacement_without(
        &self,
        vademecum: &Vademecum,
        patch: &Patch,
        skip: usize,
    ) -> Vector3<f64> {
        let rest = (patch.shares.iter())
            .map(|&(m, share)| Vector3::from(vademecum.position_coords_m[m].map(f64::from)) * share)
            .sum();
        self.nodes_displacement_without(vademecum, &rest, &patch.blend, skip)
    }

    /// [`Self::displacement_without`] at the point at rest `rest` that blends volume nodes
    /// (`(node, weight)`): each load's modal coefficients are computed once for the blend.
    fn nodes_displacement_without(
        &self,
        vademecum: &Vademecum,
        rest: &Vector3<f64>,
        nodes: &[(usize, f64)],
        skip: usize,
    ) -> Vector3<f64> {
        let mut u = self.carry.at(rest);
        for (step, coupling) in self.coupling.iter().enumerate() {
            for (mode, &c) in coupling.iter().enumerate() {
                if c != 0.0 {
                    for &(node, w) in nodes {
                        u += vademecum.mode_at_node(step, mode, node) * (c * w);
                    }
                }
            }
        }
        for point in &self.coupling_points {
            for step in 0..vademecum.steps.len() {
                vademecum.add_blend_corrections(
                    step,
                    &point.shares(),
                    &point.force_n,
                    nodes,
                    &mut u,
                );
            }
        }
        let others = self
            .loads
            .iter()
            .enumerate()
            .filter(|&(slot, load)| slot != skip && load.is_active());
        for (_, load) in others {
            for step in 0..vademecum.steps.len() {
                vademecum.add_blend_displacement(step, &load.shares, &load.force_n, nodes, &mut u);
            }
        }
        u
    }

    /// Displacement (m) of the surface point `at` under every load, the coupling's and the
    /// carry included.
    pub fn displacement(&self, vademecum: &Vademecum, at: &SurfacePoint) -> Vector3<f64> {
        self.displacement_without(vademecum, at, usize::MAX)
    }

    /// The sum of the forces (N) applied to the organ, the coupling's included.
    pub fn total_force_n(&self) -> Vector3<f64> {
        self.loads.iter().map(|l| l.force_n).sum::<Vector3<f64>>() + self.coupling_force_n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pull-back inverts the carry exactly, however far it turns, where `x − at(x)` is
    /// off by the square of the turn.
    #[test]
    fn a_carry_pulled_back_returns_every_point() {
        let carry = RigidCarry {
            translation_m: Vector3::new(0.003, -0.002, 0.001),
            rotation_rad: Vector3::new(0.05, 0.3, -0.2),
            centre_m: Vector3::new(0.1, 0.0, -0.05),
        };
        for p in [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.15, -0.04, 0.02),
            Vector3::new(-0.05, 0.08, -0.1),
        ] {
            let x = p + carry.at(&p);
            assert!((carry.pull_back(&x) - p).norm() < 1e-15, "{p}");
            assert!((x - carry.at(&x) - p).norm() > 1e-4, "{p}");
        }
    }
}
