//! The cut state online: incisions advance segment by segment, and the small system over the
//! enriched unknowns gains rows and columns with each, never rebuilt.
//!
//! With the shifted Heaviside enrichment the X-FEM stiffness is `[[K, B], [Bᵀ, A]]`, where
//! `K` is the *uncut* stiffness (the cut leaves the nodes' own functions as they were), `B`
//! couples them to the enriched functions and `A` couples those among themselves. Condensed on
//! the enriched amplitudes `q`:
//!
//! `S q = −Bᵀ K⁻¹ f` with `S = A − Bᵀ K⁻¹ B`, then `u = K⁻¹ f − K⁻¹ B q`.
//!
//! `K⁻¹` is the uncut organ's response ([`UncutResponse`]), and `Z = K⁻¹ B` its response to
//! each enriched function's forces: exact, or over a cut vademecum a patch solve corrected by
//! its modes (`local.rs`, which makes `S` the Schur complement of a Ritz system and so keeps
//! it positive definite), kept as modal coefficients and a sparse near field and, at
//! the surface's dofs, as `Ẑ = Z L⁻ᵀ`, `L` the Cholesky factor of `S`, so that the tick's
//! felt force reads it and solves nothing. A segment only ever adds enriched functions (a
//! longer face enriches the nodes its growth cuts whole; a turn starts a face with its own),
//! and the entries between the functions already there do not change. So a segment appends rows and columns to `S`,
//! whose factor is extended by bordering (`O(n² k)` for `k` new unknowns on `n`, against
//! `O(n³)` for a new factorization), and columns to `Ẑ`, whose old ones bordering leaves as
//! they are.

use std::borrow::Borrow;
use std::collections::HashMap;

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::CutError;
use super::enrichment::{Enriched, Enrichment, Front, Supports};
use super::factor::GrowingCholesky;
use super::incision::{CutFace, Incision};
use super::local::{LocalResponse, PatchSolver};
use super::response::{Response, UncutResponse, sparse_load};
use super::view::{CutView, add_surface_part, gram, surface_dof};
use super::xfem::{CutSolution, element_functions, piece_weights};
use crate::fem::{FemModel, PRESCRIBED};
use crate::mesh::Surface;

/// A sparse column of `B`: the nodes' own dofs it couples to, with the entries.
type SparseColumn = Vec<(usize, f64)>;

/// Entries of `A` keyed `(row unknown, column unknown)`.
type Entries = HashMap<(usize, usize), f64>;

/// One incision of the state: its blade and the faces (indices into the state's faces) it
/// has swept.
struct Cut {
    incision: Incision,
    faces: Vec<usize>,
}

/// The cut organ as incisions come: the enriched functions in the order they appeared, the
/// uncut response to each, and the growing condensed system.
pub struct CutState<M: Borrow<FemModel>, R: UncutResponse> {
    /// The organ's model, borrowed or owned (a cut state applied where there are no threads
    /// keeps its own).
    model: M,
    response: R,
    cuts: Vec<Cut>,
    faces: Vec<CutFace>,
    /// Enriched functions in the order they appeared: unknowns `3j..3j+3`.
    functions: Vec<Enriched>,
    /// Per unknown, `B`'s column.
    coupling: Vec<SparseColumn>,
    /// The enriched functions' uncut responses `Z = K⁻¹ B`: per unknown, the modal
    /// coefficients of `Ẑ = Z L⁻ᵀ` (`L` the factor of `S`) …
    z_modal: Vec<Vec<f64>>,
    /// … per dof, the rest of `Z` as `(unknown, value)` …
    z_near: Vec<Vec<(u32, f64)>>,
    /// … and per dof of a surface node, the rest of `Ẑ`. With `Ẑ`, the felt compliance's
    /// `Wᵀ S⁻¹ W` is `(Ẑᵀ P)ᵀ (Ẑᵀ P)`: the tick reads the few surface dofs under the tool
    /// for every unknown at once and solves nothing. Bordering leaves `Ẑ`'s old columns as
    /// they are.
    z_hat_surface: Vec<Vec<(u32, f64)>>,
    /// Per node, its place among the surface nodes, or [`crate::mesh::NOT_ON_SURFACE`].
    surface_index_of: Vec<usize>,
    /// Per unknown, `Xᵀ` of its column of `B`: its products with any response's modal part.
    rows: Vec<Vec<f64>>,
    /// Per unknown, `Xᵀ ρ` of its patch response's residual (empty for an exact response).
    residual_modes: Vec<Vec<f64>>,
    /// The patch solves behind a compressed response's enriched functions; `None` for an
    /// exact response.
    local: Option<PatchSolver>,
    /// The lower Cholesky factor of `S`.
    factor: GrowingCholesky,
    /// Where the cut's front falls between element faces.
    front: Front,
    /// The mesh's supports, which every segment's enrichment reads.
    supports: Supports,
}

