//! The FEM benchmark: assembly, factorization and solve on a mesh of the papers' liver size.
//!
//! Figures are medians over repeats, each also given as a ratio to a sparse matrix–vector
//! product with the same stiffness matrix, measured in the same run: the ratios carry over
//! between machines, the milliseconds do not.

use std::time::Instant;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use crate::fem::{DirectSolver, Dirichlet, FemError, FemModel, FreePattern, Law, Loads, Material};
use crate::mesh::{Surface, box_mesh};

/// Cubes along x, y, z: 26 × 14 × 12 = 4,368 nodes and 21,450 tetrahedra, the size of the
/// liver mesh of paper 000 (4,349 nodes, 21,788 tets).
pub const LIVER_SIZED_CELLS: [usize; 3] = [25, 13, 11];

#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    pub name: &'static str,
    pub median_ms: f64,
    /// `median_ms` divided by the baseline's median.
    pub ratio_to_baseline: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FemBenchReport {
    pub nodes: usize,
    pub tets: usize,
    pub free_dofs: usize,
    pub stiffness_nonzeros: usize,
    /// Entries of the neo-Hookean stiffness, whose nodal volumes reach two rings.
    pub two_ring_nonzeros: usize,
    pub repeats: usize,
    pub baseline: &'static str,
    pub timings: Vec<Timing>,
}

/// Runs every measurement `repeats` times on a box of liver size and extent, clamped on one
/// face, and reports medians.
pub fn run(cells: [usize; 3], repeats: usize) -> Result<FemBenchReport, FemError> {
    let repeats = repeats.max(1);
    let mesh = box_mesh([0.18, 0.10, 0.08], cells)?;
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("y1")?)?;
    let model = FemModel::new(mesh, Material::liver(Law::KirchhoffSaintVenant), dirichlet)?;
    let linear = FemModel::new(
        model.mesh().clone(),
        Material::liver(Law::Linear),
        model.dirichlet().clone(),
    )?;
    let neo_hookean = FemModel::new(
        model.mesh().clone(),
        Material::liver(Law::NeoHookean),
        model.dirichlet().clone(),
    )?;
    let loads = indentation_load(&model)?;
    let u = linear_displacement(&linear, &loads)?;
    let two_ring = neo_hookean.pattern().matrix(neo_hookean.rest_stiffness());
    let two_ring_solver = DirectSolver::new(neo_hookean.pattern())?;

    let stiffness = linear.rest_stiffness();
    let matrix = model.pattern().matrix(stiffness.clone());
    let solver = DirectSolver::new(model.pattern())?;
    let factor = solver.cholesky(&matrix)?;
    let rhs = model.dofs().restrict(loads.as_slice());
    let mut y = vec![0.0; rhs.len()];

    // The first row is the baseline every ratio refers to.
    let mut medians: Vec<(&'static str, f64)> = Vec::new();
    let mut time =
        |name: &'static str, f: &mut dyn FnMut()| medians.push((name, median_ms(repeats, f)));
    time("sparse mat-vec (baseline)", &mut || {
        model.pattern().mul(&stiffness, &rhs, &mut y)
    });
    time("pattern + scatter map", &mut || {
        FreePattern::new(model.mesh(), model.dofs());
    });
    time("assemble linear stiffness", &mut || {
        linear.force_and_tangent(&u);
    });
    time("assemble KSV force + tangent", &mut || {
        model.force_and_tangent(&u);
    });
    time("assemble neo-Hookean (nodal volumes)", &mut || {
        neo_hookean.force_and_tangent(&u);
    });
    let mut nonlinear = vec![0.0; u.len()];
    time("neo-Hookean internal force", &mut || {
        neo_hookean.internal_force(&u);
    });
    time("neo-Hookean nonlinear force (secant step)", &mut || {
        nonlinear.fill(0.0);
        neo_hookean.add_nonlinear_force(&u, &mut nonlinear);
    });
    time("symbolic Cholesky (AMD)", &mut || {
        DirectSolver::new(model.pattern()).expect("analysed above");
    });
    time("numeric Cholesky", &mut || {
        solver.cholesky(&matrix).expect("factorized above");
    });
    time("triangular solves", &mut || {
        let mut x = rhs.clone();
        factor.solve_in_place(&mut x);
    });
    time("numeric Cholesky, two-ring pattern", &mut || {
        two_ring_solver
            .cholesky(&two_ring)
            .expect("the rest stiffness is positive definite");
    });
    let baseline = medians[0].1;
    let timings = medians
        .into_iter()
        .map(|(name, median_ms)| Timing {
            name,
            median_ms,
            ratio_to_baseline: median_ms / baseline,
        })
        .collect();
    Ok(FemBenchReport {
        nodes: model.mesh().node_count(),
        tets: model.mesh().tet_count(),
        free_dofs: model.dofs().free_count(),
        stiffness_nonzeros: model.pattern().nnz(),
        two_ring_nonzeros: neo_hookean.pattern().nnz(),
        repeats,
        baseline: "sparse mat-vec",
        timings,
    })
}

/// A 0.1 N indentation spread over 1.5 cm of the top face: a typical tool press.
fn indentation_load(model: &FemModel) -> Result<Loads, FemError> {
    let mesh = model.mesh();
    let surface = Surface::extract(mesh);
    let mut loads = Loads::new(mesh.node_count());
    loads.add_point_load(
        mesh,
        &surface,
        Point3::new(0.09, 0.05, 0.08),
        Vector3::z(),
        [0.0, 0.0, -0.1],
        0.015,
    )?;
    Ok(loads)
}

fn linear_displacement(model: &FemModel, loads: &Loads) -> Result<Vec<f64>, FemError> {
    Ok(model
        .solve_static(loads, &Default::default())?
        .displacement_m)
}

pub fn median_ms(repeats: usize, f: &mut dyn FnMut()) -> f64 {
    median(
        (0..repeats)
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed().as_secs_f64() * 1e3
            })
            .collect(),
    )
}

/// The middle sample (the upper of the two middle ones for an even count).
/// The `q`-quantile of `samples`.
pub(crate) fn quantile(samples: &[f64], q: f64) -> f64 {
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[((q * (sorted.len() - 1) as f64).round() as usize).min(sorted.len() - 1)]
}

pub(crate) fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

impl std::fmt::Display for FemBenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "FEM benchmark: {} nodes, {} tets, {} free dofs, {} stiffness nonzeros ({} with nodal \
             volumes); medians of {} runs",
            self.nodes,
            self.tets,
            self.free_dofs,
            self.stiffness_nonzeros,
            self.two_ring_nonzeros,
            self.repeats
        )?;
        writeln!(
            f,
            "{:<38} {:>12} {:>14}",
            "step", "median (ms)", "× mat-vec"
        )?;
        for t in &self.timings {
            writeln!(
                f,
                "{:<38} {:>12.3} {:>14.1}",
                t.name, t.median_ms, t.ratio_to_baseline
            )?;
        }
        Ok(())
    }
}
