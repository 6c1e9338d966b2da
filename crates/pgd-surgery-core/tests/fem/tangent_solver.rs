//! Newton with its directions from conjugate gradients preconditioned by the rest stiffness's
//! factor reaches the equilibrium that Newton with a factorized tangent reaches, through an
//! indefinite tangent too, and it does so without factorizing any tangent.

use pgd_surgery_core::fem::{
    DirectSolver, Dirichlet, Factorization, FemModel, Law, Loads, Material, NewtonSettings,
    TangentSolver,
};
use pgd_surgery_core::mesh::box_mesh;

/// A 6 × 4 × 3 cm block of exponential tissue (b = 2) clamped at its base, one node of its top
/// face pushed down by `force_n`.
fn pressed_block(force_n: f64) -> (FemModel, Loads) {
    let mesh = box_mesh([0.06, 0.04, 0.03], [6, 4, 3]).unwrap();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("z0").unwrap()).unwrap();
    let top = mesh
        .node_set("z1")
        .unwrap()
        .iter()
        .copied()
        .min_by(|&a, &b| {
            let centre = |n: usize| {
                let p = mesh.nodes()[n];
                (p.x - 0.03).powi(2) + (p.y - 0.02).powi(2)
            };
            centre(a).total_cmp(&centre(b))
        })
        .unwrap();
    let material = Material::new(Law::Exponential, 3.0e3, 0.45, 1000.0)
        .and_then(|m| m.with_stiffening(2.0))
        .unwrap();
    let model = FemModel::new(mesh, material, dirichlet).unwrap();
    let mut loads = Loads::new(model.mesh().node_count());
    loads.add_nodal_force(top, [0.0, 0.0, -force_n]).unwrap();
    (model, loads)
}

fn relative(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm).sqrt()
}

/// Newton to 1e-11 of the load, in four load steps.
fn tight() -> NewtonSettings {
    NewtonSettings {
        load_steps: 4,
        relative_tolerance: 1e-11,
        ..NewtonSettings::default()
    }
}

fn rest_factor(model: &FemModel) -> Factorization {
    let rest = model.pattern().matrix(model.rest_stiffness());
    DirectSolver::new(model.pattern())
        .unwrap()
        .cholesky(&rest)
        .unwrap()
}

/// The same equilibrium to 1e-8 (both Newton solves converge to 1e-11 of the load), deep in
/// the exponential law's stiffening: the pushed node moves by more than a third of the
/// block's thickness.
#[test]
fn preconditioned_newton_reaches_the_direct_equilibrium() {
    let (model, loads) = pressed_block(1.5);
    let direct = model.solve_static(&loads, &tight()).unwrap();
    let factor = rest_factor(&model);
    let mut solver = TangentSolver::preconditioned(model.pattern(), &factor);
    let krylov = model
        .solve_static_with(&mut solver, &loads, &tight())
        .unwrap();
    let deepest = direct
        .displacement_m
        .iter()
        .fold(0.0f64, |m, u| m.max(u.abs()));
    let statistics = solver.statistics();
    let error = relative(&krylov.displacement_m, &direct.displacement_m);
    eprintln!("deepest {deepest:.4} m, error {error:.1e}, {statistics:?}");
    assert!(deepest > 0.01, "not deep enough to test: {deepest} m");
    assert!(error < 1e-8, "{error}");
    assert!(statistics.directions > 0, "{statistics:?}");
    assert_eq!(statistics.factorizations, 0, "{statistics:?}");
}

/// Started from the equilibrium turned the other way (the node pulled up as far as it is
/// pushed down), the first tangent is indefinite: conjugate gradients stop at negative
/// curvature, Newton takes the descent direction they reached, and it still lands on the
/// direct solve's equilibrium (1e-8) without factorizing a tangent.
#[test]
fn an_indefinite_tangent_gives_a_truncated_direction_and_newton_still_converges() {
    let (model, loads) = pressed_block(1.5);
    let direct = model.solve_static(&loads, &tight()).unwrap();
    let factor = rest_factor(&model);
    let mut solver = TangentSolver::preconditioned(model.pattern(), &factor);
    let reversed = direct.displacement_m.iter().map(|u| -u).collect();
    let one_step = NewtonSettings {
        load_steps: 1,
        ..tight()
    };
    let krylov = model
        .solve_static_from(reversed, &loads, &one_step, &mut solver)
        .unwrap();
    let statistics = solver.statistics();
    let error = relative(&krylov.displacement_m, &direct.displacement_m);
    eprintln!("error {error:.1e}, {statistics:?}");
    assert!(statistics.truncated > 0, "{statistics:?}");
    assert!(error < 1e-8, "{error}");
    assert_eq!(statistics.factorizations, 0, "{statistics:?}");
}
