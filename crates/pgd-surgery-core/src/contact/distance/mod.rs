//! The master organ's signed distance field for every deformation its vademecum can take, in
//! separated form, sampled on a lattice around it: the rest distance `d₀(x)` and, per mode,
//! the displacement `U^k(x) = X^k(π(x))` of the rest surface's closest point `π(x)`. The
//! deformed distance is the rest distance where the point came from:
//! `d(x, α) = d₀(y) / s(y)` with `y = x − Σ_k α_k U^k(y)`, where `s` is how much the
//! deformation stretches distances along the rest normal ([`Corners::normal_stretch`]).
//!
//! `α` are the master's modal coefficients (all load steps, one after another), the same the
//! haptic tick already sums for the organ. A lattice node's displacement is three dot products
//! over the modes, evaluated at most once per tick ([`LatticeCache`]); the rest distance then
//! needs no modes at all.
//!
//! Why pulled back rather than linearized: a first-order change `D^k = −∇d₀ · U^k` is exact
//! only for a surface moving along its normal. The floppy gallbladder also moves sideways by
//! millimetres, and its curvature turns that motion into errors of 1.1–1.8 mm (p95,
//! `tests/contact`) for the linearized field. Pulled back ([`PULLBACK_STEPS`]), a surface
//! that moves rigidly near a point keeps its distance exactly, and the error falls to 0.4 mm.
//! Where the surface turns (under the tool), the rest normal through `y` is tilted once
//! deformed, and dividing by the stretch takes that in to first order: 0.70 → 0.46 mm p95
//! within 25 mm of the tool.
//!
//! The vademecum's near-field corrections (the dimple under a tool, and on a thin floppy
//! organ most of its response within `local_radius_m` of it) follow the tool's patch, which
//! no lattice can hold beforehand. Each lattice node also keeps its closest rest point's
//! triangle corners, and adds their near-field displacement of this tick ([`NearField`]) to
//! its modes'. `tests/contact` measures the result against the exact distance to the deformed
//! surface: p95 0.23 mm beyond 25 mm of the tool and 0.46 mm within, against 1.5 mm and
//! 9.2 mm without the corrections.

mod cell;
mod field_file;
mod near;

use nalgebra::Vector3;
use rayon::prelude::*;

use super::ContactSurface;
use crate::pgd::Vademecum;
use cell::{Cell, normal_stretch};

pub use field_file::FieldOrigin;
pub use near::NearField;

/// How the lattice is laid out.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DistanceSettings {
    /// Lattice spacing (m): one cell is the depth the contact test tolerates.
    pub spacing_m: f64,
    /// How far the lattice reaches beyond the master's bounding box (m): pointshell nodes
    /// farther than this at rest never meet the master.
    pub margin_m: f64,
}

impl Default for DistanceSettings {
    fn default() -> Self {
        Self {
            spacing_m: 2e-3,
            margin_m: 12e-3,
        }
    }
}

/// Per lattice node: the rest distance and its unit gradient, then three values per mode.
pub(super) const HEAD: usize = 4;

/// Fixed-point steps `y ← x − u(y)` towards the rest point `y` that the master's displacement
/// `u` brings to `x`. The first is exact where the surface near `x` moves rigidly; the next
/// take in how the displacement changes over that distance, which is steep around the tool.
/// On the coarse gallbladder pushed 12 mm (`tests/contact`, p95 within 25 mm of the tool),
/// two steps leave 1.9 mm, three 0.60 mm, four 0.46 mm, six 0.44 mm. (Newton steps with the
/// cell's own gradient did no better, and some left the lattice.)
const PULLBACK_STEPS: usize = 4;