impl<M: Borrow<FemModel>, R: UncutResponse> CutState<M, R> {
    /// The uncut organ: `model` gives the mesh, the material and the held nodes, `response`
    /// its uncut solves.
    pub fn new(model: M, response: R) -> Self {
        let local = (response.modes() > 0).then(|| {
            let radius_m = response
                .patch_radius_m()
                .unwrap_or_else(|| PATCH_EDGES * mean_edge_m(model.borrow()));
            PatchSolver::new(model.borrow(), &response, radius_m)
        });
        Self::with_local(model, response, local)
    }

    fn with_local(model: M, response: R, local: Option<PatchSolver>) -> Self {
        let surface = Surface::extract(model.borrow().mesh());
        let nodes = model.borrow().mesh().node_count();
        let supports = Supports::new(model.borrow().mesh());
        Self {
            model,
            response,
            cuts: Vec::new(),
            faces: Vec::new(),
            functions: Vec::new(),
            coupling: Vec::new(),
            z_modal: Vec::new(),
            z_near: vec![Vec::new(); 3 * nodes],
            z_hat_surface: vec![Vec::new(); 3 * surface.nodes.len()],
            surface_index_of: surface.surface_index_of,
            rows: Vec::new(),
            residual_modes: Vec::new(),
            local,
            factor: GrowingCholesky::default(),
            front: Front::Inward,
            supports,
        }
    }

    /// The state with a compressed response's patches reaching `radius_m` from the loaded
    /// nodes (before any cut is made); an exact response solves no patch.
    pub fn with_patch_radius(mut self, radius_m: f64) -> Self {
        if let Some(local) = &mut self.local {
            local.set_radius(radius_m);
        }
        self
    }

    fn model(&self) -> &FemModel {
        self.model.borrow()
    }

    /// The state with the cut's front placed as `front` says (before any cut is made).
    pub fn with_front(mut self, front: Front) -> Self {
        self.front = front;
        self
    }

    /// The organ uncut again, its front placed as before: every incision undone, the uncut
    /// response (its factorization) kept.
    pub fn heal(self) -> Self {
        let front = self.front;
        Self::with_local(self.model, self.response, self.local).with_front(front)
    }

    /// Sets a new blade on the surface (see [`Incision::start`]); returns its index.
    pub fn start(&mut self, at: Point3<f64>, blade: Vector3<f64>, depth_m: f64) -> usize {
        self.cuts.push(Cut {
            incision: Incision::start(at, blade, depth_m),
            faces: Vec::new(),
        });
        self.cuts.len() - 1
    }

    /// Incision `cut` advances to `to`: the system grows by the functions the step enriches.
    /// A refused step (degenerate, or one that frees a piece of tissue) leaves the state as it
    /// was.
    pub fn advance(&mut self, cut: usize, to: Point3<f64>) -> Result<(), CutError> {
        let mut incision = self.cuts[cut].incision.clone();
        incision.advance(to)?;
        let face = *incision.faces().last().expect("advanced");
        let turned = incision.faces().len() > self.cuts[cut].faces.len();
        let id = match turned {
            true => self.add_face(face)?,
            false => {
                let id = *self.cuts[cut].faces.last().expect("a face to lengthen");
                self.lengthen(id, face)?;
                id
            }
        };
        let entry = &mut self.cuts[cut];
        entry.incision = incision;
        if turned {
            entry.faces.push(id);
        }
        Ok(())
    }

