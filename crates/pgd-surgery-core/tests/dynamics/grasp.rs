//! A grasper on the block: grasp, pull, hold, release — the held force against the static
//! answer, the hand's force continuous from tick to tick, the organ settling back; and a pull
//! too far, which slips, lets the tissue escape and marks it damaged.

use nalgebra::{Matrix3, Vector3};
use pgd_surgery_core::dynamics::{
    EnergyMomentum, GraspPoint, GraspSettings, GraspTick, GraspedOrgan, Jaws, RayleighDamping,
    Tether,
};
use pgd_surgery_core::fem::{FemModel, Law, Loads, NewtonSettings};

use crate::common::{KEEP, liver_block, vademecum_basis};

const TICK_S: f64 = 1e-3;

/// The node in the middle of the block's top face.
fn top_middle(model: &FemModel) -> usize {
    let nodes = model.mesh().nodes();
    let centre = Vector3::new(0.03, 0.02, 0.03);
    *model
        .mesh()
        .node_set("z1")
        .unwrap()
        .iter()
        .min_by(|&&a, &&b| {
            (nodes[a].coords - centre)
                .norm()
                .total_cmp(&(nodes[b].coords - centre).norm())
        })
        .unwrap()
}

/// The static compliance at `node` (m/N), from three full FEM solves of the linear model.
fn compliance(model: &FemModel, node: usize) -> Matrix3<f64> {
    let mut c = Matrix3::zeros();
    for axis in 0..3 {
        let mut loads = Loads::new(model.mesh().node_count());
        let mut force = [0.0; 3];
        force[axis] = 1.0;
        loads.add_nodal_force(node, force).unwrap();
        let u = model
            .solve_static(&loads, &NewtonSettings::default())
            .unwrap()
            .displacement_m;
        for row in 0..3 {
            c[(row, axis)] = u[3 * node + row];
        }
    }
    c
}

/// The linear block with a grasper on its top middle node, damped at 10 % of critical.
fn grasped(settings: GraspSettings) -> (GraspedOrgan, Vector3<f64>, Matrix3<f64>) {
    let (organ, rest, full, _) = grasped_with_modes(settings);
    (organ, rest, full)
}

/// The kept modes at the grasped node, `[mode]`, and their squared frequencies.
struct PointModes {
    at_point: Vec<Vector3<f64>>,
    omega2: Vec<f64>,
}

/// [`grasped`], with the kept modes at the grasped node.
fn grasped_with_modes(
    settings: GraspSettings,
) -> (GraspedOrgan, Vector3<f64>, Matrix3<f64>, PointModes) {
    let model = liver_block([6, 4, 3], Law::Linear);
    let (basis, reduced) = vademecum_basis(&model);
    let node = top_middle(&model);
    let modes = PointModes {
        at_point: (0..basis.len())
            .map(|k| Vector3::from_column_slice(&basis.mode(k)[3 * node..3 * node + 3]))
            .collect(),
        omega2: basis.omega2.clone(),
    };
    let rest = model.mesh().nodes()[node].coords;
    let full = compliance(&model, node);
    let point = GraspPoint::at_node(&basis, node, rest, &full);
    let omega = |k: usize| basis.omega2[k].sqrt();
    let damping = RayleighDamping::with_ratio(0.1, omega(0), omega(KEEP - 1));
    let step = EnergyMomentum::new(&reduced, &basis.omega2, TICK_S, damping);
    (
        GraspedOrgan::new(reduced, step, point, settings),
        rest,
        full,
        modes,
    )
}

/// A smooth move from 0 to 1 over `[0, 1]`.
fn ease(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    0.5 - 0.5 * (std::f64::consts::PI * t).cos()
}