#[derive(Clone, Debug, PartialEq)]
pub struct DistanceField {
    /// A hash of what the field is built from (`field_file::inputs_of`): tells a stored field
    /// built from another vademecum.
    inputs: String,
    settings: DistanceSettings,
    origin_m: Vector3<f64>,
    dims: [usize; 3],
    modes: usize,
    /// Per lattice node, x fastest: the rest distance and its unit gradient. Apart from the
    /// modes, so that a cell's corners share cache lines.
    rest: Vec<[f32; HEAD]>,
    /// Per lattice node, `3 × modes` values: each mode's displacement there.
    modal: Vec<f32>,
    /// Per mode, the largest `|U^k|` over the lattice: bounds how far the field can move.
    mode_bounds: Vec<f32>,
    /// Per lattice node, its closest rest point on the master's surface, where it reads the
    /// near-field displacement.
    closest: Vec<ClosestPoint>,
}

/// A point of the master's accessible surface as the lattice reads it: its triangle's corners
/// (surface positions) and their weights, all zero where the node has no closest point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ClosestPoint {
    corners: [u32; 3],
    weights: [f32; 3],
}

/// The lattice values of the current tick, each computed on first use.
#[derive(Clone, Debug, Default)]
pub struct LatticeCache {
    tick: u32,
    nodes: Vec<Stamped>,
    /// The master's coefficients the values are for, where `alpha_known`: not where a near
    /// field moved it too, nor before the first tick. Kept in place, so that a tick allocates
    /// nothing.
    alpha: Vec<f32>,
    alpha_known: bool,
}

/// A lattice node's displacement and the tick it was computed on, side by side: one cache
/// line for both.
#[derive(Clone, Copy, Debug, Default)]
struct Stamped {
    tick: u32,
    displacement: [f32; 3],
}

impl LatticeCache {
    /// Forgets the last tick's values (O(1): stamps, not clearing), unless the master's
    /// `shape` is the last tick's: the same coefficients, bit for bit, and no near field. A
    /// master held still keeps its lattice's displacements, which otherwise cost a third of
    /// the reads of a press at rest (three dot products over the modes per lattice node).
    pub fn next_tick(&mut self, field: &DistanceField, shape: &MasterShape) {
        if self.nodes.len() != field.node_count() {
            self.nodes = vec![Stamped::default(); field.node_count()];
            self.alpha_known = false;
        }
        let held = shape.near.is_none();
        if held && self.alpha_known && self.alpha == shape.alpha {
            return;
        }
        self.alpha_known = held;
        if held {
            shape.alpha.clone_into(&mut self.alpha);
        }
        self.tick = self.tick.wrapping_add(1);
        if self.tick == 0 {
            self.nodes.fill(Stamped::default());
            self.tick = 1;
        }
    }
}

/// The master's deformation as the field reads it: its modal coefficients (all load steps
/// concatenated, the coefficients the haptic tick already sums for the organ) and, where its
/// loads have near-field corrections, their displacement of its surface this tick.
#[derive(Clone, Copy, Debug)]
pub struct MasterShape<'a> {
    pub alpha: &'a [f32],
    pub near: Option<&'a NearField>,
}

/// The rest distance and outward direction at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistanceSample {
    /// Signed distance to the master at rest (m), negative inside.
    pub distance_m: f64,
    /// Unit direction out of the master (the rest field's gradient, interpolated).
    pub normal: Vector3<f64>,
}

