//! The compressible neo-Hookean law and its exponentially stiffening sibling against exact
//! homogeneous solutions (uniaxial stretch and compression, simple shear), their tangents
//! against finite differences and their nonlinear force against the full one.

use nalgebra::Matrix3;
use pgd_surgery_core::fem::{
    Dirichlet, FemModel, Law, Loads, Material, NewtonSettings, PRESCRIBED,
};
use pgd_surgery_core::mesh::{TetMesh, box_mesh};

use crate::beams::cantilever;
use crate::ksv::tangent_error;

const SIDE_M: f64 = 0.02;
const YOUNG_PA: f64 = 4.0e3;
const POISSON: f64 = 0.45;

/// The exponential law's exponent in these tests: at 40 % uniaxial compression its end
/// force is 2.6 times the neo-Hookean one.
const STIFFENING: f64 = 2.0;

/// The law with exponent `b`: neo-Hookean for 0, exponential otherwise.
fn material(b: f64) -> Material {
    let law = if b == 0.0 {
        Law::NeoHookean
    } else {
        Law::Exponential
    };
    Material::new(law, YOUNG_PA, POISSON, 1000.0)
        .and_then(|m| m.with_stiffening(b))
        .unwrap()
}

fn lame() -> (f64, f64) {
    let mu = YOUNG_PA / (2.0 * (1.0 + POISSON));
    let lambda = YOUNG_PA * POISSON / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON));
    (lambda, mu)
}

/// `P = μ e^{b x} (F − F⁻ᵀ) + λ ln J F⁻ᵀ`, `x = tr(FᵀF) − 3 − 2 ln J`, written out
/// independently of the element code.
fn first_piola(f: &Matrix3<f64>, b: f64) -> Matrix3<f64> {
    let (lambda, mu) = lame();
    let inverse_t = f.try_inverse().unwrap().transpose();
    let log_j = f.determinant().ln();
    let x = (f.transpose() * f).trace() - 3.0 - 2.0 * log_j;
    (f - inverse_t) * (mu * (b * x).exp()) + inverse_t * (lambda * log_j)
}

fn cube() -> TetMesh {
    box_mesh([SIDE_M; 3], [3, 3, 3]).unwrap()
}

fn solve(
    mesh: TetMesh,
    dirichlet: Dirichlet,
    material: Material,
    load_steps: usize,
) -> (FemModel, Vec<f64>) {
    let model = FemModel::new(mesh, material, dirichlet).unwrap();
    let settings = NewtonSettings {
        load_steps,
        relative_tolerance: 1e-12,
        ..NewtonSettings::default()
    };
    let loads = Loads::new(model.mesh().node_count());
    let u = model
        .solve_static(&loads, &settings)
        .unwrap()
        .displacement_m;
    (model, u)
}

/// Sum of the internal forces over a set of nodes: the reaction the constraints there carry.
fn reaction(model: &FemModel, u: &[f64], nodes: &[usize]) -> [f64; 3] {
    let force = model.internal_force(u);
    [0, 1, 2].map(|c| nodes.iter().map(|&n| force[3 * n + c]).sum())
}

/// The lateral stretch that leaves the sides of a bar stretched by `axial` free of stress:
/// `μ e^{b x} (t − 1/t) + λ ln(axial t²) / t = 0` with `x = axial² + 2t² − 3 − 2 ln(axial t²)`,
/// by bisection (the left side increases with t).
fn lateral_stretch(axial: f64, b: f64) -> f64 {
    let (lambda, mu) = lame();
    let stress = |t: f64| {
        let log_j = (axial * t * t).ln();
        let x = axial * axial + 2.0 * t * t - 3.0 - 2.0 * log_j;
        mu * (b * x).exp() * (t - 1.0 / t) + lambda * log_j / t
    };
    let (mut low, mut high) = (0.2, 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if stress(mid) > 0.0 {
            high = mid;
        } else {
            low = mid;
        }
    }
    0.5 * (low + high)
}

/// A cube of `material` on rollers at x = 0, y = 0, z = 0, its face x = L moved to stretch it
/// by `axial`: the model, its displacement, and the nodes of the moved face.
pub fn stretched_cube(material: Material, axial: f64) -> (FemModel, Vec<f64>, Vec<usize>) {
    let mesh = cube();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    for (axis, side) in ["x0", "y0", "z0"].into_iter().enumerate() {
        for &n in mesh.node_set(side).unwrap() {
            dirichlet.prescribe_component(n, axis, 0.0).unwrap();
        }
    }
    let pulled = mesh.node_set("x1").unwrap().to_vec();
    for &n in &pulled {
        dirichlet
            .prescribe_component(n, 0, (axial - 1.0) * SIDE_M)
            .unwrap();
    }
    let (model, u) = solve(mesh, dirichlet, material, 4);
    (model, u, pulled)
}

/// The nominal stress (Pa) on the moved face of [`stretched_cube`].
pub fn end_stress_pa(material: Material, axial: f64) -> f64 {
    let (model, u, pulled) = stretched_cube(material, axial);
    reaction(&model, &u, &pulled)[0] / (SIDE_M * SIDE_M)
}