    /// Adds a whole face at once (a keratotomy's meridian incision, say); returns its index.
    pub fn add_face(&mut self, face: CutFace) -> Result<usize, CutError> {
        let mut faces = self.faces.clone();
        faces.push(face);
        self.apply(faces)?;
        Ok(self.faces.len() - 1)
    }

    /// Replaces face `id` by `face`, which must cover it (the same incision, longer or
    /// deeper): a cut only ever grows.
    pub fn lengthen(&mut self, id: usize, face: CutFace) -> Result<(), CutError> {
        let mut faces = self.faces.clone();
        faces[id] = face;
        self.apply(faces)
    }

    /// Takes `faces` as the cut, growing the system by the functions they add; a refused cut
    /// leaves the state as it was.
    fn apply(&mut self, faces: Vec<CutFace>) -> Result<(), CutError> {
        let enrichment = Enrichment::over(self.model().mesh(), &self.supports, &faces, self.front);
        let held = |n: usize| self.model().dofs().free_index[3 * n] == PRESCRIBED;
        if enrichment.detaches(self.model().mesh(), held) {
            return Err(CutError::Detached);
        }
        self.grow(&enrichment)?;
        self.faces = faces;
        Ok(())
    }

    /// The enriched unknowns so far.
    pub fn unknowns(&self) -> usize {
        self.z_modal.len()
    }

    pub fn faces(&self) -> &[CutFace] {
        &self.faces
    }

    /// The cut organ under nodal forces `loads_n` (full vector, each force on its node's own
    /// side), in the same form as the full X-FEM solve's, enriched amplitudes in the order of
    /// [`Enrichment::new`] over [`Self::faces`]. Fails only for a load outside the region a
    /// cut vademecum covers.
    pub fn solve(&self, loads_n: &[f64]) -> Result<CutSolution, CutError> {
        let uncut = self.response.respond(&[sparse_load(loads_n)])?.remove(0);
        Ok(self.solve_from(uncut))
    }

    /// The cut organ from its uncut displacement `uncut` (`K⁻¹ f`, however it is known: a
    /// standing load such as the intraocular pressure has it computed once, exactly).
    pub fn solve_from(&self, uncut: Response) -> CutSolution {
        let (nodes_m, q) = self.condensed(uncut);
        let order = Enrichment::over(self.model().mesh(), &self.supports, &self.faces, self.front);
        let index = self.function_index();
        let mut enriched_m = Vec::with_capacity(q.len());
        for f in &order.functions {
            let j = index.get(&(f.node, f.face));
            enriched_m.extend((0..3).map(|c| j.map_or(0.0, |&j| q[3 * j + c])));
        }
        CutSolution {
            nodes_m,
            enriched_m,
        }
    }

    /// The nodes' displacements from the uncut ones `response`, and the enriched amplitudes in
    /// the state's order: `q = −S⁻¹ Bᵀ K⁻¹ f`, `u = K⁻¹ f − Z q`, the modal part as `Ẑ y`
    /// with `L y = −Bᵀ K⁻¹ f` and `q = L⁻ᵀ y`.
    fn condensed(&self, response: Response) -> (Vec<f64>, Vec<f64>) {
        let mut u = vec![0.0; 3 * self.model().mesh().node_count()];
        scatter(&response.near, 1.0, &mut u);
        let rhs: Vec<f64> = (0..self.unknowns())
            .map(|p| -self.product(p, &response.modal, &u))
            .collect();
        let mut y = rhs;
        self.factor.forward(&mut y);
        // An uncut field known exactly has no modal part; `Z`'s may still have one.
        let mut modal = response.modal;
        modal.resize(self.response.modes(), 0.0);
        for (z, &yj) in self.z_modal.iter().zip(&y) {
            modal.iter_mut().zip(z).for_each(|(m, a)| *m -= yj * a);
        }
        let mut q = y;
        self.factor.backward(&mut q);
        for (ud, entries) in u.iter_mut().zip(&self.z_near) {
            *ud -= entries.iter().map(|&(p, v)| q[p as usize] * v).sum::<f64>();
        }
        self.response.add_spatial(&modal, &mut u);
        (u, q)
    }

