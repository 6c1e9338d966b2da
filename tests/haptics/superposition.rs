//! Several loads on one organ superpose through the vademecum: the deformation state's field
//! for two loads is the sum of the two single-load fields.

use nalgebra::Vector3;
use pgd_surgery::pgd::{Deformation, PatchLoad, SurfacePoint};

use crate::common::liver;

#[test]
fn two_loads_on_one_organ_superpose() {
    let vademecum = &liver().vademecum;
    let points = [(10, [0.2, 0.3, 0.5]), (200, [0.6, 0.2, 0.2])].map(|(triangle, barycentric)| {
        SurfacePoint {
            triangle,
            barycentric,
        }
    });
    let forces = [Vector3::new(0.0, -0.2, 0.05), Vector3::new(0.1, 0.0, -0.15)];
    let mut deformation = Deformation::new(vademecum, 2);
    for ((load, at), force) in deformation.loads.iter_mut().zip(&points).zip(&forces) {
        *load = PatchLoad {
            shares: vademecum.patch(at).shares,
            force_n: *force,
        };
    }
    deformation.evaluate(vademecum);
    let mut both = vec![0.0; vademecum.dof_count()];
    deformation.field_into(vademecum, &mut both);
    let first = vademecum.field(&points[0], &forces[0]);
    let second = vademecum.field(&points[1], &forces[1]);
    let sum: Vec<f64> = first.iter().zip(&second).map(|(a, b)| a + b).collect();
    let norm = sum.iter().map(|v| v * v).sum::<f64>().sqrt();
    let error = both
        .iter()
        .zip(&sum)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
        / norm;
    assert!(norm > 1e-3, "the loads should move the liver: {norm}");
    assert!(error < 1e-12, "superposition off by {error}");
    assert!((deformation.total_force_n() - forces[0] - forces[1]).norm() < 1e-15);
}
