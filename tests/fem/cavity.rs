//! A closed cavity of fluid: its volume against exact volumes, its force and tangent against
//! finite differences, the net force of the fluid on the wall against zero, and a hollow
//! sphere of linear solid around a fluid under outer pressure against Lamé's solution.

use nalgebra::Point3;
use pgd_surgery::fem::{
    Cavity, Dirichlet, FemError, FemModel, Law, Loads, Material, NewtonSettings,
};
use pgd_surgery::mesh::{Surface, TetMesh, box_mesh, extrude, revolution};

/// A hollow sphere of inner radius `inner_m` and outer radius `outer_m`, its wall `layers`
/// elements thick, and its inner and outer boundary triangles (as `Surface::extract` orders
/// them: facing out of the solid, so the inner ones face into the cavity).
fn hollow_sphere(
    (inner_m, outer_m): (f64, f64),
    segments: usize,
    layers: usize,
) -> (TetMesh, Vec<[usize; 3]>, Vec<[usize; 3]>) {
    let mid = 0.5 * (inner_m + outer_m);
    let radius = move |t: f64| 2.0 * mid * (t * (1.0 - t)).max(0.0).sqrt();
    let surface = revolution(
        Point3::new(0.0, 0.0, -mid),
        Point3::new(0.0, 0.0, mid),
        &radius,
        segments / 2,
        segments,
    );
    let per_layer = surface.points.len();
    let mesh = extrude("hollow sphere", &surface, outer_m - inner_m, layers).unwrap();
    let boundary = Surface::extract(&mesh).triangles;
    let (inner, outer) = boundary
        .into_iter()
        .partition(|face| face.iter().all(|&n| n < per_layer));
    (mesh, inner, outer)
}

/// Holds a free body against its six rigid motions and nothing else (3-2-1): the outer pole
/// nodes and one node on the equator, so a self-equilibrated load meets no reaction.
fn held_321(mesh: &TetMesh) -> Dirichlet {
    let nearest = |target: [f64; 3]| {
        let distance = |n: usize| (mesh.nodes()[n] - Point3::from(target)).norm();
        (0..mesh.node_count())
            .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
            .unwrap()
    };
    let far = 1.0;
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet
        .prescribe(nearest([0.0, 0.0, -far]), [0.0; 3])
        .unwrap();
    let top = nearest([0.0, 0.0, far]);
    dirichlet.prescribe_component(top, 0, 0.0).unwrap();
    dirichlet.prescribe_component(top, 1, 0.0).unwrap();
    dirichlet
        .prescribe_component(nearest([far, 0.0, 0.0]), 1, 0.0)
        .unwrap();
    dirichlet
}

#[test]
fn the_cavity_of_a_box_turned_inside_out_holds_the_box_volume() {
    let mesh = box_mesh([0.02, 0.03, 0.05], [2, 3, 4]).unwrap();
    let outward = Surface::extract(&mesh).triangles;
    let inward: Vec<[usize; 3]> = outward.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let cavity = Cavity::new(&mesh, inward, 1.0e6).unwrap();
    let exact = 0.02 * 0.03 * 0.05;
    assert!((cavity.rest_volume_m3() - exact).abs() < 1e-12 * exact);

    // Facing out of the cavity, the wall encloses no volume on its inner side.
    let refused = Cavity::new(&mesh, outward.clone(), 1.0e6).unwrap_err();
    assert!(
        refused.to_string().contains("must face into the cavity"),
        "{refused}"
    );
    // An open wall is refused.
    let refused = Cavity::new(&mesh, outward[1..].to_vec(), 1.0e6).unwrap_err();
    assert!(refused.to_string().contains("must close"), "{refused}");
}

/// A smooth displacement of a few percent of the sphere's size, in every direction.
fn twist(mesh: &TetMesh, amplitude_m: f64) -> Vec<f64> {
    mesh.nodes()
        .iter()
        .flat_map(|p| {
            let s = p.coords * 100.0;
            [s.y.sin() + s.z, s.z.cos() * s.x, (s.x + s.y).sin()].map(|v| amplitude_m * v)
        })
        .collect()
}