    /// `b_pᵀ K⁻¹ f` for unknown `p` and a response given by its modal coefficients and its
    /// near field scattered over full dofs.
    fn product(&self, p: usize, modal: &[f64], near: &[f64]) -> f64 {
        let modal_part: f64 = self.rows[p].iter().zip(modal).map(|(r, m)| r * m).sum();
        modal_part
            + self.coupling[p]
                .iter()
                .map(|&(d, b)| b * near[d])
                .sum::<f64>()
    }

    /// Each enriched function's place among the unknowns, by `(node, face)`.
    fn function_index(&self) -> HashMap<(usize, usize), usize> {
        self.functions
            .iter()
            .enumerate()
            .map(|(j, f)| ((f.node, f.face), j))
            .collect()
    }

    /// The force (N) the tool feels for an `indentation_m` of the patch it loads: `patch`
    /// holds the nodes under the tool and their shares of its load (summing to one). The
    /// uncut patch compliance `Pᵀ K⁻¹ P` comes from the uncut response (a sparse solve for an
    /// exact one); the haptic tick, which has it from the tool's vademecum, calls
    /// [`Self::felt_force_over`]. An error for a patch outside the region a cut vademecum
    /// covers.
    pub fn felt_force(
        &self,
        patch: &[(usize, f64)],
        indentation_m: Vector3<f64>,
    ) -> Result<Option<Vector3<f64>>, CutError> {
        let uncut = self.uncut_compliance(patch)?;
        Ok(self.felt_force_over(patch, uncut, indentation_m))
    }

    /// The uncut patch compliance `Pᵀ K⁻¹ P` (m/N) from the uncut response.
    pub fn uncut_compliance(&self, patch: &[(usize, f64)]) -> Result<Matrix3<f64>, CutError> {
        let loads = axis_loads(patch);
        let responses = self.response.respond(&loads)?;
        let mut near = vec![0.0; 3 * self.model().mesh().node_count()];
        let mut uncut = Matrix3::zeros();
        for (axis, response) in responses.iter().enumerate() {
            scatter(&response.near, 1.0, &mut near);
            for (row, load) in loads.iter().enumerate() {
                let modal: f64 = self
                    .response
                    .spatial_products(load)
                    .iter()
                    .zip(&response.modal)
                    .map(|(x, m)| x * m)
                    .sum();
                let near_part: f64 = load.iter().map(|&(d, s)| s * near[d]).sum();
                uncut[(row, axis)] = modal + near_part;
            }
            scatter(&response.near, -1.0, &mut near);
        }
        Ok(uncut)
    }

    /// The felt force from the uncut patch compliance `uncut_m_per_n` (3 × 3): the cut one is
    /// `C = C₀ + Wᵀ S⁻¹ W` with `W = Bᵀ K⁻¹ P = Zᵀ P` (`K⁻¹` symmetric), `Wᵀ S⁻¹ W = Yᵀ Y`
    /// with `Y = Ẑᵀ P` read at the patch's nodes: no solve, `O(n (p + m))` for `n` unknowns,
    /// `p` patch nodes and `m` modes. The patch's nodes are surface nodes, as a tool's are (a
    /// node inside adds nothing). `None` where the patch does not resist.
    pub fn felt_force_over(
        &self,
        patch: &[(usize, f64)],
        uncut_m_per_n: Matrix3<f64>,
        indentation_m: Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        let loads = axis_loads(patch);
        let patch_modes: Vec<Vec<f64>> = loads
            .iter()
            .map(|load| self.response.spatial_products(load))
            .collect();
        // Wᵀ S⁻¹ W = Yᵀ Y with Y = L⁻¹ W = Ẑᵀ P.
        let y: Vec<Vec<f64>> = (0..3)
            .map(|axis| {
                let mut y: Vec<f64> = self
                    .z_modal
                    .iter()
                    .map(|z| patch_modes[axis].iter().zip(z).map(|(x, m)| x * m).sum())
                    .collect();
                add_surface_part(
                    &self.surface_index_of,
                    &self.z_hat_surface,
                    &loads[axis],
                    &mut y,
                );
                y
            })
            .collect();
        (uncut_m_per_n + gram(&y))
            .try_inverse()
            .map(|stiffness| stiffness * indentation_m)
    }

