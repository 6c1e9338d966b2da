//! A rod against the analytic solutions of a cantilever (Euler–Bernoulli for a small tip load,
//! the elastica for a large one) and of a tube under tension.

use nalgebra::Vector3;
use pgd_surgery_core::rods::{Rod, RodError, TubeSection};

/// A duct 50 mm long, 5 mm across with a 0.5 mm wall, of a 4.7 MPa wall (the pancreatic
/// duct's measured modulus, the nearest duct measured), along x.
const LENGTH_M: f64 = 0.05;
const YOUNG_PA: f64 = 4.7e6;
const SECTION: TubeSection = TubeSection {
    outer_radius_m: 2.5e-3,
    wall_m: 0.5e-3,
};

/// Forces left in a settled rod: a nanonewton.
const TOLERANCE_N: f64 = 1e-9;

fn flexural() -> f64 {
    YOUNG_PA * SECTION.second_moment_m4()
}

/// The duct in `segments` along x, held nowhere.
fn duct(segments: usize) -> Rod {
    Rod::straight(
        Vector3::zeros(),
        Vector3::x() * LENGTH_M,
        segments,
        SECTION,
        YOUNG_PA,
    )
    .unwrap()
}

/// The duct in `segments`, clamped at x = 0.
fn cantilever(segments: usize) -> Rod {
    let mut rod = duct(segments);
    rod.clamp_start();
    rod
}

/// The tip's displacement under `load_n` at the tip, applied in `ramp` equal steps.
fn tip_under(rod: &mut Rod, load_n: Vector3<f64>, ramp: usize) -> Vector3<f64> {
    let tip = rod.nodes() - 1;
    for k in 1..=ramp {
        rod.solve(&[(tip, load_n * (k as f64 / ramp as f64))], TOLERANCE_N)
            .unwrap();
    }
    rod.positions[tip] - Vector3::x() * LENGTH_M
}

/// A tip load that bends the duct by 1 % of its length: the tip moves `P L³ / 3 E I`
/// (Euler–Bernoulli) to 0.5 % with 40 segments.
#[test]
fn a_cantilever_under_a_small_tip_load_bends_as_euler_bernoulli_says() {
    let deflection_m = 0.01 * LENGTH_M;
    let load_n = 3.0 * flexural() * deflection_m / LENGTH_M.powi(3);
    let moved = tip_under(&mut cantilever(40), -Vector3::z() * load_n, 1);
    let error = (-moved.z - deflection_m).abs() / deflection_m;
    eprintln!(
        "{load_n:.3e} N: tip {:.4} mm down, Euler–Bernoulli {:.4} mm ({error:.2e})",
        -moved.z * 1e3,
        deflection_m * 1e3
    );
    assert!(error < 5e-3, "off by {error}");
}