#[test]
fn the_fluid_force_and_tangent_match_finite_differences() {
    let (mesh, inner, _) = hollow_sphere((0.008, 0.010), 16, 1);
    let cavity = Cavity::new(&mesh, inner, 4.0e3).unwrap();
    let dirichlet = held_321(&mesh);
    let material = Material::new(Law::NeoHookean, 1.0e3, 0.45, 1000.0).unwrap();
    let model = FemModel::new(mesh, material, dirichlet)
        .unwrap()
        .with_cavity(cavity);
    let u = twist(model.mesh(), 4e-4);
    let cavity = model.cavity().unwrap();
    assert!(
        cavity.pressure_pa(model.mesh(), &u).abs() > 10.0,
        "the twist squeezes the fluid"
    );

    // The fluid's net force on a closed wall is zero at any shape.
    let gradient = cavity.volume_gradient(model.mesh(), &u);
    let scale = gradient.iter().map(|g| g.abs()).sum::<f64>();
    for c in 0..3 {
        let net: f64 = gradient.iter().skip(c).step_by(3).sum();
        assert!(
            net.abs() < 1e-12 * scale,
            "net fluid force component {c}: {net}"
        );
    }

    // The tangent against central differences of the internal force, along a direction.
    let free = |d: usize| model.dirichlet().value(d).is_none();
    let direction: Vec<f64> = twist(model.mesh(), 1.0)
        .iter()
        .enumerate()
        .map(|(d, v)| if free(d) { v.cos() } else { 0.0 })
        .collect();
    let step = 1e-7;
    let shifted = |sign: f64| -> Vec<f64> {
        let moved: Vec<f64> = u
            .iter()
            .zip(&direction)
            .map(|(a, d)| a + sign * step * d)
            .collect();
        model.internal_force(&moved)
    };
    let (plus, minus) = (shifted(1.0), shifted(-1.0));
    let dofs = &model.dofs().free_dofs;
    let numeric: Vec<f64> = dofs
        .iter()
        .map(|&d| (plus[d] - minus[d]) / (2.0 * step))
        .collect();
    let (_, stiffness) = model.force_and_tangent(&u);
    let free_direction = model.dofs().restrict(&direction);
    let mut analytic = vec![0.0; free_direction.len()];
    model
        .pattern()
        .mul(&stiffness.values, &free_direction, &mut analytic);
    let rank_one = stiffness.rank_one.expect("the cavity's rank-one part");
    rank_one.add_product(&free_direction, &mut analytic);
    let error = relative(&analytic, &numeric);
    assert!(
        error < 1e-6,
        "tangent against finite differences: {error:.2e}"
    );

    // Without its sparse part (the pressure's change of the wall's shape) the tangent misses.
    let mut without = vec![0.0; free_direction.len()];
    let bare = FemModel::new(
        model.mesh().clone(),
        *model.material(),
        model.dirichlet().clone(),
    )
    .unwrap();
    let (_, elastic) = bare.force_and_tangent(&u);
    bare.pattern()
        .mul(&elastic.values, &free_direction, &mut without);
    rank_one.add_product(&free_direction, &mut without);
    assert!(relative(&without, &numeric) > 100.0 * error);
}

fn relative(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm).sqrt()
}

/// Lamé's hollow sphere (linear elasticity, bulk modulus `K`, shear modulus `G`), radii `a < b`,
/// pressed by `P` outside and filled with fluid of bulk modulus `κ`: `u(r) = A r + B/r²`,
/// `σ_rr = 3K A − 4G B/r³`, with `σ_rr(b) = −P` and `σ_rr(a) = −p`, `p = −κ ΔV/V = −3κ u(a)/a`.
/// Returns the fluid's pressure.
fn lame_fluid_pressure(
    (a, b): (f64, f64),
    (bulk, shear): (f64, f64),
    kappa: f64,
    outer_pa: f64,
) -> f64 {
    // [3K, −4G/b³; 3K − 3κ, −(4G + 3κ)/a³] [A; B] = [−P; 0]
    let (m11, m12) = (3.0 * bulk, -4.0 * shear / b.powi(3));
    let (m21, m22) = (
        3.0 * (bulk - kappa),
        -(4.0 * shear + 3.0 * kappa) / a.powi(3),
    );
    let det = m11 * m22 - m12 * m21;
    let big_a = -outer_pa * m22 / det;
    let big_b = outer_pa * m21 / det;
    -3.0 * kappa * (big_a + big_b / a.powi(3))
}

/// The fluid pressure of a linear hollow sphere pressed by `outer_pa`, `segments` around.
fn fluid_pressure_fem(
    (segments, layers): (usize, usize),
    kappa: f64,
    outer_pa: f64,
    material: Material,
) -> f64 {
    let (mesh, inner, outer) = hollow_sphere((0.008, 0.012), segments, layers);
    let cavity = Cavity::new(&mesh, inner, kappa).unwrap();
    let dirichlet = held_321(&mesh);
    let mut loads = Loads::new(mesh.node_count());
    loads.add_pressure(&mesh, &outer, outer_pa).unwrap();
    let model = FemModel::new(mesh, material, dirichlet)
        .unwrap()
        .with_cavity(cavity);
    let solution = model
        .solve_static(&loads, &NewtonSettings::default())
        .unwrap();
    let cavity = model.cavity().unwrap();
    cavity.pressure_pa(model.mesh(), &solution.displacement_m)
}

#[test]
fn a_fluid_filled_hollow_sphere_under_outer_pressure_matches_lame() {
    let material = Material::new(Law::Linear, 1.0e4, 0.3, 1000.0).unwrap();
    let (young, nu) = (material.young_pa, material.poisson);
    let (bulk, shear) = (young / (3.0 * (1.0 - 2.0 * nu)), young / (2.0 * (1.0 + nu)));
    let (kappa, outer_pa) = (2.0e4, 1.0);
    let exact = lame_fluid_pressure((0.008, 0.012), (bulk, shear), kappa, outer_pa);
    let errors: Vec<f64> = [(16, 2), (32, 4)]
        .map(|mesh| {
            let fem = fluid_pressure_fem(mesh, kappa, outer_pa, material);
            println!("{mesh:?} segments, layers: fluid {fem:.5} Pa, Lamé {exact:.5} Pa");
            (fem - exact).abs() / exact
        })
        .to_vec();
    println!("relative errors {errors:.4?}");
    assert!(errors[1] < 0.02, "fine mesh: {:.4}", errors[1]);
    assert!(errors[1] < 0.5 * errors[0], "refinement: {errors:.4?}");
}

#[test]
fn a_cavity_needs_a_stiff_fluid_and_a_wall_on_the_mesh() {
    let (mesh, inner, _) = hollow_sphere((0.008, 0.010), 8, 1);
    let zero = Cavity::new(&mesh, inner.clone(), 0.0).unwrap_err();
    assert!(matches!(zero, FemError::InvalidInput { .. }), "{zero}");
    let mut outside = inner;
    outside[0][0] = mesh.node_count();
    let out = Cavity::new(&mesh, outside, 1.0e6).unwrap_err();
    assert!(matches!(out, FemError::NodeOutOfRange { .. }), "{out}");
}