    /// What the tick and the window need of the state, to read while the state grows
    /// elsewhere: the faces, the enriched functions, `Ẑ` at the surface's dofs and the factor
    /// of `S`. Only for an exact uncut response, whose `Ẑ` has no modal part: a cut
    /// vademecum's would need its modes too.
    pub fn view(&self) -> CutView {
        debug_assert!(self.z_modal.iter().all(|z| z.is_empty()));
        CutView {
            faces: self.faces.clone(),
            unknowns: self.unknowns(),
            functions: self.functions.clone(),
            surface_index_of: self.surface_index_of.clone(),
            z_hat_surface: self.z_hat_surface.clone(),
            factor: self.factor.clone(),
        }
    }

    /// Incision `cut` cuts `depth_m` deep from now on, and its last face as deep: a blade
    /// pressed deeper deepens the face it is sweeping (which then covers the shallower one).
    /// A depth no deeper than the incision's changes nothing.
    pub fn deepen(&mut self, cut: usize, depth_m: f64) -> Result<(), CutError> {
        let mut incision = self.cuts[cut].incision.clone();
        let deeper = incision.deepen(depth_m)?;
        if let (Some(face), Some(&id)) = (deeper, self.cuts[cut].faces.last()) {
            self.lengthen(id, face)?;
        }
        self.cuts[cut].incision = incision;
        Ok(())
    }

    /// Adds the functions of `enrichment` not yet in the state: their columns of `B`, their
    /// uncut responses, and their rows of `S`, bordering the factor.
    fn grow(&mut self, enrichment: &Enrichment) -> Result<(), CutError> {
        let known = self.function_index();
        let held = |n: usize| self.model().dofs().free_index[3 * n] == PRESCRIBED;
        // The enrichment's function index → the state's, old or new; held ones dropped.
        let mut slot = vec![None; enrichment.functions.len()];
        let mut added = Vec::new();
        for (j, f) in enrichment.functions.iter().enumerate() {
            if held(f.node) {
                continue;
            }
            slot[j] = Some(match known.get(&(f.node, f.face)) {
                Some(&old) => old,
                None => {
                    added.push(*f);
                    self.functions.len() + added.len() - 1
                }
            });
        }
        if known.len()
            != enrichment
                .functions
                .iter()
                .filter(|f| !held(f.node))
                .count()
                - added.len()
        {
            return Err(CutError::Solve(
                "a step took an enriched function away: the cut state cannot grow by it".into(),
            ));
        }
        let first_new = 3 * self.functions.len();
        let (coupling, a) = self.new_blocks(enrichment, &slot, first_new, 3 * added.len());
        let local = match &self.local {
            None => self
                .response
                .respond(&coupling)?
                .into_iter()
                .map(|response| LocalResponse {
                    response,
                    ..LocalResponse::default()
                })
                .collect(),
            Some(solver) => solver.respond(&coupling, &self.response)?,
        };
        let rows: Vec<Vec<f64>> = coupling
            .iter()
            .map(|b| self.response.spatial_products(b))
            .collect();
        let columns = self.condensed_columns(&coupling, &a, &local);
        self.factor.border(&columns).map_err(|_| {
            CutError::Solve("the condensed system lost positive definiteness".into())
        })?;
        self.functions.extend(added);
        self.coupling.extend(coupling);
        let mut z = Vec::with_capacity(local.len());
        for response in local {
            self.residual_modes.push(response.residual_modes);
            z.push(response.response);
        }
        self.push_responses(z);
        self.rows.extend(rows);
        Ok(())
    }