impl DistanceField {
    /// Samples the master at rest (`surface`, the accessible surface of `vademecum`) and its
    /// modes on a lattice. Work: one closest-point query per node, in parallel.
    pub fn build(
        vademecum: &Vademecum,
        surface: &ContactSurface,
        settings: &DistanceSettings,
    ) -> Self {
        let (min, max) = bounds(vademecum);
        let margin = Vector3::repeat(settings.margin_m);
        let origin_m = min - margin;
        let extent = max - min + 2.0 * margin;
        let dims = [0, 1, 2].map(|c| (extent[c] / settings.spacing_m).ceil() as usize + 1);
        let modes = vademecum.total_modes();
        let mut field = Self {
            inputs: field_file::inputs_of(vademecum),
            settings: *settings,
            origin_m,
            dims,
            modes,
            rest: Vec::new(),
            modal: Vec::new(),
            mode_bounds: vec![0.0; modes],
            closest: Vec::new(),
        };
        let stride = HEAD + 3 * modes;
        let mut values = vec![0.0f32; field.node_count() * stride];
        let closest = values
            .par_chunks_mut(stride)
            .enumerate()
            .map(|(node, out)| field.fill_node(vademecum, surface, node, out))
            .collect();
        field.rest = values
            .chunks_exact(stride)
            .map(|node| [node[0], node[1], node[2], node[3]])
            .collect();
        field.modal = values
            .chunks_exact(stride)
            .flat_map(|node| &node[HEAD..])
            .copied()
            .collect();
        for node in field.modal.chunks_exact(3 * modes.max(1)) {
            for (bound, u) in field.mode_bounds.iter_mut().zip(node.chunks_exact(3)) {
                *bound = bound.max(Vector3::from_column_slice(u).norm());
            }
        }
        field.closest = closest;
        field
    }

    /// Fills one lattice node: the rest distance and gradient from the closest surface point,
    /// and each mode's displacement there. Returns the closest point.
    fn fill_node(
        &self,
        vademecum: &Vademecum,
        surface: &ContactSurface,
        node: usize,
        out: &mut [f32],
    ) -> ClosestPoint {
        let x = self.node_point(node);
        let Some(hit) = surface.closest(&x) else {
            out[0] = f32::MAX;
            return ClosestPoint::default();
        };
        let offset = x - hit.point_m;
        let outside = offset.dot(&hit.normal) >= 0.0;
        let sign = if outside { 1.0 } else { -1.0 };
        let gradient = offset
            .try_normalize(1e-9)
            .map_or(hit.normal, |direction| direction * sign);
        out[0] = (sign * offset.norm()) as f32;
        out[1..HEAD].copy_from_slice(&gradient.map(|c| c as f32).as_slice()[..3]);
        let corners = vademecum.triangles[hit.at.triangle];
        let mut k = HEAD;
        for step in 0..vademecum.steps.len() {
            for mode in 0..vademecum.modes(step) {
                let moved: Vector3<f64> = corners
                    .iter()
                    .zip(hit.at.barycentric)
                    .map(|(&m, l)| {
                        let node = vademecum.positions[m as usize] as usize;
                        vademecum.mode_at_node(step, mode, node) * l
                    })
                    .sum();
                out[k..k + 3].copy_from_slice(&[0, 1, 2].map(|c| moved[c] as f32));
                k += 3;
            }
        }
        ClosestPoint {
            corners,
            weights: hit.at.barycentric.map(|l| l as f32),
        }
    }

    pub fn node_count(&self) -> usize {
        self.dims.iter().product()
    }

    pub fn spacing_m(&self) -> f64 {
        self.settings.spacing_m
    }

    /// How far the lattice's farthest point lies from `centre_m` (m).
    pub fn farthest_from_m(&self, centre_m: &Vector3<f64>) -> f64 {
        let extent = Vector3::from(self.dims.map(|n| (n - 1) as f64)) * self.settings.spacing_m;
        let far = (self.origin_m - centre_m)
            .abs()
            .sup(&(self.origin_m + extent - centre_m).abs());
        far.norm()
    }

    /// How far `x` lies outside the lattice (m), 0 inside it: it must move that far before a
    /// distance can be read there.
    pub fn outside_by_m(&self, x: &Vector3<f64>) -> f64 {
        let extent = Vector3::from(self.dims.map(|n| (n - 1) as f64)) * self.settings.spacing_m;
        let below = (self.origin_m - x).sup(&Vector3::zeros());
        let above = (x - self.origin_m - extent).sup(&Vector3::zeros());
        (below + above).norm()
    }