/// Grasped at 0.1 s, pulled 20 mm up over 1 s, held 2 s, released at 3.1 s, watched 3 s more:
/// - held, the hand feels the static answer of coupling and organ in series,
///   `(I + kC)⁻¹ k d` with `C` the full FEM compliance, within 1 %;
/// - the hand's force changes from tick to tick by no more than the pull makes it (31 mm/s at
///   most through the 150 N/m coupling: 4.7 mN, with 20 % for the organ's swing) while held,
///   and by no more than the release's fade (the held force over 50 ticks: 11.5 mN) at all;
/// - released, the grasped point swings back to within 1 % of its held displacement and the
///   hand's force is zero from 50 ms after the release on; nothing is non-finite; no damage.
#[test]
fn grasped_pulled_held_and_released() {
    let settings = GraspSettings::default();
    let (mut organ, rest, full) = grasped(settings);
    let lift = Vector3::new(0.0, 0.0, 0.02);
    let hand = |t: f64| rest + lift * ease(t - 0.1);
    let (mut last, mut largest_change, mut while_held) = (Vector3::zeros(), 0.0_f64, 0.0_f64);
    let mut held = (Vector3::zeros(), 0.0);
    let mut after_release = Vec::new();
    for tick in 0..6100 {
        let t = tick as f64 * TICK_S;
        let closed = (0.1..3.1).contains(&t);
        if tick == 100 {
            organ.close(&hand(t), &Vector3::zeros());
        }
        let GraspTick {
            hand_force_n,
            point_m,
            ..
        } = organ.tick(&hand(t), closed).unwrap();
        assert!(hand_force_n.iter().all(|f| f.is_finite()), "tick {tick}");
        let change = (hand_force_n - last).norm();
        largest_change = largest_change.max(change);
        if closed {
            while_held = while_held.max(change);
        }
        last = hand_force_n;
        if tick == 3099 {
            held = (hand_force_n, (point_m.unwrap() - rest).norm());
        }
        if t >= 3.15 {
            after_release.push(hand_force_n.norm());
        }
    }
    let k = settings.coupling_n_per_m;
    let expected = -(Matrix3::identity() + full * k)
        .lu()
        .solve(&(lift * k))
        .unwrap();
    let error = (held.0 - expected).norm() / expected.norm();
    let u = organ.point_displacement();
    eprintln!(
        "held {:.4} N against {:.4} N ({error:.1e}), point drawn {:.1} mm; largest change {largest_change:.4} N/tick ({while_held:.4} while held); left at {:.3} mm",
        held.0.norm(),
        expected.norm(),
        held.1 * 1e3,
        u.norm() * 1e3
    );
    assert!(error < 0.01, "{error}");
    // The pull at up to π/2 · 20 mm/s through the coupling: k v h = 4.7 mN a tick.
    let pull_step = k * std::f64::consts::FRAC_PI_2 * 0.02 * TICK_S;
    assert!(
        while_held <= 1.2 * pull_step,
        "{while_held} N a tick while held"
    );
    // The release fades the held force in equal steps over 50 ms.
    let fade_step = held.0.norm() * TICK_S / settings.release_s;
    assert!(
        largest_change <= fade_step * (1.0 + 1e-6),
        "{largest_change} N a tick"
    );
    assert!(after_release.iter().all(|&f| f == 0.0));
    assert!(
        u.norm() < 0.01 * held.1,
        "{} m left of {} m",
        u.norm(),
        held.1
    );
    assert!(!organ.damaged);
    assert_eq!(organ.jaws, Jaws::Open);
}