    /// The condensed matrix's new columns, against every unknown, old then new:
    /// `S̃_pr = A_pr − b_pᵀ r_r + r_pᵀ ρ_r + (Xᵀ ρ_p) · c_r` (`local.rs`; with an exact
    /// response `ρ = 0` and this is `A − Bᵀ K⁻¹ B`).
    fn condensed_columns(
        &self,
        coupling: &[SparseColumn],
        a: &Entries,
        new: &[LocalResponse],
    ) -> Vec<Vec<f64>> {
        let first_new = self.coupling.len();
        let total = first_new + new.len();
        let mut near = vec![0.0; 3 * self.model().mesh().node_count()];
        let mut scratch = near.clone();
        let mut columns = vec![vec![0.0; total]; new.len()];
        for (r, column) in columns.iter_mut().enumerate() {
            let z = &new[r].response;
            scatter(&z.near, 1.0, &mut near);
            let edge = self.edge_products(&new[r].residual, new, &mut scratch);
            for (p, entry) in column.iter_mut().enumerate() {
                let (b, residual_modes) = match p < first_new {
                    true => (&self.coupling[p], &self.residual_modes[p]),
                    false => (&coupling[p - first_new], &new[p - first_new].residual_modes),
                };
                let modal: f64 = residual_modes
                    .iter()
                    .zip(&z.modal)
                    .map(|(x, c)| x * c)
                    .sum();
                let near_part: f64 = b.iter().map(|&(d, v)| v * near[d]).sum();
                *entry = a.get(&(p, first_new + r)).copied().unwrap_or(0.0) - near_part
                    + edge[p]
                    + modal;
            }
            scatter(&z.near, -1.0, &mut near);
        }
        columns
    }

    /// `r_pᵀ ρ` for every unknown `p`, old (through their responses per dof) then `new`;
    /// `scratch` (full dofs, zero) is left zero.
    fn edge_products(
        &self,
        residual: &[(usize, f64)],
        new: &[LocalResponse],
        scratch: &mut [f64],
    ) -> Vec<f64> {
        let mut products = vec![0.0; self.coupling.len() + new.len()];
        if residual.is_empty() {
            return products;
        }
        for &(d, rho) in residual {
            for &(p, v) in &self.z_near[d] {
                products[p as usize] += v * rho;
            }
        }
        scatter(residual, 1.0, scratch);
        for (k, response) in new.iter().enumerate() {
            products[self.coupling.len() + k] = response
                .response
                .near
                .iter()
                .map(|&(d, v)| v * scratch[d])
                .sum();
        }
        scatter(residual, -1.0, scratch);
        products
    }

    /// Appends the new unknowns' responses: `Z`'s rest as it is, and `Ẑ`'s modal part and
    /// surface rest, their factor rows `l` in place: `ẑ_p = (z_p − Σ_{j<p} ẑ_j l_j) / l_p`.
    /// The recurrence runs dof by dof (each dof's entries are all it reads), so the surface
    /// dofs go in parallel.
    fn push_responses(&mut self, z: Vec<Response>) {
        let first = self.z_modal.len();
        let factor = &self.factor;
        let hatted = |value: f64, entries: &[(u32, f64)], p: usize| {
            let reached: f64 = entries
                .iter()
                .map(|&(j, v)| factor.at(p, j as usize) * v)
                .sum();
            (value - reached) / factor.at(p, p)
        };
        let mut dense = vec![vec![0.0; z.len()]; self.z_hat_surface.len()];
        for (r, response) in z.iter().enumerate() {
            for &(d, v) in &response.near {
                self.z_near[d].push(((first + r) as u32, v));
                if let Some(k) = surface_dof(&self.surface_index_of, d) {
                    dense[k][r] += v;
                }
            }
        }
        self.z_hat_surface
            .par_iter_mut()
            .zip(dense)
            .for_each(|(entries, values)| {
                for (r, value) in values.into_iter().enumerate() {
                    let v = hatted(value, entries, first + r);
                    if v != 0.0 {
                        entries.push(((first + r) as u32, v));
                    }
                }
            });
        for (r, response) in z.into_iter().enumerate() {
            let p = first + r;
            let mut modal = response.modal;
            for (j, zj) in self.z_modal.iter().enumerate() {
                let l = factor.at(p, j);
                modal.iter_mut().zip(zj).for_each(|(m, a)| *m -= l * a);
            }
            modal.iter_mut().for_each(|m| *m /= factor.at(p, p));
            self.z_modal.push(modal);
        }
    }

