//! Patch test: a homogeneous deformation must be reproduced exactly (to round-off) by linear
//! tetrahedra, with a distorted interior node, for both material laws.

use nalgebra::{Matrix3, Point3, Vector3};
use pgd_surgery_core::fem::{Dirichlet, FemModel, Law, Loads, Material, NewtonSettings};
use pgd_surgery_core::mesh::{TetMesh, box_mesh};

/// A 2×2×2-cube mesh of the unit cube whose single interior node is moved off-centre, so the
/// test does not rely on a symmetric mesh.
fn distorted_cube() -> (TetMesh, usize) {
    let regular = box_mesh([1.0, 1.0, 1.0], [2, 2, 2]).unwrap();
    let centre = regular
        .nodes()
        .iter()
        .position(|p| (p - Point3::new(0.5, 0.5, 0.5)).norm() < 1e-12)
        .unwrap();
    let mut nodes = regular.nodes().to_vec();
    nodes[centre] = Point3::new(0.58, 0.44, 0.61);
    let mesh = TetMesh::new(
        "distorted cube",
        nodes,
        regular.tets().to_vec(),
        Default::default(),
    )
    .unwrap();
    (mesh, centre)
}

fn check_patch(law: Law, gradient: Matrix3<f64>, settings: NewtonSettings) {
    let (mesh, centre) = distorted_cube();
    let offset = Vector3::new(1e-3, -2e-3, 0.5e-3);
    let field = |p: &Point3<f64>| gradient * p.coords + offset;
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    for n in (0..mesh.node_count()).filter(|&n| n != centre) {
        dirichlet
            .prescribe(n, field(&mesh.nodes()[n]).into())
            .unwrap();
    }
    let expected = field(&mesh.nodes()[centre]);
    let material = Material::new(law, 2.0e3, 0.45, 1000.0).unwrap();
    let model = FemModel::new(mesh, material, dirichlet).unwrap();
    let solution = model
        .solve_static(&Loads::new(model.mesh().node_count()), &settings)
        .unwrap();
    let got = Vector3::from(solution.node(centre));
    let error = (got - expected).norm() / expected.norm();
    assert!(
        error < 1e-12,
        "{law:?}: interior node off the linear field by {error:e} (relative)"
    );
}

#[test]
fn linear_elasticity_reproduces_a_linear_field() {
    let gradient = Matrix3::new(1e-3, 2e-4, -3e-4, 5e-4, -2e-3, 1e-4, 0.0, 7e-4, 1.5e-3);
    check_patch(Law::Linear, gradient, NewtonSettings::default());
}

#[test]
fn ksv_reproduces_a_finite_homogeneous_deformation() {
    // 10–20 % strains and a rotation: far outside the linear regime, yet F is constant.
    let gradient = Matrix3::new(0.15, 0.10, -0.05, -0.08, -0.12, 0.06, 0.04, 0.09, 0.20);
    let settings = NewtonSettings {
        load_steps: 3,
        relative_tolerance: 1e-13,
        ..NewtonSettings::default()
    };
    check_patch(Law::KirchhoffSaintVenant, gradient, settings);
}
