//! The computational vademecum of one organ, as the trainer evaluates it: for a force at any
//! point of the accessible surface, the displacement under the tool, the felt force for an
//! indentation, and the whole displacement field, each in O(modes + local entries).

use std::ops::RangeInclusive;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::error_curve::ErrorCurve;
use super::local::LocalPart;
use super::region::{CutHeader, RegionResponse};
use super::settings::BuildSettings;
use super::tool_patch::PatchGeometry;
use crate::fem::{Inclusion, Material};

/// What the vademecum was built from and how: enough to refuse a stale file and to say how it
/// was made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The organ name or mesh file it was built for.
    pub source: String,
    /// [`super::mesh_hash`] of the mesh and its regions.
    pub mesh_hash: String,
    pub node_count: usize,
    pub tet_count: usize,
    pub material: Material,
    /// Stiffer or softer regions of the tissue (none in files written before they existed).
    #[serde(default)]
    pub inclusions: Vec<Inclusion>,
    /// The node set held fixed.
    pub clamped_region: String,
    /// The face set the tool may load.
    pub accessible_region: String,
    /// Loads are unit forces along these axes at every position.
    pub load_directions: [[f64; 3]; 3],
    pub settings: BuildSettings,
    /// Per load step: the indentation (m) its loads make under the tool (0 for the linear step).
    pub indentation_levels_m: Vec<f64>,
    /// What a nonlinear step's loads are (files from before the field: nodal loads). A
    /// nonlinear file whose steps were built otherwise than this version builds them is
    /// refused and rebuilt.
    #[serde(default)]
    pub step_loads: StepLoads,
    pub modes_per_step: Vec<usize>,
    /// Per load step, the error against the number of modes (for the convergence plot).
    pub convergence: Vec<ErrorCurve>,
    pub build_seconds: f64,
    /// The cut section's region and build (none in a vademecum built without cuts).
    #[serde(default)]
    pub cuts: Option<CutHeader>,
}

/// The load a nonlinear step answers at each position.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum StepLoads {
    /// A force on the position's node alone, the whole secant response kept.
    #[default]
    Nodal,
    /// The tool's patch centred on the position, along each axis, at the tool's own depth;
    /// the step keeps the nonlinear correction to the linear response of that patch.
    ToolPatch,
    /// The tool's patch centred on the position, pushing along its inward normal, at the
    /// tool's own depth; the step keeps the nonlinear correction to the linear response of
    /// that patch, and a force's components answer to it by their share along the normal.
    InwardToolPatch,
}

/// One load step's response per unit force: a separated global part plus the local part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Step {
    /// Spatial modes, one after another, each over all `3 × node_count` dofs.
    pub spatial: Vec<f32>,
    /// Parametric modes, one after another, each over all `3 × positions` parameters.
    pub parametric: Vec<f32>,
    pub local: LocalPart,
}

/// A point of the accessible surface: a triangle and barycentric weights on its positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub triangle: usize,
    pub barycentric: [f64; 3],
}

/// The tool's contact patch on one vademecum's surface: positions with their shares of the
/// load (summing to one), and the patch slot of every position, so that the pairs of a patch
/// compliance are found by one lookup each. Reused from tick to tick, it allocates nothing
/// once grown.
#[derive(Clone, Debug, Default)]
pub struct Patch {
    pub shares: Vec<(usize, f64)>,
    /// The same shares by volume node: a blend, where a field is read over the whole patch
    /// at once ([`super::Deformation::patch_displacement_without`]).
    pub blend: Vec<(usize, f64)>,
    slot_of: Vec<u32>,
    columns: StepColumns,
}

impl Patch {
    /// An empty patch with room for every position of `vademecum` and its load steps'
    /// columns: the haptic tick then never grows it.
    pub fn reserved(vademecum: &Vademecum) -> Self {
        let positions = vademecum.positions.len();
        Self {
            shares: Vec::with_capacity(positions),
            blend: Vec::with_capacity(positions),
            slot_of: Vec::with_capacity(positions),
            columns: StepColumns {
                columns: Vec::with_capacity(positions * vademecum.steps.len()),
                ..StepColumns::default()
            },
        }
    }
}

/// The most load steps a vademecum holds, the linear one included: a press marks the steps
/// whose columns it filled in one word.
pub const MAX_STEPS: usize = 64;

/// Per load step, each patch member's column of the patch compliance, `Σ_i β_i C_ij` (3 × 3,
/// row-major): the patch-averaged displacement per unit load on member `j`. A nonlinear press
/// fills a step's columns the first time its secant iteration reaches that step, so every
/// iteration after costs one pass over the members rather than one over their rows of blocks.
#[derive(Clone, Debug, Default)]
struct StepColumns {
    /// Step-major: `columns[step * members + slot]`.
    columns: Vec<[f64; 9]>,
    members: usize,
    /// One bit per step whose columns are filled.
    filled: u64,
}

const NO_SLOT: u32 = u32::MAX;

impl Patch {
    fn slot(&self, position: usize) -> Option<usize> {
        match self.slot_of[position] {
            NO_SLOT => None,
            slot => Some(slot as usize),
        }
    }

    /// Sizes the step columns for `steps` load steps of the current shares, none filled.
    fn reset_columns(&mut self, steps: usize) {
        let members = self.shares.len();
        self.columns.columns.resize(steps * members, [0.0; 9]);
        self.columns.members = members;
        self.columns.filled = 0;
    }