    fn node_point(&self, node: usize) -> Vector3<f64> {
        let [nx, ny, _] = self.dims;
        let ijk = [node % nx, (node / nx) % ny, node / (nx * ny)];
        self.origin_m + Vector3::from(ijk.map(|i| i as f64)) * self.settings.spacing_m
    }

    /// Per mode, the largest `|U^k|` over the lattice.
    pub fn mode_bounds(&self) -> &[f32] {
        &self.mode_bounds
    }

    /// `Σ_k |α_k| max|U^k|`: no point of the master moves farther than this (m), so no
    /// interpolated distance changes by more than `√3` times it (trilinear interpolation of a
    /// 1-Lipschitz field).
    pub fn movement_bound_m(&self, alpha: &[f32]) -> f32 {
        super::modal_rows::movement_bound(alpha, &self.mode_bounds)
    }

    /// The deformed distance (m) at `x` for the master's `shape`: the rest distance where the
    /// master's displacement brought `x` from. `None` outside the lattice, where no contact is
    /// possible.
    pub fn distance_m(
        &self,
        x: &Vector3<f64>,
        shape: &MasterShape,
        cache: &mut LatticeCache,
    ) -> Option<f64> {
        let mut cell = self.cell(x)?;
        let mut corners = self.corner_values(cell.base, shape, cache);
        for _ in 0..PULLBACK_STEPS {
            let u = cell.interpolate(&corners.displacement_m);
            let y = x - Vector3::from(u.map(f64::from));
            let next = self.cell(&y)?;
            if next == cell {
                // Where the point stays put, the fixed point is reached: the steps after
                // would repeat this one (a master held still, or not moving there).
                break;
            }
            if next.base != cell.base {
                corners = self.corner_values(next.base, shape, cache);
            }
            cell = next;
        }
        let [rest_m, gradient @ ..] = cell.interpolate(&corners.rest);
        let per_m = (1.0 / self.settings.spacing_m) as f32;
        let slopes = cell
            .slopes(&corners.displacement_m)
            .map(|s| s.map(|s| s * per_m));
        Some(f64::from(rest_m / normal_stretch(&slopes, gradient)))
    }

    /// The rest distance and this tick's displacement at the corners of the cell at `base`.
    fn corner_values(&self, base: usize, shape: &MasterShape, cache: &mut LatticeCache) -> Corners {
        let mut corners = Corners::default();
        for (k, node) in self.corners(base).enumerate() {
            corners.rest[k] = self.rest[node];
            corners.displacement_m[k] = self.node_displacement(node, shape, cache);
        }
        corners
    }

    /// The rest distance and direction at a point, or `None` outside the lattice: trilinear
    /// interpolation of the lattice's values. The direction is the rest gradient, so that of
    /// a penalty varies smoothly from cell to cell.
    pub fn at_rest(&self, x: &Vector3<f64>) -> Option<DistanceSample> {
        let cell = self.cell(x)?;
        let corners = std::array::from_fn(|k| self.rest[self.corner(cell.base, k)]);
        let [distance_m, gradient @ ..] = cell.interpolate(&corners).map(f64::from);
        Some(DistanceSample {
            distance_m,
            normal: Vector3::from(gradient).try_normalize(1e-9)?,
        })
    }

    /// One lattice node's displacement, once per tick: `Σ_k α_k U^k` and the near-field
    /// displacement at its closest rest point.
    fn node_displacement(
        &self,
        node: usize,
        shape: &MasterShape,
        cache: &mut LatticeCache,
    ) -> [f32; 3] {
        let stamped = &mut cache.nodes[node];
        if stamped.tick == cache.tick {
            return stamped.displacement;
        }
        let stride = 3 * self.modes;
        let modes = &self.modal[node * stride..(node + 1) * stride];
        let mut u = [0.0f32; 3];
        for (m, &a) in modes.chunks_exact(3).zip(shape.alpha) {
            for c in 0..3 {
                u[c] += a * m[c];
            }
        }
        if let Some(near) = shape.near {
            let closest = &self.closest[node];
            for (&position, &w) in closest.corners.iter().zip(&closest.weights) {
                let v = near.at(position as usize);
                for c in 0..3 {
                    u[c] += w * v[c];
                }
            }
        }
        *stamped = Stamped {
            tick: cache.tick,
            displacement: u,
        };
        u
    }

