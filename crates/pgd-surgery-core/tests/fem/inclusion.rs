//! Heterogeneous tissue: an inclusion scales Young's modulus element by element. Checked
//! against a bar of two materials in series (exact for linear tetrahedra), and refused when
//! it holds no element.

use pgd_surgery_core::fem::{
    Dirichlet, FemError, FemModel, Inclusion, Law, Loads, Material, NewtonSettings,
};
use pgd_surgery_core::mesh::{TetMesh, box_mesh};

const LENGTH_M: f64 = 0.1;
const SIDE_M: f64 = 0.01;
const YOUNG_PA: f64 = 2.0e3;
const FORCE_N: f64 = 0.01;

/// A bar along x clamped at x = 0 and pulled along x at x = L by a uniform traction, with
/// Poisson's ratio 0: the stress is uniaxial and uniform, so each part stretches as a spring
/// and linear elements are exact wherever the material changes on a node plane.
fn bar() -> (TetMesh, Dirichlet, Loads, Vec<usize>) {
    let mesh = box_mesh([LENGTH_M, SIDE_M, SIDE_M], [10, 2, 2]).unwrap();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("x0").unwrap()).unwrap();
    let mut loads = Loads::new(mesh.node_count());
    let traction = FORCE_N / (SIDE_M * SIDE_M);
    loads
        .add_traction(&mesh, mesh.face_set("x1").unwrap(), [traction, 0.0, 0.0])
        .unwrap();
    let tip = mesh.node_set("x1").unwrap().to_vec();
    (mesh, dirichlet, loads, tip)
}

fn tip_stretch_m(inclusions: &[Inclusion]) -> f64 {
    let (mesh, dirichlet, loads, tip) = bar();
    let material = Material::new(Law::Linear, YOUNG_PA, 0.0, 1000.0).unwrap();
    let model = FemModel::new(mesh, material, dirichlet)
        .unwrap()
        .with_inclusions(inclusions)
        .unwrap();
    let solution = model
        .solve_static(&loads, &NewtonSettings::default())
        .unwrap();
    tip.iter().map(|&n| solution.node(n)[0]).sum::<f64>() / tip.len() as f64
}

/// A sphere so large that, across the bar's 1 cm section, its surface is the plane x = L/2
/// within 0.3 µm: the far half of the bar is `ratio` times as stiff.
fn far_half(ratio: f64) -> Inclusion {
    let radius_m = 50.0;
    Inclusion {
        centre_m: [LENGTH_M / 2.0 + radius_m, SIDE_M / 2.0, SIDE_M / 2.0],
        radius_m,
        stiffness_ratio: ratio,
    }
}

/// Two springs in series: `F L₁ / (E₁ A) + F L₂ / (E₂ A)`. Tolerance 1e-9 (round-off).
#[test]
fn a_bar_half_stiffer_stretches_as_two_springs_in_series() {
    let ratio = 5.0;
    let area = SIDE_M * SIDE_M;
    let half = LENGTH_M / 2.0;
    let expected = FORCE_N * half / (YOUNG_PA * area) + FORCE_N * half / (ratio * YOUNG_PA * area);
    let found = tip_stretch_m(&[far_half(ratio)]);
    assert!(
        (found - expected).abs() < 1e-9 * expected,
        "stretch {found:e} m, springs in series {expected:e} m"
    );
    let homogeneous = FORCE_N * LENGTH_M / (YOUNG_PA * area);
    let plain = tip_stretch_m(&[]);
    assert!(
        (plain - homogeneous).abs() < 1e-9 * homogeneous,
        "{plain:e}"
    );
}

#[test]
fn an_inclusion_that_holds_no_element_is_refused() {
    let (mesh, dirichlet, ..) = bar();
    let model = FemModel::new(mesh, Material::liver(Law::Linear), dirichlet).unwrap();
    let outside = Inclusion {
        centre_m: [1.0, 1.0, 1.0],
        radius_m: 0.01,
        stiffness_ratio: 5.0,
    };
    let error = model.with_inclusions(&[outside]).err().unwrap();
    assert!(
        matches!(error, FemError::InvalidInput { .. })
            && error.to_string().contains("outside the organ"),
        "{error}"
    );
    let (mesh, dirichlet, ..) = bar();
    let model = FemModel::new(mesh, Material::liver(Law::Linear), dirichlet).unwrap();
    let limp = Inclusion {
        stiffness_ratio: f64::NAN,
        ..far_half(1.0)
    };
    let error = model.with_inclusions(&[limp]).err().unwrap();
    assert!(error.to_string().contains("stiffness ratio"), "{error}");
}
