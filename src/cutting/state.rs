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
//! each enriched function's forces. A segment only ever adds enriched functions (a longer face
//! enriches the nodes its growth cuts whole; a turn starts a face with its own), and the
//! entries between the functions already there do not change. So a segment appends columns to
//! `Z` and rows and columns to `S`, whose Cholesky factor is extended by bordering: `O(n² k)`
//! for `k` new unknowns on `n`, against `O(n³)` for a new factorization.

use std::collections::HashMap;

use nalgebra::{Matrix3, Point3, Vector3};

use super::CutError;
use super::enrichment::Enrichment;
use super::incision::{CutFace, Incision};
use super::response::UncutResponse;
use super::xfem::{CutSolution, element_functions, piece_weights};
use crate::fem::{FemModel, PRESCRIBED};

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
pub struct CutState<'m, R: UncutResponse> {
    model: &'m FemModel,
    response: R,
    cuts: Vec<Cut>,
    faces: Vec<CutFace>,
    /// Enriched functions as `(node, face)`, in the order they appeared: unknowns `3j..3j+3`.
    functions: Vec<(usize, usize)>,
    /// Per unknown, `B`'s column.
    coupling: Vec<SparseColumn>,
    /// Per unknown, `K⁻¹` of its column of `B` (full nodal vectors).
    z: Vec<Vec<f64>>,
    /// The lower Cholesky factor of `S`, row by row (row `i` holds `i + 1` entries).
    factor: Vec<Vec<f64>>,
}

impl<'m, R: UncutResponse> CutState<'m, R> {
    /// The uncut organ: `model` gives the mesh, the material and the held nodes, `response`
    /// its uncut solves.
    pub fn new(model: &'m FemModel, response: R) -> Self {
        Self {
            model,
            response,
            cuts: Vec::new(),
            faces: Vec::new(),
            functions: Vec::new(),
            coupling: Vec::new(),
            z: Vec::new(),
            factor: Vec::new(),
        }
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
        let mut faces = self.faces.clone();
        let turned = incision.faces().len() > self.cuts[cut].faces.len();
        let id = if turned {
            faces.push(face);
            faces.len() - 1
        } else {
            let id = *self.cuts[cut].faces.last().expect("a face to lengthen");
            faces[id] = face;
            id
        };
        let enrichment = Enrichment::new(self.model.mesh(), &faces);
        let held = |n: usize| self.model.dofs().free_index[3 * n] == PRESCRIBED;
        if enrichment.detaches(self.model.mesh(), held) {
            return Err(CutError::Detached);
        }
        self.grow(&enrichment)?;
        self.faces = faces;
        let entry = &mut self.cuts[cut];
        entry.incision = incision;
        if turned {
            entry.faces.push(id);
        }
        Ok(())
    }

    /// The enriched unknowns so far.
    pub fn unknowns(&self) -> usize {
        self.z.len()
    }

    pub fn faces(&self) -> &[CutFace] {
        &self.faces
    }