/// Pulled 150 mm: the hand's force never exceeds the slip limit, the jaws slip, the tissue
/// escapes once they have slid 10 mm (the jaws let go, the force fades), and the tissue is
/// marked damaged on the way (the 2 N damage pull is below the 2.5 N slip); the jaws, kept shut,
/// do not take it again, and a new grasp starts with undamaged tissue.
#[test]
fn a_pull_too_far_slips_escapes_and_damages() {
    let settings = GraspSettings::default();
    let (mut organ, rest, _) = grasped(settings);
    let (mut strongest, mut slipped, mut damaged_at, mut escaped_at) = (0.0_f64, false, None, None);
    for tick in 0..3000 {
        let t = tick as f64 * TICK_S;
        let hand = rest + Vector3::new(0.0, 0.0, 0.15) * ease((t - 0.1) / 2.0);
        if tick == 100 {
            organ.close(&hand, &Vector3::zeros());
        }
        let outcome = organ.tick(&hand, t >= 0.1).unwrap();
        strongest = strongest.max(outcome.hand_force_n.norm());
        slipped |= outcome.slipping;
        if outcome.damaged_now {
            damaged_at = Some(t);
        }
        if escaped_at.is_none() && matches!(organ.jaws, Jaws::Releasing { .. }) {
            escaped_at = Some(t);
        }
    }
    eprintln!(
        "strongest {strongest:.3} N, damaged at {damaged_at:?} s, escaped at {escaped_at:?} s"
    );
    assert!(
        strongest <= settings.slip_force_n * (1.0 + 1e-9),
        "{strongest}"
    );
    assert!(slipped);
    assert!(damaged_at.is_some() && escaped_at.is_some());
    assert!(damaged_at < escaped_at);
    // The jaws stayed shut on nothing after the escape; a new grasp starts undamaged.
    assert_eq!(organ.jaws, Jaws::Open);
    organ.close(&(rest + Vector3::new(0.0, 0.0, 0.15)), &Vector3::zeros());
    assert!(!organ.damaged);
}

/// A stiffness over the kept modes (s⁻²): each mode held by a hundred times its own, and
/// modes 0 and 1 coupled; positive definite.
fn holding(omega2: &[f64]) -> Vec<f64> {
    let r = omega2.len();
    let mut k = vec![0.0; r * r];
    for (i, w2) in omega2.iter().enumerate() {
        k[i * r + i] = 100.0 * w2;
    }
    let coupled = 50.0 * omega2[0];
    k[1] = coupled;
    k[r] = coupled;
    k
}

/// Held by a restraint over its kept modes (a bed's ties, as `GraspedOrgan::set_restraint`
/// takes them) and pulled 5 mm, the hand feels the static answer of coupling, remainder and
/// restrained modes in series, `(I + k (R + Φₛ (Λ + K_r)⁻¹ Φₛᵀ))⁻¹ k d` (R the full FEM
/// compliance less the free kept modes' share), within 1 %; stiffer than unrestrained; and
/// the kept modes' dynamic correction to that static answer has died out (below 1e-3 of the
/// kept modes' motion).
#[test]
fn a_restrained_organ_resists_the_pull_as_its_restraint_says() {
    let settings = GraspSettings::default();
    let (mut organ, rest, full, modes) = grasped_with_modes(settings);
    let restraint = holding(&modes.omega2);
    organ.set_restraint(&modes.omega2, &restraint);
    let pull = Vector3::new(0.0, 0.0, 0.005);
    let hand = |t: f64| rest + pull * ease(t - 0.1);
    let mut held = Vector3::zeros();
    for tick in 0..3000 {
        let t = tick as f64 * TICK_S;
        if tick == 100 {
            organ.close(&hand(t), &Vector3::zeros());
        }
        held = organ.tick(&hand(t), true).unwrap().hand_force_n;
        assert!(held.iter().all(|f| f.is_finite()), "tick {tick}");
    }
    let r = modes.omega2.len();
    let phi = nalgebra::DMatrix::from_fn(3, r, |i, k| modes.at_point[k][i]);
    let lambda =
        nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&modes.omega2));
    let held_modes = &lambda + nalgebra::DMatrix::from_row_slice(r, r, &restraint);
    let share = |stiffness: &nalgebra::DMatrix<f64>| {
        let s = &phi * stiffness.clone().try_inverse().unwrap() * phi.transpose();
        Matrix3::from_fn(|i, j| s[(i, j)])
    };
    let remainder = full - share(&lambda);
    let k = settings.coupling_n_per_m;
    let answer = |compliance: Matrix3<f64>| {
        -(Matrix3::identity() + compliance * k)
            .lu()
            .solve(&(pull * k))
            .unwrap()
    };
    let expected = answer(remainder + share(&held_modes));
    let free = answer(full);
    let error = (held - expected).norm() / expected.norm();
    let mut correction = vec![0.0; r];
    organ.correction(&modes.omega2, &mut correction);
    let motion = organ.state.q.iter().map(|q| q * q).sum::<f64>().sqrt();
    let left = correction.iter().map(|c| c * c).sum::<f64>().sqrt();
    eprintln!(
        "restrained: held {:.4} N against {:.4} N ({error:.1e}); free {:.4} N; correction {:.1e} of the motion",
        held.norm(),
        expected.norm(),
        free.norm(),
        left / motion
    );
    assert!(error < 0.01, "{error}");
    assert!(held.norm() > 1.05 * free.norm());
    assert!(left < 1e-3 * motion, "{left} of {motion}");
}