/// The stretched cube against the exact homogeneous solution.
fn uniaxial(axial: f64, b: f64) {
    let (model, u, pulled) = stretched_cube(material(b), axial);
    let lateral = lateral_stretch(axial, b);
    let mut worst: f64 = 0.0;
    for (n, x) in model.mesh().nodes().iter().enumerate() {
        let exact = [
            (axial - 1.0) * x[0],
            (lateral - 1.0) * x[1],
            (lateral - 1.0) * x[2],
        ];
        for c in 0..3 {
            worst = worst.max((u[3 * n + c] - exact[c]).abs());
        }
    }
    let stretch = (lateral - 1.0).abs().max((axial - 1.0).abs()) * SIDE_M;
    assert!(
        worst <= 1e-9 * stretch,
        "stretch {axial}: displacement off the exact field by {worst:e} m"
    );
    let f = Matrix3::from_diagonal(&nalgebra::Vector3::new(axial, lateral, lateral));
    let exact_force = first_piola(&f, b)[(0, 0)] * SIDE_M * SIDE_M;
    let force = reaction(&model, &u, &pulled)[0];
    assert!(
        (force - exact_force).abs() <= 1e-8 * exact_force.abs(),
        "stretch {axial}: end force {force} N, exact {exact_force} N"
    );
}

#[test]
fn uniaxial_stretch_matches_the_exact_homogeneous_solution() {
    uniaxial(1.3, 0.0);
    uniaxial(1.3, STIFFENING);
}

#[test]
fn uniaxial_compression_to_sixty_percent_matches_the_exact_solution() {
    uniaxial(0.6, 0.0);
    uniaxial(0.6, STIFFENING);
}

#[test]
fn simple_shear_matches_the_exact_homogeneous_solution() {
    simple_shear(0.0);
    simple_shear(STIFFENING);
}

fn simple_shear(b: f64) {
    let gamma = 0.4;
    let mesh = cube();
    let surface: Vec<usize> = (0..mesh.node_count())
        .filter(|&n| {
            let x = mesh.nodes()[n];
            (0..3).any(|c| x[c].abs() < 1e-12 || (x[c] - SIDE_M).abs() < 1e-12)
        })
        .collect();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    for &n in &surface {
        let y = mesh.nodes()[n][1];
        dirichlet.prescribe(n, [gamma * y, 0.0, 0.0]).unwrap();
    }
    let top = mesh.node_set("y1").unwrap().to_vec();
    let (model, u) = solve(mesh, dirichlet, material(b), 2);

    for (n, x) in model.mesh().nodes().iter().enumerate() {
        let error = (u[3 * n] - gamma * x[1]).abs() + u[3 * n + 1].abs() + u[3 * n + 2].abs();
        assert!(
            error <= 1e-12,
            "node {n} off the affine shear by {error:e} m"
        );
    }
    // With J = 1, P e_y = (μ'γ, 0, 0): the top carries a shear force μ'γL² and no normal force.
    let f = Matrix3::new(1.0, gamma, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let exact = first_piola(&f, b) * nalgebra::Vector3::y() * SIDE_M * SIDE_M;
    let force = reaction(&model, &u, &top);
    let (_, mu) = lame();
    for c in 0..3 {
        assert!(
            (force[c] - exact[c]).abs() <= 1e-9 * mu * gamma * SIDE_M * SIDE_M,
            "top reaction {force:?} N, exact {exact:?} N"
        );
    }
}

#[test]
fn neo_hookean_tangent_matches_finite_differences() {
    let beam = cantilever(1, Law::NeoHookean, 0.45, 0.0);
    let error = tangent_error(&beam.model, 1e-3);
    assert!(error < 1e-7, "tangent vs central differences: {error:e}");
}

/// At displacements of 1 mm per node on 3 mm cells the strain invariant x reaches about 0.1,
/// where the growth of the shear modulus is a third of the tangent.
#[test]
fn exponential_tangent_matches_finite_differences() {
    let beam = cantilever(1, Law::Exponential, 0.45, 0.0);
    let error = tangent_error(&beam.model, 1e-3);
    assert!(error < 1e-7, "tangent vs central differences: {error:e}");
}

/// The nonlinear force the vademecum build moves to the right-hand side is the internal force
/// less the rest stiffness times the displacement, assembled independently.
#[test]
fn nonlinear_force_is_the_internal_force_less_the_rest_stiffness() {
    for law in [Law::NeoHookean, Law::Exponential] {
        let model = cantilever(1, law, 0.45, 0.0).model;
        let dofs = model.dofs();
        let u: Vec<f64> = (0..3 * model.mesh().node_count())
            .map(|d| match dofs.free_index[d] {
                PRESCRIBED => 0.0,
                _ => 1e-3 * ((d as f64 * 0.7).sin()),
            })
            .collect();
        let mut nonlinear = vec![0.0; u.len()];
        model.add_nonlinear_force(&u, &mut nonlinear);
        let rest = model.rest_stiffness();
        let mut k0u = vec![0.0; dofs.free_count()];
        model.pattern().mul(&rest, &dofs.restrict(&u), &mut k0u);
        let full = dofs.restrict(&model.internal_force(&u));
        let expected: Vec<f64> = full.iter().zip(&k0u).map(|(f, k)| f - k).collect();
        let got = dofs.restrict(&nonlinear);
        let scale = expected.iter().map(|v| v * v).sum::<f64>().sqrt();
        let error = got
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        assert!(
            error <= 1e-9 * scale,
            "{}: nonlinear force off by {error:e} of {scale:e} N",
            law.name()
        );
    }
}