    /// Fills load step `step`'s columns from its local part (one pass over the members' rows)
    /// unless they are filled already.
    fn fill_columns(&mut self, step: usize, local: &LocalPart) {
        if self.columns.filled & (1 << step) != 0 {
            return;
        }
        let members = self.columns.members;
        let columns = &mut self.columns.columns[step * members..(step + 1) * members];
        columns.fill([0.0; 9]);
        for &(i, li) in &self.shares {
            for e in local.neighbours_of(i) {
                let slot = self.slot_of[local.neighbours[e] as usize];
                if slot == NO_SLOT {
                    continue;
                }
                let block = &local.compliance[9 * e..9 * e + 9];
                for (ck, &bk) in columns[slot as usize].iter_mut().zip(block) {
                    *ck += li * bk as f64;
                }
            }
        }
        self.columns.filled |= 1 << step;
    }

    /// Member `slot`'s column in load step `step` (filled by [`Self::fill_columns`]).
    fn column(&self, step: usize, slot: usize) -> &[f64; 9] {
        &self.columns.columns[step * self.columns.members + slot]
    }

    /// Replaces the shares, keeping the slot table in step (sized for `positions`).
    fn set(&mut self, positions: usize, shares: impl Iterator<Item = (usize, f64)>) {
        if self.slot_of.len() != positions {
            self.slot_of = vec![NO_SLOT; positions];
        }
        for &(m, _) in &self.shares {
            self.slot_of[m] = NO_SLOT;
        }
        self.shares.clear();
        self.shares.extend(shares);
        for (slot, &(m, _)) in self.shares.iter().enumerate() {
            self.slot_of[m] = slot as u32;
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Vademecum {
    pub header: Header,
    /// Volume node of each load position.
    pub positions: Vec<u32>,
    /// Rest position (m) of each load position.
    pub position_coords_m: Vec<[f32; 3]>,
    /// Lumped surface area (m²) of each load position: its weight in a tool patch.
    pub position_areas_m2: Vec<f32>,
    /// Unit outward normal of each load position: a patch loads only the positions on its
    /// own side of a thin wall (`on_pressed_side`).
    pub position_normals: Vec<[f32; 3]>,
    /// The accessible triangles, as position indices.
    pub triangles: Vec<[u32; 3]>,
    /// Per position, how deep (m/N) a unit force along its outward normal presses the tool's
    /// patch centred on it, linearly (a linear vademecum: its largest nodal self-compliance):
    /// turns a force into the indentation level that selects load steps.
    pub reference_compliance_m_per_n: Vec<f32>,
    /// Per position, the level (m) of the deepest load step its load converged at (zero in a
    /// linear vademecum): a position whose load fails at a step is not loaded deeper, its
    /// columns there keeping the step before's correction. Beside a clamped attachment the
    /// range so ends sooner than elsewhere.
    pub range_level_m: Vec<f32>,
    /// Load steps in increasing indentation; one for a linear vademecum.
    pub steps: Vec<Step>,
    /// The uncut organ's compressed responses to loads anywhere cuts may go: what a cut state
    /// condenses incisions onto (`docs/cutting.md`).
    pub cuts: Option<RegionResponse>,
}

impl Vademecum {
    pub fn dof_count(&self) -> usize {
        3 * self.header.node_count
    }

    pub fn parameter_count(&self) -> usize {
        3 * self.positions.len()
    }

    pub fn modes(&self, step: usize) -> usize {
        self.steps[step].parametric.len() / self.parameter_count()
    }

    /// Spatial mode `mode` of load step `step` at volume node `node` (m/N).
    pub fn mode_at_node(&self, step: usize, mode: usize, node: usize) -> Vector3<f64> {
        let x = &self.steps[step].spatial[mode * self.dof_count() + 3 * node..];
        Vector3::new(x[0], x[1], x[2]).map(f64::from)
    }

    /// Parametric mode `mode` of load step `step` at load position `position`: the mode's
    /// coefficient per newton along each axis there.
    pub fn load_mode_at(&self, step: usize, mode: usize, position: usize) -> Vector3<f64> {
        let y = &self.steps[step].parametric[mode * self.parameter_count() + 3 * position..];
        Vector3::new(y[0], y[1], y[2]).map(f64::from)
    }

    /// The modes of every load step together: the length of a concatenated coefficient list.
    pub fn total_modes(&self) -> usize {
        (0..self.steps.len()).map(|s| self.modes(s)).sum()
    }

    /// The deepest load step's level (m): the linear depth of the tool's patch there. A press
    /// stays within the range while its patch's level does
    /// ([`Self::patch_press_in_range`]).
    pub fn valid_indentation_m(&self) -> f64 {
        self.header
            .indentation_levels_m
            .last()
            .copied()
            .unwrap_or(0.0)
    }

    /// Outward unit normals of the accessible surface at rest, per position (area-weighted).
    pub fn rest_normals(&self) -> Vec<Vector3<f64>> {
        let coords: Vec<[f64; 3]> = self
            .position_coords_m
            .iter()
            .map(|p| p.map(f64::from))
            .collect();
        let triangles: Vec<[usize; 3]> = self
            .triangles
            .iter()
            .map(|t| t.map(|m| m as usize))
            .collect();
        crate::mesh::vertex_normals(&triangles, &coords)
            .into_iter()
            .map(Vector3::from)
            .collect()
    }

    /// Rest coordinates (m) of a surface point.
    pub fn point(&self, at: &SurfacePoint) -> Vector3<f64> {
        self.triangles[at.triangle]
            .iter()
            .zip(at.barycentric)
            .map(|(&m, l)| Vector3::from(self.position_coords_m[m as usize].map(f64::from)) * l)
            .sum()
    }

    /// Which way accessible triangle `t` faces: the sum of its corners' outward normals (the
    /// surface's, whatever the order of the triangle's corners), as a tool patch on it sees it.
    pub fn triangle_facing(&self, t: usize) -> Vector3<f64> {
        self.triangles[t]
            .iter()
            .map(|&m| Vector3::from(self.position_normals[m as usize].map(f64::from)))
            .sum()
    }

    /// The tool's contact patch centred at `at`, the same kernel as the full FEM load. A patch
    /// narrower than the mesh (no node inside it) falls back to the triangle's corners.
    pub fn patch(&self, at: &SurfacePoint) -> Patch {
        let mut patch = Patch::default();
        self.patch_into(at, &mut patch);
        patch
    }

    /// [`Self::patch`] into a patch the caller keeps. The candidates are one corner's
    /// neighbours: they reach `2 r + longest edge` from it, and every position of the patch
    /// lies within `r + longest edge` of each corner.
    pub fn patch_into(&self, at: &SurfacePoint, patch: &mut Patch) {
        let local = &self.steps[0].local;
        let corners = self.triangles[at.triangle];
        let candidates = local
            .neighbours_of(corners[0] as usize)
            .map(|e| local.neighbours[e] as usize);
        let weights = self.geometry().weights(
            self.point(at),
            self.triangle_facing(at.triangle),
            candidates,
        );
        patch.set(self.positions.len(), weights);
        let total: f64 = patch.shares.iter().map(|s| s.1).sum();
        if total > 0.0 {
            patch.shares.iter_mut().for_each(|s| s.1 /= total);
        } else {
            let corners = (0..3).map(|k| (corners[k] as usize, at.barycentric[k]));
            patch.set(self.positions.len(), corners);
        }
        patch.blend.clear();
        let shares = patch.shares.iter();
        (patch.blend).extend(shares.map(|&(m, share)| (self.positions[m] as usize, share)));
    }

    /// The load positions as the tool's patch sees them.
    fn geometry(&self) -> PatchGeometry<'_> {
        PatchGeometry {
            coords_m: &self.position_coords_m,
            areas_m2: &self.position_areas_m2,
            normals: &self.position_normals,
            radius_m: self.header.settings.tool_tip_radius_m,
        }
    }

    /// The shares of the tool's patch centred on position `m`: what a nonlinear step loaded
    /// there.
    pub fn patch_centred_on(&self, m: usize) -> Vec<(usize, f64)> {
        let local = &self.steps[0].local;
        let neighbours = &local.neighbours[local.neighbours_of(m)];
        self.geometry().centred_on(m, neighbours)
    }

    /// Weight of load step `step` at a level `level_m` deep ([`Self::blend`]).
    fn step_weight(&self, step: usize, level_m: f64) -> f64 {
        let (first, last, t) = self.blend(level_m);
        if step == last {
            t
        } else if step == first {
            1.0 - t
        } else {
            0.0
        }
    }

    /// The two load steps a level `level_m` deep blends, and the second one's weight:
    /// piecewise linear between the steps' levels, held at the last step beyond it (both
    /// steps the same, weight one, outside the levels).
    fn blend(&self, level_m: f64) -> (usize, usize, f64) {
        let (first, last) = self.steps_at(level_m);
        if first == last {
            return (first, last, 1.0);
        }
        let levels = &self.header.indentation_levels_m;
        (
            first,
            last,
            (level_m - levels[first]) / (levels[last] - levels[first]),
        )
    }

    /// The first and last steps [`Self::step_weight`] blends at a level `level_m` deep (the
    /// last step beyond the deepest level, or for a level that is not a number).
    fn steps_at(&self, level_m: f64) -> (usize, usize) {
        let levels = &self.header.indentation_levels_m;
        match levels.iter().position(|&l| l >= level_m) {
            None => (levels.len() - 1, levels.len() - 1),
            Some(0) => (0, 0),
            Some(k) => (k - 1, k),
        }
    }

    /// The linear depth (m) of the tool's patch centred on position `j` under the whole force
    /// `force_norm_n`: what picks the load steps of position `j`'s correction.
    fn level_m(&self, j: usize, force_norm_n: f64) -> f64 {
        force_norm_n * self.reference_compliance_m_per_n[j] as f64
    }

    /// The share of a total force that position `j` (share `l` of the patch) carries in load
    /// step `step`, the force's magnitude as [`Self::level_force_n`] gives it. The linear step
    /// carries the whole share; a nonlinear step holds the correction of the patch centred on
    /// `j`, at the level the whole force presses it, and carries the share its blend gives it
    /// (the linear step's correction being none).
    pub(crate) fn step_share(&self, step: usize, j: usize, l: f64, level_force_n: f64) -> f64 {
        if step == 0 {
            return l;
        }
        l * self.step_weight(step, self.level_m(j, level_force_n))
    }

    /// The magnitude (N) of `force_n` on the patch `shares` that sets its positions' levels:
    /// the force's own up to the patch's range edge ([`Self::range_force_n`]), the edge's
    /// beyond it. So past the edge every position of the patch keeps the level it had there,
    /// and the patch answers at the edge's secant compliance, the same for any deeper press,
    /// whether or not the positions' own ranges reach further.
    pub(crate) fn level_force_n(&self, shares: &[(usize, f64)], force_n: &Vector3<f64>) -> f64 {
        force_n.norm().min(self.shares_range_force_n(shares))
    }

    /// The load steps the positions of `patch` use under a force whose magnitude, as
    /// [`Self::level_force_n`] gives it, is `level_force_n`: the linear one and the
    /// corrections up to the deepest position's (a step in between that no position uses adds
    /// nothing).
    fn loaded_steps(&self, patch: &Patch, level_force_n: f64) -> RangeInclusive<usize> {
        let deepest = patch
            .shares
            .iter()
            .map(|&(j, _)| self.level_m(j, level_force_n))
            .map(|level| if level.is_nan() { f64::INFINITY } else { level })
            .fold(0.0, f64::max);
        0..=self.steps_at(deepest).1
    }

    /// The 3 × 3 compliance (m/N) of load step `step` for `patch`: the patch-averaged
    /// displacement under the tool per unit force, `Σ_ij β_i β_j C_ij`.
    pub fn step_compliance(&self, step: usize, patch: &Patch) -> Matrix3<f64> {
        match step {
            0 => self.linear_compliance(patch),
            _ => self.weighted_compliance(step, patch, |_, l| l),
        }
    }

    /// The linear step's patch compliance by reciprocity (Maxwell–Betti, `C_ji = C_ijᵀ`): each
    /// pair once, from the row of its lower index, which halves the scan of the general sum.
    /// The haptic tick's hot spot on fine organs (65 positions under the gallbladder's tip).
    fn linear_compliance(&self, patch: &Patch) -> Matrix3<f64> {
        let local = &self.steps[0].local;
        let mut c = [0.0f64; 9];
        for &(i, li) in &patch.shares {
            let row = local.neighbours_of(i);
            let own = &local.compliance[9 * row.start..9 * row.start + 9];
            for (ck, &bk) in c.iter_mut().zip(own) {
                *ck += li * li * bk as f64;
            }
            let others = &local.neighbours[row.start + 1..row.end];
            let higher = row.start + 1 + others.partition_point(|&j| (j as usize) < i);
            for e in higher..row.end {
                let Some(slot) = patch.slot(local.neighbours[e] as usize) else {
                    continue;
                };
                let w = li * patch.shares[slot].1;
                let b = &local.compliance[9 * e..9 * e + 9];
                for r in 0..3 {
                    for k in 0..3 {
                        c[3 * r + k] += w * (b[3 * r + k] as f64 + b[3 * k + r] as f64);
                    }
                }
            }
        }
        Matrix3::from_row_slice(&c)
    }

    /// `Σ_ij β_i γ_j C_ij`: the displacement averaged with the patch's shares `β` under loads
    /// whose shares are `γ_j = loaded(j, β_j)`. Each position's row of blocks is scanned
    /// once and its patch members picked by the slot table.
    fn weighted_compliance(
        &self,
        step: usize,
        patch: &Patch,
        loaded: impl Fn(usize, f64) -> f64,
    ) -> Matrix3<f64> {
        let local = &self.steps[step].local;
        let mut c = [0.0f64; 9];
        for &(i, li) in &patch.shares {
            for e in local.neighbours_of(i) {
                let j = local.neighbours[e] as usize;
                if let Some(slot) = patch.slot(j) {
                    let w = li * loaded(j, patch.shares[slot].1);
                    let block = &local.compliance[9 * e..9 * e + 9];
                    for (ck, &bk) in c.iter_mut().zip(block) {
                        *ck += w * bk as f64;
                    }
                }
            }
        }
        Matrix3::from_row_slice(&c)
    }

    /// The compliance for a force `force_n` on `patch`: the linear step's plus the blended
    /// corrections of the steps the patch's positions reach, and (a law whose modulus grows
    /// with the strain) their share across the normal (`across_the_normal`), summed block
    /// by block: the reference the haptic tick's columns must agree with for the force on the
    /// organ ([`Self::patch_press_in_range`]).
    pub fn compliance(&self, patch: &Patch, force_n: &Vector3<f64>) -> Matrix3<f64> {
        if self.steps.len() == 1 {
            return self.step_compliance(0, patch);
        }
        let level_n = self.level_force_n(&patch.shares, force_n);
        let steps: Vec<usize> = self.loaded_steps(patch, level_n).collect();
        let along: Matrix3<f64> = steps
            .iter()
            .map(|&k| self.weighted_compliance(k, patch, |j, l| self.step_share(k, j, l, level_n)))
            .sum();
        if !self.header.material.law.modulus_grows_with_strain() {
            return along;
        }
        let across: Matrix3<f64> = patch
            .shares
            .iter()
            .map(|&(j, l)| {
                // Position j's own loads alone, at unit share.
                let own = |k: usize, weight: f64| {
                    self.weighted_compliance(k, patch, |i, _| if i == j { weight } else { 0.0 })
                };
                let correction: Matrix3<f64> = steps
                    .iter()
                    .filter(|&&k| k != 0)
                    .map(|&k| own(k, self.step_share(k, j, 1.0, level_n)))
                    .sum();
                let normal = Vector3::from(self.position_normals[j].map(f64::from));
                l * across_the_normal(&own(0, 1.0), &correction, &normal)
            })
            .sum();
        along + across
    }

    /// Displacement (m) of the surface under the tool for a force (N) at `at`.
    pub fn tool_displacement(&self, at: &SurfacePoint, force_n: &Vector3<f64>) -> Vector3<f64> {
        self.compliance(&self.patch(at), force_n) * force_n
    }

    /// The force (N) that pushes the surface at `at` by `indentation_m`: the force the trainee
    /// feels is its opposite (beyond the range, with the tissue's stiffening past its last
    /// load step, [`RangePress::felt_n`]).
    pub fn force_for_indentation(
        &self,
        at: &SurfacePoint,
        indentation_m: &Vector3<f64>,
    ) -> Vector3<f64> {
        self.patch_press_in_range(&mut self.patch(at), indentation_m)
            .felt_n
    }

    /// The press of `patch` by `indentation_m`: one 3 × 3 solve when linear; a secant
    /// iteration over the load steps otherwise, on the patch's step columns, each step's
    /// filled once. The patch's level is the share-weighted level of the patches centred on
    /// its positions (close to the linear depth of the tool's own patch); past the range's
    /// edge ([`Self::range_force_n`]) every position keeps the level it had there
    /// (`Self::level_force_n`), so the organ answers at the edge's secant compliance: its
    /// load and the field drawn follow the tool. What the trainee feels goes on stiffening
    /// there: a second iteration from the organ's force, blended from the edge's secant
    /// compliance to the last load-step interval's chord (`Self::chord_compliance`) as the
    /// force grows past the edge, `δ = C_e F_e + C_chord (F − F_e)` along the force: closer
    /// to full FEM than the edge's secant alone (docs/pgd.md, "Beyond the range").
    pub fn patch_press_in_range(
        &self,
        patch: &mut Patch,
        indentation_m: &Vector3<f64>,
    ) -> RangePress {
        if self.steps.len() == 1 {
            let (force_n, stiffness_n_per_m) =
                solve_press(self.linear_compliance(patch), indentation_m);
            return RangePress::within(force_n, stiffness_n_per_m);
        }
        let edge_n = self.range_force_n(patch);
        patch.reset_columns(self.steps.len());
        let linear = solve_press(self.column_compliance(patch, 0.0), indentation_m);
        let (force_n, stiffness_n_per_m) = secant_iteration(linear, indentation_m, |force| {
            self.column_compliance(patch, force.norm().min(edge_n))
        });
        let f = force_n.norm();
        if f <= edge_n {
            return RangePress::within(force_n, stiffness_n_per_m);
        }
        let at_edge = self.column_compliance(patch, edge_n);
        let (felt_n, felt_stiffness_n_per_m) = match self.chord_compliance(patch, edge_n, &at_edge)
        {
            Some(chord) => {
                let from = (force_n, stiffness_n_per_m);
                let blend = |force: &Vector3<f64>| {
                    let w = (edge_n / force.norm()).min(1.0);
                    at_edge * w + chord * (1.0 - w)
                };
                let felt_n = secant_iteration(from, indentation_m, blend).0;
                (felt_n, stiffness_of(chord))
            }
            None => (force_n, stiffness_n_per_m),
        };
        RangePress {
            force_n,
            stiffness_n_per_m,
            felt_n,
            felt_stiffness_n_per_m,
            beyond: 1.0 - edge_n / f,
        }
    }

    /// The chord compliance of `patch`'s last load-step interval along the patch's normal `n`,
    /// the edge's secant `C_e` across it: `C_e + n nᵀ (nᵀ (C_chord − C_e) n)`, with `C_chord =
    /// (C_e F_e − C_b F_b) / (F_e − F_b)` from the force `F_b` (N) that puts the patch at the
    /// share-weighted level of the step before each position's range edge to the edge's `F_e
    /// = edge_n`, each `C` the secant compliance there. Along the normal only, as the steps
    /// pushed the patches along it: the whole chord matrix makes oblique presses far past the
    /// coarse liver's edge stiffer across the normal than full FEM (p95 47.7 % against
    /// 42.4 % along the normal only). None where the chord is not stiffer along the normal
    /// (a patch that gives way under the tool, as under the KSV law, or whose range begins at
    /// its first step's level or has none): the press goes on at the secant.
    fn chord_compliance(
        &self,
        patch: &mut Patch,
        edge_n: f64,
        at_edge: &Matrix3<f64>,
    ) -> Option<Matrix3<f64>> {
        let before_n = edge_n * self.interval_start_share(&patch.shares);
        if !(before_n > 0.0 && before_n < edge_n) {
            return None;
        }
        let normal = self.patch_normal(&patch.shares)?;
        let before = self.column_compliance(patch, before_n);
        let chord = (at_edge * edge_n - before * before_n) / (edge_n - before_n);
        let extra = normal.dot(&((chord - at_edge) * normal));
        let along_edge = normal.dot(&(at_edge * normal));
        (extra < 0.0 && along_edge + extra > 0.0)
            .then(|| at_edge + normal * normal.transpose() * extra)
    }

    /// The unit outward normal of the patch `shares`: its positions' normals by their shares
    /// (none where they cancel).
    fn patch_normal(&self, shares: &[(usize, f64)]) -> Option<Vector3<f64>> {
        shares
            .iter()
            .map(|&(j, l)| Vector3::from(self.position_normals[j].map(f64::from)) * l)
            .sum::<Vector3<f64>>()
            .try_normalize(1e-12)
    }

    /// Where the last load-step interval of the patch `shares` begins, as a share of its range
    /// edge's force: the share-weighted level of the step before each position's range edge
    /// (zero for a range that ends at the first nonlinear step), over the share-weighted range
    /// level.
    fn interval_start_share(&self, shares: &[(usize, f64)]) -> f64 {
        let levels = &self.header.indentation_levels_m;
        let (before_m, range_m) = shares.iter().fold((0.0, 0.0), |(b, r), &(j, l)| {
            let range_m = f64::from(self.range_level_m[j]);
            let before_m = levels
                .iter()
                .rev()
                .find(|&&level| level < range_m * (1.0 - LEVEL_TOLERANCE))
                .copied()
                .unwrap_or(0.0);
            (b + l * before_m, r + l * range_m)
        });
        before_m / range_m
    }

    /// The largest force (N) on `patch` its load steps answer: the one that puts the patch's
    /// share-weighted level at the share-weighted level its positions' loads converged to
    /// ([`Self::range_level_m`]; infinite for a linear vademecum). A
    /// patch's positions are levelled by the patch centred on each, which on a mesh coarse
    /// under the tool can be more or less compliant than the patch between nodes (1.6 times
    /// over the middle of the test block's 1 cm grid under a 12 mm tool), so the edge can lie
    /// at another linear depth of the tool's own patch than the deepest step's level.
    pub fn range_force_n(&self, patch: &Patch) -> f64 {
        self.shares_range_force_n(&patch.shares)
    }

    /// [`Self::range_force_n`] of the patch `shares`.
    fn shares_range_force_n(&self, shares: &[(usize, f64)]) -> f64 {
        if self.steps.len() == 1 {
            return f64::INFINITY;
        }
        let (range_m, level_per_n) = shares.iter().fold((0.0, 0.0), |(r, n), &(j, l)| {
            let range_m = f64::from(self.range_level_m[j]);
            (r + l * range_m, n + l * self.level_m(j, 1.0))
        });
        range_m / level_per_n
    }

    /// [`Self::compliance`] from the patch's step columns, filling the linear step's and those
    /// of the steps its positions reach under a force whose magnitude, as
    /// [`Self::level_force_n`] gives it, is `level_force_n`.
    fn column_compliance(&self, patch: &mut Patch, level_force_n: f64) -> Matrix3<f64> {
        let blend = |j: usize| self.blend(self.level_m(j, level_force_n));
        patch.fill_columns(0, &self.steps[0].local);
        for slot in 0..patch.shares.len() {
            let (first, last, _) = blend(patch.shares[slot].0);
            patch.fill_columns(first, &self.steps[first].local);
            patch.fill_columns(last, &self.steps[last].local);
        }
        let transfers = self.header.material.law.modulus_grows_with_strain();
        let mut c = Matrix3::zeros();
        for (slot, &(j, l)) in patch.shares.iter().enumerate() {
            let (first, last, t) = blend(j);
            let linear = Matrix3::from_row_slice(patch.column(0, slot));
            let mut correction = Matrix3::zeros();
            for (step, w) in [(first, 1.0 - t), (last, t)] {
                if step != 0 && w != 0.0 {
                    correction += w * Matrix3::from_row_slice(patch.column(step, slot));
                }
            }
            c += l * (linear + correction);
            if transfers {
                let normal = Vector3::from(self.position_normals[j].map(f64::from));
                c += l * across_the_normal(&linear, &correction, &normal);
            }
        }
        c
    }

    /// The displacement field (m, all dofs) for a force (N) at `at`.
    pub fn field(&self, at: &SurfacePoint, force_n: &Vector3<f64>) -> Vec<f64> {
        let mut u = vec![0.0; self.dof_count()];
        self.add_patch_field(&self.patch(at).shares, force_n, &mut u);
        u
    }

    /// Adds the displacement field of a force `force_n` on the patch `shares` to `u`.
    pub fn add_patch_field(&self, shares: &[(usize, f64)], force_n: &Vector3<f64>, u: &mut [f64]) {
        for k in 0..self.steps.len() {
            if self.step_carries(k, shares, force_n) {
                self.add_step_field(k, shares, force_n, u);
            }
        }
    }

    /// Whether load step `step` carries any share of a force `force_n` on `shares`: the
    /// linear step always; a nonlinear one where a position's level blends it in.
    fn step_carries(&self, step: usize, shares: &[(usize, f64)], force_n: &Vector3<f64>) -> bool {
        let level_n = self.level_force_n(shares, force_n);
        step == 0
            || shares
                .iter()
                .any(|&(j, l)| self.step_share(step, j, l, level_n) > 0.0)
    }

    /// The modal coefficients of load step `step` for a force on the patch `shares`:
    /// `c_k = Σ_i γ_i Y^k_i · F`, added to `coefficients` (one per mode of the step).
    pub fn add_coefficients(
        &self,
        step: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        coefficients: &mut [f64],
    ) {
        self.mode_coefficients(step, shares, force_n, |mode, c| coefficients[mode] += c);
    }

    /// Calls `add(mode, c)` with each mode's coefficient `Σ_i γ_i Y_i · F` for a force on
    /// `shares` in load step `step`; a patch of more than [`SHARE_CHUNK`] positions is summed
    /// a chunk at a time, so a mode's coefficient is the sum of its calls. Each position's
    /// step share (its blend) is computed once, not once per mode, and kept on the stack; a
    /// chunk whose positions the step carries no share of calls nothing (the haptic tick
    /// skips the modes of the steps a press does not reach, most of a deep vademecum's).
    fn mode_coefficients(
        &self,
        step: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        mut add: impl FnMut(usize, f64),
    ) {
        let params = self.parameter_count();
        let level_n = self.level_force_n(shares, force_n);
        let mut weights = [0.0; SHARE_CHUNK];
        for chunk in shares.chunks(SHARE_CHUNK) {
            for (w, &(i, l)) in weights.iter_mut().zip(chunk) {
                *w = self.step_share(step, i, l, level_n);
            }
            if weights[..chunk.len()].iter().all(|&w| w == 0.0) {
                continue;
            }
            let modes = self.steps[step].parametric.chunks_exact(params);
            for (mode, y) in modes.enumerate() {
                let c = chunk
                    .iter()
                    .zip(&weights)
                    .filter(|&(_, &w)| w != 0.0)
                    .map(|(&(i, _), &w)| {
                        w * (0..3)
                            .map(|d| y[3 * i + d] as f64 * force_n[d])
                            .sum::<f64>()
                    })
                    .sum();
                add(mode, c);
            }
        }
    }

    /// Adds `Σ_k c_k X^k` of load step `step` to `u`.
    pub fn add_modes(&self, step: usize, coefficients: &[f64], u: &mut [f64]) {
        debug_assert_eq!(u.len(), self.dof_count());
        add_scaled_modes(&self.steps[step].spatial, coefficients, u);
    }

    /// Adds the near-field correction of load step `step` for a force on `shares` to `u`.
    pub fn add_corrections(
        &self,
        step: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        u: &mut [f64],
    ) {
        self.add_corrections_at(step, shares, force_n, Some, u);
    }

    /// [`Self::add_corrections`] into `u` numbered by `slot` (a node's place in `u`, or
    /// `None` to leave it out, before its correction is computed).
    pub(crate) fn add_corrections_at(
        &self,
        step: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        slot: impl Fn(usize) -> Option<usize>,
        u: &mut [f64],
    ) {
        let local = &self.steps[step].local;
        let level_n = self.level_force_n(shares, force_n);
        for &(i, l) in shares {
            let l = self.step_share(step, i, l, level_n);
            if l == 0.0 {
                continue;
            }
            for e in local.corrections_of(i) {
                let Some(at) = slot(local.correction_nodes[e] as usize) else {
                    continue;
                };
                let value = local.residual(e, force_n);
                for c in 0..3 {
                    u[3 * at + c] += l * value[c];
                }
            }
        }
    }

    /// Adds to `u` the displacement (m) of a blend of volume nodes (`(node, weight)`) under a
    /// force on `shares` in load step `step`: the modes there, each mode's coefficient computed
    /// once for the whole blend, and, where a node is in a loaded position's near field, its
    /// correction (the lists are sorted: a binary search each). Allocates nothing: what
    /// contact needs of a surface moved by other loads.
    pub fn add_blend_displacement(
        &self,
        step: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        blend: &[(usize, f64)],
        u: &mut Vector3<f64>,
    ) {
        let (spatial, dofs) = (&self.steps[step].spatial, self.dof_count());
        self.mode_coefficients(step, shares, force_n, |mode, c| {
            let x = &spatial[mode * dofs..(mode + 1) * dofs];
            for &(node, w) in blend {
                *u += Vector3::from_fn(|k, _| c * w * x[3 * node + k] as f64);
            }
        });
        self.add_blend_corrections(step, shares, force_n, blend, u);
    }

    /// The near-field part of [`Self::add_blend_displacement`]: what a force whose modes are
    /// already counted adds at the blend.
    pub fn add_blend_corrections(
        &self,
        step: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        blend: &[(usize, f64)],
        u: &mut Vector3<f64>,
    ) {
        let local = &self.steps[step].local;
        let level_n = self.level_force_n(shares, force_n);
        for &(i, l) in shares {
            let range = local.corrections_of(i);
            let nodes = &local.correction_nodes[range.clone()];
            let l = self.step_share(step, i, l, level_n);
            if l == 0.0 {
                continue;
            }
            for &(node, w) in blend {
                if let Ok(k) = nodes.binary_search(&(node as u32)) {
                    let e = range.start + k;
                    *u += local.residual(e, force_n) * (l * w);
                }
            }
        }
    }

    fn add_step_field(
        &self,
        k: usize,
        shares: &[(usize, f64)],
        force_n: &Vector3<f64>,
        u: &mut [f64],
    ) {
        let mut coefficients = vec![0.0; self.modes(k)];
        self.add_coefficients(k, shares, force_n, &mut coefficients);
        self.add_modes(k, &coefficients, u);
        self.add_corrections(k, shares, force_n, u);
    }
}

/// How many of a patch's positions a mode's coefficient is summed over at a time, their
/// weights on the stack (a larger patch takes several chunks, to the same sum).
const SHARE_CHUNK: usize = 128;

/// A position's range level is stored in single precision: a step's level within this
/// share of it is the same level.
const LEVEL_TOLERANCE: f64 = 1e-6;

/// A press of a patch, within or beyond its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangePress {
    /// The force on the organ (N): what its load and the field drawn take.
    pub force_n: Vector3<f64>,
    /// How that force changes with the indentation (N/m): the inverse of the patch's
    /// compliance (its secant compliance for a nonlinear vademecum; zero if singular).
    pub stiffness_n_per_m: Matrix3<f64>,
    /// The force the trainee feels the opposite of (N): `force_n` within the range; beyond it
    /// stiffer, as the tissue goes on firming up past its last load step
    /// ([`Vademecum::patch_press_in_range`]).
    pub felt_n: Vector3<f64>,
    /// How the felt force changes with the indentation (N/m): `stiffness_n_per_m` within the
    /// range; beyond it the inverse of the last load-step interval's chord compliance, along
    /// which the felt force grows there.
    pub felt_stiffness_n_per_m: Matrix3<f64>,
    /// The share of the indentation that lies beyond the range (zero within it).
    pub beyond: f64,
}

impl RangePress {
    fn within(force_n: Vector3<f64>, stiffness_n_per_m: Matrix3<f64>) -> Self {
        Self {
            force_n,
            stiffness_n_per_m,
            felt_n: force_n,
            felt_stiffness_n_per_m: stiffness_n_per_m,
            beyond: 0.0,
        }
    }
}

/// The force that `compliance` carries to `indentation_m`, and the stiffness (N/m; zero where
/// the compliance is singular).
fn solve_press(
    compliance: Matrix3<f64>,
    indentation_m: &Vector3<f64>,
) -> (Vector3<f64>, Matrix3<f64>) {
    let stiffness = stiffness_of(compliance);
    (stiffness * indentation_m, stiffness)
}

/// The stiffness (N/m) of `compliance` (m/N): its inverse, zero where it is singular.
fn stiffness_of(compliance: Matrix3<f64>) -> Matrix3<f64> {
    compliance.try_inverse().unwrap_or_else(Matrix3::zeros)
}

/// The secant iteration from the press `press` (force, stiffness) to the force whose
/// `compliance` carries it to `indentation_m`; it stops once the force changes by less than
/// [`SECANT_TOLERANCE`], or after [`SECANT_ITERATIONS`].
fn secant_iteration(
    mut press: (Vector3<f64>, Matrix3<f64>),
    indentation_m: &Vector3<f64>,
    mut compliance: impl FnMut(&Vector3<f64>) -> Matrix3<f64>,
) -> (Vector3<f64>, Matrix3<f64>) {
    for _ in 0..SECANT_ITERATIONS {
        let next = solve_press(compliance(&press.0), indentation_m);
        let settled = (next.0 - press.0).norm() <= SECANT_TOLERANCE * next.0.norm();
        press = next;
        if settled {
            break;
        }
    }
    press
}

/// Secant iterations of [`Vademecum::force_for_indentation`] over load steps, at most.
const SECANT_ITERATIONS: usize = 8;

/// The secant iteration stops once the force changes by less than this (relative): far below
/// the 7 % a hand feels, and it spares the haptic tick the iterations that change nothing.
const SECANT_TOLERANCE: f64 = 1e-6;

/// Adds `Σ_k c_k X^k` to `u`, the modes `X^k` one after another in `modes`, each as long as
/// `u`; a mode whose coefficient is zero is skipped.
pub(crate) fn add_scaled_modes(modes: &[f32], coefficients: &[f64], u: &mut [f64]) {
    for (x, &c) in modes.chunks_exact(u.len()).zip(coefficients) {
        if c != 0.0 {
            for (ui, &xi) in u.iter_mut().zip(x) {
                *ui += c * xi as f64;
            }
        }
    }
}

/// The correction of a position's compliance to forces across its normal `normal`. A step
/// holds only the response to a push along the normal (`correction`, whose columns are that
/// push's, weighted by each axis's share of it), so a force across the normal would be
/// answered linearly. A law whose modulus grows with the strain stiffens the tissue under
/// the tool whichever way it is pushed: the responses to forces across the normal are scaled
/// by the ratio the normal compliance changed by, `nᵀ D n / nᵀ L n` (`L` the linear
/// compliance), kept above −0.9 so that the compliance stays positive. The tool's own
/// patch pushed across the normal at each step would be exact, at three times the build.
fn across_the_normal(
    linear: &Matrix3<f64>,
    correction: &Matrix3<f64>,
    normal: &Vector3<f64>,
) -> Matrix3<f64> {
    let along = normal.dot(&(linear * normal));
    if along <= 0.0 {
        return Matrix3::zeros();
    }
    let ratio = (normal.dot(&(correction * normal)) / along).max(-0.9);
    let across = Matrix3::identity() - normal * normal.transpose();
    ratio * linear * across
}