    /// `B`'s columns for the new unknowns `first_new..first_new + count`, and the entries of
    /// `A` between any unknown and a new one (keyed `(row, new column)`).
    fn new_blocks(
        &self,
        enrichment: &Enrichment,
        slot: &[Option<usize>],
        first_new: usize,
        count: usize,
    ) -> (Vec<SparseColumn>, Entries) {
        let mesh = self.model().mesh();
        let nodes = mesh.node_count();
        let free = &self.model().dofs().free_index;
        let mut coupling = vec![Vec::new(); count];
        let mut a = HashMap::new();
        // A function's first unknown in the state, or its node's first dof (own functions).
        let unknown = |function_dof: usize| -> Option<usize> {
            match function_dof.checked_sub(3 * nodes) {
                None => Some(function_dof),
                Some(k) => slot[k / 3].map(|s| 3 * s),
            }
        };
        for (t, tet) in mesh.tets().iter().enumerate() {
            let cut = &enrichment.elements[t];
            let touches_new = cut
                .functions
                .iter()
                .any(|&(j, _)| slot[j].is_some_and(|s| 3 * s >= first_new));
            if !touches_new {
                continue;
            }
            let geometry = &self.model().geometry()[t];
            let (lambda, mu) = self.model().lame(t);
            let functions = element_functions(tet, cut, nodes);
            let weights = piece_weights(cut, &functions, enrichment, geometry.volume_m3);
            let n = functions.len();
            for (y, &(col_dof, b)) in functions.iter().enumerate().skip(4) {
                let Some(col) = unknown(col_dof).filter(|&c| c >= first_new) else {
                    continue;
                };
                for (x, &(row_dof, a_corner)) in functions.iter().enumerate() {
                    let w = weights[x * n + y];
                    if w == 0.0 {
                        continue;
                    }
                    let block = geometry.elastic_block(a_corner, b, lambda, mu) * w;
                    for i in 0..3 {
                        for k in 0..3 {
                            if x < 4 {
                                let d = row_dof + i;
                                if free[d] != PRESCRIBED {
                                    coupling[col - first_new + k].push((d, block[(i, k)]));
                                }
                            } else if let Some(row) = unknown(row_dof) {
                                *a.entry((row + i, col + k)).or_insert(0.0) += block[(i, k)];
                            }
                        }
                    }
                }
            }
        }
        (coupling, a)
    }
}

/// A compressed response that does not say how far its patches reach has them reach this
/// many mean element edges from the loaded nodes.
const PATCH_EDGES: f64 = 3.0;

/// The mean edge length of the model's tetrahedra (m).
fn mean_edge_m(model: &FemModel) -> f64 {
    let nodes = model.mesh().nodes();
    let (mut sum, mut count) = (0.0, 0usize);
    for tet in model.mesh().tets() {
        for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            sum += (nodes[tet[i]] - nodes[tet[j]]).norm();
            count += 1;
        }
    }
    sum / count.max(1) as f64
}

/// The patch's unit loads along x, y and z: each node's share on its dof of that axis.
fn axis_loads(patch: &[(usize, f64)]) -> Vec<SparseColumn> {
    (0..3)
        .map(|axis| {
            patch
                .iter()
                .map(|&(n, share)| (3 * n + axis, share))
                .collect()
        })
        .collect()
}

/// `u += scale · v` for a sparse `v`.
fn scatter(v: &[(usize, f64)], scale: f64, u: &mut [f64]) {
    for &(d, value) in v {
        u[d] += scale * value;
    }
}
