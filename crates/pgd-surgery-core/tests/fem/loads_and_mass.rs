//! Loads and masses against conservation: total force, total mass, closed-surface pressure.

use nalgebra::{Point3, Vector3};
use pgd_surgery_core::fem::{
    Dirichlet, DofMap, FreePattern, Loads, TetGeometry, consistent_mass, lumped_mass,
};
use pgd_surgery_core::mesh::{Surface, box_mesh};

const SIZE: [f64; 3] = [0.08, 0.05, 0.03];

#[test]
fn masses_sum_to_density_times_volume() {
    let mesh = box_mesh(SIZE, [6, 4, 3]).unwrap();
    let geometry = TetGeometry::of_mesh(&mesh);
    let rho = 1060.0;
    let expected = rho * SIZE.iter().product::<f64>();
    let lumped: f64 = lumped_mass(mesh.tets(), &geometry, mesh.node_count(), rho)
        .iter()
        .sum();
    assert!(
        (lumped - expected).abs() < 1e-12 * expected,
        "lumped {lumped} vs {expected}"
    );

    // A rigid translation t along x: tᵀ M t is the total mass, for the consistent matrix too.
    let dofs = DofMap::new(&Dirichlet::new(mesh.node_count()));
    let pattern = FreePattern::new(&mesh, &dofs);
    let values = consistent_mass(&pattern, &geometry, rho);
    let t: Vec<f64> = (0..3 * mesh.node_count())
        .map(|d| if d % 3 == 0 { 1.0 } else { 0.0 })
        .collect();
    let mut mt = vec![0.0; t.len()];
    pattern.mul(&values, &t, &mut mt);
    let total: f64 = t.iter().zip(&mt).map(|(a, b)| a * b).sum();
    assert!(
        (total - expected).abs() < 1e-12 * expected,
        "consistent {total} vs {expected}"
    );
}

#[test]
fn pressure_on_a_closed_surface_has_no_resultant_and_the_right_magnitude_per_face() {
    let mesh = box_mesh(SIZE, [4, 3, 2]).unwrap();
    let surface = Surface::extract(&mesh);
    let p = 466.6; // the gallbladder's bile pressure (Pa)
    let mut closed = Loads::new(mesh.node_count());
    closed.add_pressure(&mesh, &surface.triangles, p).unwrap();
    let resultant = closed.total_force_n().norm();
    assert!(
        resultant < 1e-12 * p * surface.area(&mesh),
        "closed-surface resultant {resultant} N"
    );

    let mut top = Loads::new(mesh.node_count());
    top.add_pressure(&mesh, mesh.face_set("z1").unwrap(), p)
        .unwrap();
    let expected = Vector3::new(0.0, 0.0, -p * SIZE[0] * SIZE[1]);
    assert!((top.total_force_n() - expected).norm() < 1e-12 * expected.norm());
}

#[test]
fn a_regularized_point_load_keeps_its_total_and_stays_local() {
    let mesh = box_mesh(SIZE, [16, 10, 6]).unwrap();
    let surface = Surface::extract(&mesh);
    let point = Point3::new(0.031, 0.022, SIZE[2]);
    let force = [0.1, -0.2, -0.5];
    let radius = 0.012;
    let mut loads = Loads::new(mesh.node_count());
    loads
        .add_point_load(&mesh, &surface, point, Vector3::z(), force, radius)
        .unwrap();
    assert!((loads.total_force_n() - Vector3::from(force)).norm() < 1e-14);
    // Only nodes within the radius carry load, and their load-weighted centroid is the point.
    let mut centroid = Vector3::zeros();
    let mut weight = 0.0;
    for n in 0..mesh.node_count() {
        let f = Vector3::new(
            loads.as_slice()[3 * n],
            loads.as_slice()[3 * n + 1],
            loads.as_slice()[3 * n + 2],
        );
        if f.norm() > 0.0 {
            let d = (mesh.nodes()[n] - point).norm();
            assert!(
                d < radius,
                "node {n} at {d} m carries load outside the radius"
            );
            let w = f.norm() / Vector3::from(force).norm();
            centroid += mesh.nodes()[n].coords * w;
            weight += w;
        }
    }
    let centroid = centroid / weight;
    assert!(
        (centroid - point.coords).norm() < 0.1 * radius,
        "load centroid {centroid:?} far from {point:?}"
    );
}

/// A 12 mm patch on a 3 mm wall reaches the far face in distance, but the tool presses only
/// the face it touches: no share on the bottom face, and the whole force on the top one.
#[test]
fn a_point_load_on_a_thin_wall_loads_only_the_pressed_face() {
    let wall = [0.06, 0.05, 0.003];
    let mesh = box_mesh(wall, [12, 10, 1]).unwrap();
    let surface = Surface::extract(&mesh);
    let force = [0.0, 0.0, -0.3];
    let mut loads = Loads::new(mesh.node_count());
    loads
        .add_point_load(
            &mesh,
            &surface,
            Point3::new(0.03, 0.025, wall[2]),
            Vector3::z(),
            force,
            0.012,
        )
        .unwrap();
    let on_face = |z: f64| -> f64 {
        (0..mesh.node_count())
            .filter(|&n| (mesh.nodes()[n].z - z).abs() < 1e-9)
            .map(|n| loads.as_slice()[3 * n + 2])
            .sum()
    };
    assert_eq!(on_face(0.0), 0.0, "the far face carries load");
    assert!((on_face(wall[2]) - force[2]).abs() < 1e-14);
}