    /// The lattice cell holding `x` (its lowest node) and where `x` lies in it.
    fn cell(&self, x: &Vector3<f64>) -> Option<Cell> {
        let local = (x - self.origin_m) / self.settings.spacing_m;
        let mut base = [0usize; 3];
        let mut t = [0.0; 3];
        for c in 0..3 {
            let cells = (self.dims[c] - 1) as f64;
            if !(0.0..=cells).contains(&local[c]) {
                return None;
            }
            // Non-negative here, so truncation is the floor (no call into libm).
            let i = (local[c] as usize).min(self.dims[c] - 2);
            base[c] = i;
            t[c] = (local[c] - i as f64) as f32;
        }
        let [nx, ny, _] = self.dims;
        Some(Cell {
            base: base[0] + nx * (base[1] + ny * base[2]),
            t,
        })
    }

    /// Corner `k` of the cell at `base` (in [`Cell`]'s order).
    fn corner(&self, base: usize, k: usize) -> usize {
        let [nx, ny, _] = self.dims;
        base + (k & 1) + nx * ((k >> 1) & 1) + nx * ny * ((k >> 2) & 1)
    }

    fn corners(&self, base: usize) -> impl Iterator<Item = usize> {
        (0..8).map(move |k| self.corner(base, k))
    }
}

/// The bounding box of the master's accessible surface at rest.
fn bounds(vademecum: &Vademecum) -> (Vector3<f64>, Vector3<f64>) {
    let mut min = Vector3::repeat(f64::INFINITY);
    let mut max = Vector3::repeat(f64::NEG_INFINITY);
    for p in &vademecum.position_coords_m {
        let p = Vector3::from(p.map(f64::from));
        min = min.inf(&p);
        max = max.sup(&p);
    }
    (min, max)
}

/// A cell's eight corners, as [`DistanceField::distance_m`] reads them: the rest distance and
/// its direction, and this tick's displacement, so that pull-back steps landing in the same
/// cell read the lattice once.
#[derive(Default)]
struct Corners {
    rest: [[f32; HEAD]; 8],
    displacement_m: [[f32; 3]; 8],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lattice of 3 × 4 × 5 nodes 2 mm apart from the origin, with no values: its box is
    /// 4 × 6 × 8 mm.
    fn lattice() -> DistanceField {
        DistanceField {
            inputs: String::new(),
            settings: DistanceSettings::default(),
            origin_m: Vector3::new(1e-3, -2e-3, 0.0),
            dims: [3, 4, 5],
            modes: 0,
            rest: Vec::new(),
            modal: Vec::new(),
            mode_bounds: Vec::new(),
            closest: Vec::new(),
        }
    }

    /// Inside or on the box, zero; beside a face, the distance to it; beyond an edge or a
    /// corner, the distance to that edge or corner.
    #[test]
    fn a_point_outside_the_lattice_is_as_far_out_as_its_box_is() {
        let field = lattice();
        let at = |x: f64, y: f64, z: f64| field.outside_by_m(&(Vector3::new(x, y, z) * 1e-3));
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert_eq!(at(3.0, 1.0, 4.0), 0.0);
        assert_eq!(at(5.0, 4.0, 8.0), 0.0, "the far corner is on the box");
        assert!(close(at(3.0, 1.0, 10.5), 2.5e-3), "{}", at(3.0, 1.0, 10.5));
        assert!(close(at(-2.0, 1.0, 4.0), 3e-3), "{}", at(-2.0, 1.0, 4.0));
        assert!(close(at(8.0, -6.0, 4.0), 5e-3), "{}", at(8.0, -6.0, 4.0));
    }
}