    /// The cut organ under nodal forces `loads_n` (full vector, each force on its node's own
    /// side), in the same form as the full X-FEM solve's, enriched amplitudes in the order of
    /// [`Enrichment::new`] over [`Self::faces`].
    pub fn solve(&self, loads_n: &[f64]) -> CutSolution {
        let (nodes_m, q) = self.condensed(loads_n);
        let order = Enrichment::new(self.model.mesh(), &self.faces);
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

    /// The nodes' displacements under `loads_n`, and the enriched amplitudes in the state's
    /// order: `q = −S⁻¹ Bᵀ K⁻¹ f`, `u = K⁻¹ f − Z q`.
    fn condensed(&self, loads_n: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut u = loads_n.to_vec();
        self.response.respond(&mut u, 1);
        let rhs: Vec<f64> = self
            .coupling
            .iter()
            .map(|column| -column.iter().map(|&(d, b)| b * u[d]).sum::<f64>())
            .collect();
        let q = self.cholesky_solve(rhs);
        for (zr, qr) in self.z.iter().zip(&q) {
            for (ui, z) in u.iter_mut().zip(zr) {
                *ui -= z * qr;
            }
        }
        (u, q)
    }

    /// Each enriched function's place among the unknowns, by `(node, face)`.
    fn function_index(&self) -> HashMap<(usize, usize), usize> {
        self.functions
            .iter()
            .enumerate()
            .map(|(j, &key)| (key, j))
            .collect()
    }

    /// The force (N) the tool feels for an `indentation_m` of the patch it loads: `patch`
    /// holds the nodes under the tool and their shares of its load (summing to one). The cut
    /// patch compliance `C` (3 × 3) is the shares' mean displacement under each unit force;
    /// the force is `C⁻¹ δ`. `None` where the patch does not resist (held nothing).
    pub fn felt_force(
        &self,
        patch: &[(usize, f64)],
        indentation_m: Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        let nodes = self.model.mesh().node_count();
        let mut compliance = Matrix3::zeros();
        for axis in 0..3 {
            let mut loads = vec![0.0; 3 * nodes];
            for &(n, share) in patch {
                loads[3 * n + axis] += share;
            }
            let (nodes_m, _) = self.condensed(&loads);
            for &(n, share) in patch {
                let u = Vector3::from_column_slice(&nodes_m[3 * n..3 * n + 3]);
                compliance.set_column(axis, &(compliance.column(axis) + u * share));
            }
        }
        compliance
            .try_inverse()
            .map(|stiffness| stiffness * indentation_m)
    }

    /// Adds the functions of `enrichment` not yet in the state: their columns of `B`, their
    /// uncut responses, and their rows of `S`, bordering the factor.
    fn grow(&mut self, enrichment: &Enrichment) -> Result<(), CutError> {
        let known = self.function_index();
        let held = |n: usize| self.model.dofs().free_index[3 * n] == PRESCRIBED;
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
                    added.push((f.node, f.face));
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
        let mut z: Vec<Vec<f64>> = coupling.iter().map(|c| self.nodal(c)).collect();
        let mut flat: Vec<f64> = z.concat();
        self.response.respond(&mut flat, z.len());
        let full = 3 * self.model.mesh().node_count();
        for (r, column) in z.iter_mut().enumerate() {
            column.copy_from_slice(&flat[r * full..(r + 1) * full]);
        }
        // S's new columns: A − Bᵀ Z, against every unknown, old and new.
        let total = first_new + z.len();
        let mut columns = vec![vec![0.0; total]; z.len()];
        for (r, column) in columns.iter_mut().enumerate() {
            for (p, entry) in column.iter_mut().enumerate() {
                let b = if p < first_new {
                    &self.coupling[p]
                } else {
                    &coupling[p - first_new]
                };
                *entry = a.get(&(p, first_new + r)).copied().unwrap_or(0.0)
                    - b.iter().map(|&(d, v)| v * z[r][d]).sum::<f64>();
            }
        }
        self.border(&columns)?;
        self.functions.extend(added);
        self.coupling.extend(coupling);
        self.z.extend(z);
        Ok(())
    }

    /// A sparse column as a full nodal vector.
    fn nodal(&self, column: &[(usize, f64)]) -> Vec<f64> {
        let mut out = vec![0.0; 3 * self.model.mesh().node_count()];
        for &(d, v) in column {
            out[d] += v;
        }
        out
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
        let mesh = self.model.mesh();
        let nodes = mesh.node_count();
        let free = &self.model.dofs().free_index;
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
            let geometry = &self.model.geometry()[t];
            let (lambda, mu) = self.model.lame(t);
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

    /// Extends the lower factor `L` of `S` by the new columns `[C; D]` (each holding every
    /// row, old then new): `L X = C`, then `L_D L_Dᵀ = D − Xᵀ X`.
    fn border(&mut self, columns: &[Vec<f64>]) -> Result<(), CutError> {
        let old = self.factor.len();
        for (r, column) in columns.iter().enumerate() {
            let row_index = old + r;
            let mut row = vec![0.0; row_index + 1];
            for k in 0..row_index {
                let known: f64 = (0..k).map(|m| row[m] * self.factor[k][m]).sum();
                row[k] = (column[k] - known) / self.factor[k][k];
            }
            let diagonal = column[row_index] - row[..row_index].iter().map(|x| x * x).sum::<f64>();
            if !(diagonal.is_finite() && diagonal > 0.0) {
                self.factor.truncate(old);
                return Err(CutError::Solve(
                    "the condensed system lost positive definiteness".into(),
                ));
            }
            row[row_index] = diagonal.sqrt();
            self.factor.push(row);
        }
        Ok(())
    }

    /// `S⁻¹ rhs` through the factor.
    fn cholesky_solve(&self, mut x: Vec<f64>) -> Vec<f64> {
        let n = x.len();
        for i in 0..n {
            let s: f64 = (0..i).map(|k| self.factor[i][k] * x[k]).sum();
            x[i] = (x[i] - s) / self.factor[i][i];
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| self.factor[k][i] * x[k]).sum();
            x[i] = (x[i] - s) / self.factor[i][i];
        }
        x
    }
}
