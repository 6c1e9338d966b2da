//! A vademecum of tissue with a stiffer nodule: built on the heterogeneous model, it matches
//! full FEM of that model, the nodule is felt through the tool, and a vademecum of other
//! tissue is refused.

use nalgebra::Vector3;
use pgd_surgery::fem::{FemModel, Inclusion};
use pgd_surgery::pgd::{SurfacePoint, Vademecum, VademecumError};

use crate::common::{block_mesh, block_model, build_block};
use crate::convergence::assert_felt_force_exact;

/// Ten times as stiff, in the middle of the block, reaching its top face (z = 3 cm).
fn nodule() -> Inclusion {
    Inclusion {
        centre_m: [0.03, 0.02, 0.02],
        radius_m: 0.01,
        stiffness_ratio: 10.0,
    }
}

fn model_with_nodule() -> FemModel {
    block_model(block_mesh([6, 4, 3]))
        .with_inclusions(&[nodule()])
        .unwrap()
}

/// The centre of the surface triangle nearest `point_m`.
fn surface_point_near(vademecum: &Vademecum, point_m: Vector3<f64>) -> SurfacePoint {
    let centre = |t: &[u32; 3]| {
        t.iter()
            .map(|&p| Vector3::from(vademecum.position_coords_m[p as usize].map(f64::from)))
            .sum::<Vector3<f64>>()
            / 3.0
    };
    let triangle = (0..vademecum.triangles.len())
        .min_by(|&a, &b| {
            let distance = |t: usize| (centre(&vademecum.triangles[t]) - point_m).norm();
            distance(a).total_cmp(&distance(b))
        })
        .unwrap();
    SurfacePoint {
        triangle,
        barycentric: [1.0 / 3.0; 3],
    }
}

/// The model's heterogeneity is in the exact local responses as in the modes: the felt force
/// matches full FEM of the heterogeneous model to f32 storage (tolerance 1e-4, as for
/// homogeneous tissue).
#[test]
fn a_vademecum_with_a_nodule_matches_full_fem_of_the_heterogeneous_tissue() {
    let model = model_with_nodule();
    let vademecum = build_block(&model, 8);
    assert_eq!(vademecum.header.inclusions, vec![nodule()]);
    assert_felt_force_exact(&model, &vademecum);
}

/// Pressed 3 mm straight down, the surface over the nodule pushes back harder than the same
/// spot of plain tissue (more than 1.5 times; measured 2.7), and a corner far from it hardly
/// differs (within 10 %; measured 6.5 %).
#[test]
fn the_nodule_is_felt_over_it_and_not_far_from_it() {
    let with = build_block(&model_with_nodule(), 8);
    let without = build_block(&block_model(block_mesh([6, 4, 3])), 8);
    let press = Vector3::new(0.0, 0.0, -0.003);
    let felt = |vademecum: &Vademecum, at: Vector3<f64>| {
        let point = surface_point_near(vademecum, at);
        vademecum.force_for_indentation(&point, &press).norm()
    };
    let over = Vector3::new(0.03, 0.02, 0.03);
    let far = Vector3::new(0.005, 0.005, 0.03);
    let (over_ratio, far_ratio) = (
        felt(&with, over) / felt(&without, over),
        felt(&with, far) / felt(&without, far),
    );
    assert!(
        over_ratio > 1.5,
        "over the nodule: {over_ratio:.3} times plain tissue"
    );
    assert!((far_ratio - 1.0).abs() < 0.1, "far from it: {far_ratio:.3}");
}

#[test]
fn a_vademecum_of_plain_tissue_is_refused_for_tissue_with_a_nodule() {
    let model = block_model(block_mesh([6, 4, 3]));
    let vademecum = build_block(&model, 2);
    let file = std::path::Path::new("plain.vdm");
    let error = vademecum
        .check_material(file, model.material(), &[nodule()])
        .unwrap_err();
    assert!(
        matches!(error, VademecumError::OtherMaterial { .. })
            && error.to_string().contains("inclusions"),
        "{error}"
    );
    assert!(
        vademecum
            .check_material(file, model.material(), &[])
            .is_ok()
    );
}