/// Tethered beside the organ (a stiff wall carrying the pull to what holds it, as
/// `GraspedOrgan::set_tether` takes it: springs of 40 and 120 N/m from the point's rest
/// position, stiffer than the block there) and pulled 5 mm, the hand feels the static answer
/// of the coupling in series with the organ and the tether side by side,
/// `(k⁻¹ I + (K_t + C⁻¹)⁻¹)⁻¹ d` with `C` the full FEM compliance, within 1 %; the organ takes
/// the share `C⁻¹ (x − X)` of the point's displacement, within 1 %; released, the tether
/// goes with the jaws and the point swings back to rest.
#[test]
fn a_tethered_point_shares_the_pull_with_its_tether() {
    let settings = GraspSettings::default();
    let (mut organ, rest, full) = grasped(settings);
    let stiffness = Matrix3::from_diagonal(&Vector3::new(40.0, 40.0, 120.0));
    let tether = Tether {
        stiffness_n_per_m: stiffness,
        force_at_origin_n: stiffness * rest,
    };
    let pull = Vector3::new(0.002, 0.0, 0.005);
    let hand = |t: f64| rest + pull * ease(t - 0.1);
    let mut held = GraspTick {
        hand_force_n: Vector3::zeros(),
        point_m: None,
        slipping: false,
        damaged_now: false,
    };
    for tick in 0..3000 {
        let t = tick as f64 * TICK_S;
        if tick == 100 {
            organ.close(&hand(t), &Vector3::zeros());
            organ.set_tether(Some(tether));
        }
        held = organ.tick(&hand(t), true).unwrap();
        assert!(
            held.hand_force_n.iter().all(|f| f.is_finite()),
            "tick {tick}"
        );
    }
    let k = settings.coupling_n_per_m;
    let point = stiffness + full.try_inverse().unwrap();
    let series = Matrix3::identity() / k + point.try_inverse().unwrap();
    let expected = -series.try_inverse().unwrap() * pull;
    let error = (held.hand_force_n - expected).norm() / expected.norm();
    let moved = held.point_m.unwrap() - rest;
    let share = full.try_inverse().unwrap() * moved;
    let share_error = (organ.applied_n() - share).norm() / share.norm();
    eprintln!(
        "tethered: held {:.4} N against {:.4} N ({error:.1e}); the organ takes {:.4} N against {:.4} N ({share_error:.1e})",
        held.hand_force_n.norm(),
        expected.norm(),
        organ.applied_n().norm(),
        share.norm()
    );
    assert!(error < 0.01, "{error}");
    assert!(share_error < 0.01, "{share_error}");
    for tick in 3000..6000 {
        let let_go = organ.tick(&hand(tick as f64 * TICK_S), false).unwrap();
        assert!(
            let_go.hand_force_n.iter().all(|f| f.is_finite()),
            "tick {tick}"
        );
    }
    let back = organ.point_displacement().norm();
    assert!(back < 0.01 * moved.norm(), "{back} m from rest");
}