/// The elastica of a cantilever under a tip load `α = P L² / E I` (its end force staying
/// vertical), inextensible: `θ'' = −α cos θ`, `θ(0) = 0`, `θ'(1) = 0` over `s ∈ [0, 1]`,
/// solved by shooting on `θ'(0)` with a fourth-order Runge–Kutta march of 4,000 steps.
/// Returns the tip's (x, y) over the length, y along the load.
fn elastica_tip(alpha: f64) -> (f64, f64) {
    let march = |kappa0: f64| {
        let steps = 4000;
        let h = 1.0 / steps as f64;
        // (θ, θ', x, y)
        let derivative = |s: [f64; 4]| [s[1], -alpha * s[0].cos(), s[0].cos(), s[0].sin()];
        let mut s = [0.0, kappa0, 0.0, 0.0];
        for _ in 0..steps {
            let add = |a: [f64; 4], b: [f64; 4], t: f64| std::array::from_fn(|i| a[i] + t * b[i]);
            let k1 = derivative(s);
            let k2 = derivative(add(s, k1, h / 2.0));
            let k3 = derivative(add(s, k2, h / 2.0));
            let k4 = derivative(add(s, k3, h));
            s = std::array::from_fn(|i| {
                s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        s
    };
    let (mut low, mut high) = (0.0, alpha);
    for _ in 0..80 {
        let mid = 0.5 * (low + high);
        if march(mid)[1] < 0.0 {
            low = mid;
        } else {
            high = mid;
        }
    }
    let end = march(0.5 * (low + high));
    (end[2], end[3])
}

/// Tip loads of `α = P L² / E I` = 1 and 3 bend the duct through large rotations: its tip
/// lies where the elastica puts it, to 1 % of the length (the duct stretches by 0.3 % under
/// the larger load, the elastica not at all), closer with 40 segments than with 10.
#[test]
fn a_cantilever_under_a_large_tip_load_bends_as_the_elastica() {
    for alpha in [1.0, 3.0] {
        let load_n = alpha * flexural() / LENGTH_M.powi(2);
        let (x, y) = elastica_tip(alpha);
        let errors = [10, 40].map(|segments| {
            let moved = tip_under(&mut cantilever(segments), -Vector3::z() * load_n, 20);
            let tip = (LENGTH_M + moved.x, -moved.z);
            let error = ((tip.0 / LENGTH_M - x).powi(2) + (tip.1 / LENGTH_M - y).powi(2)).sqrt();
            eprintln!(
                "α = {alpha}, {segments} segments: tip at ({:.4}, {:.4}) L, elastica ({x:.4}, {y:.4}) L, off by {error:.2e} L",
                tip.0 / LENGTH_M,
                tip.1 / LENGTH_M
            );
            error
        });
        assert!(errors[1] < 0.01, "α = {alpha}: off by {} L", errors[1]);
        assert!(errors[1] < errors[0], "α = {alpha}: {errors:?}");
    }
}

/// Pulled along its axis by 1 N at the free end, the tube lengthens by `F L / E A` to 1e-9,
/// and stays straight.
#[test]
fn a_tube_under_tension_lengthens_as_f_l_over_e_a() {
    let mut rod = cantilever(20);
    let moved = tip_under(&mut rod, Vector3::x(), 1);
    let expected = LENGTH_M / (YOUNG_PA * SECTION.area_m2());
    let error = (moved.x - expected).abs() / expected;
    eprintln!(
        "1 N: {:.4} mm longer, F L / E A {:.4} mm",
        moved.x * 1e3,
        expected * 1e3
    );
    assert!(error < 1e-9, "off by {error}");
    assert!(rod.positions.iter().all(|p| p.y == 0.0 && p.z == 0.0));
}

/// A rod held nowhere, a load on a node it lacks and a section of no wall are refused.
#[test]
fn bad_rods_and_loads_are_refused() {
    let mut free = Rod::straight(Vector3::zeros(), Vector3::x(), 4, SECTION, YOUNG_PA).unwrap();
    assert_eq!(free.solve(&[], TOLERANCE_N), Err(RodError::Unheld));
    let mut held = cantilever(4);
    assert!(matches!(
        held.solve(&[(9, Vector3::x())], TOLERANCE_N),
        Err(RodError::NoNode { node: 9, .. })
    ));
    let hollow = TubeSection {
        wall_m: 0.0,
        ..SECTION
    };
    let refused = Rod::straight(Vector3::zeros(), Vector3::x(), 4, hollow, YOUNG_PA).unwrap_err();
    assert!(refused.to_string().contains("wall_m"), "{refused}");
}

/// A tube held at both ends and stretched by `δ` carries `E A δ / L` at each end. Divided at
/// segment 10 of 20, each piece is held at the cut and stretched on its own: stretching the
/// far piece further changes nothing at the near end, and the far end carries its own
/// piece's tension, `E A (9 δ / 20 + d) / (9 Δ)`, to 1e-9.
#[test]
fn a_divided_tube_carries_nothing_across_its_cut() {
    let segments = 20;
    let mut rod = duct(segments);
    let (first, last) = (0, segments);
    rod.hold(first).unwrap();
    rod.hold(last).unwrap();
    let axial = YOUNG_PA * SECTION.area_m2();
    let stretch_m = 1e-3;
    rod.positions[last].x += stretch_m;
    rod.solve(&[], TOLERANCE_N).unwrap();
    let tension = axial * stretch_m / LENGTH_M;
    let near = -rod.node_forces_n()[first].x;
    assert!(
        (near - tension).abs() < 1e-9 * tension,
        "{near} for {tension}"
    );

    rod.divide(10).unwrap();
    assert!(rod.is_divided(10) && rod.is_held(10) && rod.is_held(11));
    let further_m = 2e-3;
    rod.positions[last].x += further_m;
    rod.solve(&[], TOLERANCE_N).unwrap();
    let near_after = -rod.node_forces_n()[first].x;
    assert!(
        (near_after - tension).abs() < 1e-9 * tension,
        "{near_after} for {tension}"
    );
    let segment_m = LENGTH_M / segments as f64;
    let far_piece = axial * (9.0 * stretch_m / 20.0 + further_m) / (9.0 * segment_m);
    let far = rod.node_forces_n()[last].x;
    assert!(
        (far - far_piece).abs() < 1e-9 * far_piece,
        "{far} for {far_piece}"
    );
    assert!(
        rod.divide(segments).is_err(),
        "a rod of 20 segments has no segment 20"
    );
}
