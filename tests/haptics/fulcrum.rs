//! The fulcrum effect against hand-computed cases: the tip moves opposite to the hand across
//! the shaft, scaled by inside over outside, and one for one along it; the force comes back
//! through the same lever; and the port makes no energy.

use nalgebra::Vector3;
use pgd_surgery::devices::{Fulcrum, Instrument, MIN_OUTSIDE_M};

/// A 300 mm instrument through a port at the origin, pointing down (−y) into the abdomen.
fn port() -> Fulcrum {
    Fulcrum {
        port_m: Vector3::zeros(),
        shaft_m: 0.3,
    }
}

/// The handle 100 mm above the port: 200 mm of shaft inside, the tip 200 mm below it.
/// Moving the handle 10 mm to +x swings the tip to −x; computed by hand: the shaft from
/// h = (0.01, 0.1, 0) through the origin, |h| of it outside, ends 0.3 − |h| beyond the port at
/// −h (0.3 − |h|) / |h|.
#[test]
fn the_tip_moves_opposite_to_the_hand_scaled_by_depth() {
    let fulcrum = port();
    let straight = fulcrum.pose(&Vector3::new(0.0, 0.1, 0.0)).unwrap();
    assert!((straight.tip_m - Vector3::new(0.0, -0.2, 0.0)).norm() < 1e-15);
    assert!((straight.outside_m - 0.1).abs() < 1e-15 && (straight.inside_m - 0.2).abs() < 1e-15);

    let handle = Vector3::new(0.01, 0.1, 0.0);
    let moved = fulcrum.pose(&handle).unwrap();
    let by_hand = -handle * ((0.3 - handle.norm()) / handle.norm());
    assert!((moved.tip_m - by_hand).norm() < 1e-15, "{:?}", moved.tip_m);
    assert!(moved.tip_m.x < 0.0, "the tip did not move against the hand");
    // For a small move, the ratio is inside over outside: twice here, once deeper in.
    let small = 1e-6;
    let ratio = |outside: f64| {
        let pose = |x: f64| {
            fulcrum
                .pose(&Vector3::new(x, outside, 0.0))
                .unwrap()
                .tip_m
                .x
        };
        (pose(small) - pose(0.0)) / small
    };
    assert!((ratio(0.1) + 2.0).abs() < 1e-6, "{}", ratio(0.1));
    assert!((ratio(0.15) + 1.0).abs() < 1e-6, "{}", ratio(0.15));
    // Along the shaft, one for one: the handle 10 mm nearer the port puts the tip 10 mm deeper.
    let deeper = fulcrum.pose(&Vector3::new(0.0, 0.09, 0.0)).unwrap();
    assert!((deeper.tip_m.y + 0.21).abs() < 1e-15);
}

/// A 1 N sideways push on the tip, 200 mm in and 100 mm out, is 2 N the other way at the hand;
/// a 1 N push along the shaft is 1 N along it.
#[test]
fn the_force_comes_back_through_the_lever() {
    let pose = port().pose(&Vector3::new(0.0, 0.1, 0.0)).unwrap();
    let across = Fulcrum::hand_force(&pose, &Vector3::new(1.0, 0.0, 0.0));
    assert!(
        (across - Vector3::new(-2.0, 0.0, 0.0)).norm() < 1e-15,
        "{across:?}"
    );
    let along = Fulcrum::hand_force(&pose, &Vector3::new(0.0, 1.0, 0.0));
    assert!(
        (along - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15,
        "{along:?}"
    );
}

/// For any small motion of the hand, the power the tip's force does at the tip equals the
/// power the hand's force does at the hand: the port is passive.
#[test]
fn the_port_makes_no_energy() {
    let fulcrum = port();
    let handle = Vector3::new(0.013, 0.11, -0.021);
    let pose = fulcrum.pose(&handle).unwrap();
    let tip_force = Vector3::new(0.4, -1.3, 0.7);
    let hand_force = Fulcrum::hand_force(&pose, &tip_force);
    for velocity in [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        Vector3::new(0.3, -0.5, 0.8),
    ] {
        let dt = 1e-7;
        let moved = fulcrum.pose(&(handle + velocity * dt)).unwrap();
        let tip_velocity = (moved.tip_m - pose.tip_m) / dt;
        let (at_tip, at_hand) = (tip_force.dot(&tip_velocity), hand_force.dot(&velocity));
        assert!(
            (at_tip - at_hand).abs() < 1e-5 * tip_force.norm(),
            "{at_tip} vs {at_hand}"
        );
    }
}

/// The handle for a tip puts the tip there (what the mouse does through a port).
#[test]
fn the_handle_for_a_tip_puts_the_tip_there() {
    let fulcrum = port();
    for tip in [
        Vector3::new(0.0, -0.2, 0.0),
        Vector3::new(0.03, -0.12, 0.05),
    ] {
        let handle = fulcrum.handle_for(&tip).unwrap();
        let pose = fulcrum.pose(&handle).unwrap();
        assert!(
            (pose.tip_m - tip).norm() < 1e-15,
            "{:?} for {tip:?}",
            pose.tip_m
        );
    }
}

/// A handle pulled out beyond the shaft leaves the tip at the port; one pushed onto the port is
/// held out, so the lever's ratio stays bounded.
#[test]
fn the_shaft_stays_in_its_port() {
    let fulcrum = port();
    let out = fulcrum.pose(&Vector3::new(0.0, 0.5, 0.0)).unwrap();
    assert_eq!(out.inside_m, 0.0);
    assert!(out.tip_m.norm() < 1e-15);
    let at = fulcrum.pose(&Vector3::new(0.0, 0.001, 0.0)).unwrap();
    assert_eq!(at.outside_m, MIN_OUTSIDE_M);
    assert!(fulcrum.pose(&Vector3::zeros()).is_none());
}

/// Through a port in the trainer: the device moves the handle, the tip is where the shaft puts
/// it, and the device is sent the tip's force through the lever. The handle goes down the
/// port's axis until the tip presses the liver 4 mm, then 10 mm sideways: the tip swings the
/// other way, and the hand feels the liver's push with its part across the shaft inverted and
/// scaled.
#[test]
fn the_trainer_moves_the_handle_and_sends_the_lever_force() {
    use crate::common::{TIP_RADIUS_M, run, scene, scripted, target};
    use pgd_surgery::app::haptic::{DeviceForce, HandTouches, HapticLoop, Tool};
    use pgd_surgery::devices::{DeviceSample, SafetySettings, Trajectory, TrajectoryRow};

    let target = target();
    let n = target.normal;
    let fulcrum = Fulcrum {
        port_m: target.point_m + n * 0.12,
        shaft_m: 0.3,
    };
    let pressing = 0.3 - 0.12 + TIP_RADIUS_M - 0.004;
    let side = n.cross(&Vector3::x()).normalize();
    let handle = |outside: f64, sideways: f64| fulcrum.port_m + n * outside + side * sideways;
    let row = |t: f64, at: Vector3<f64>| TrajectoryRow::new(t, &DeviceSample::at(at));
    let trajectory = Trajectory {
        rows: vec![
            row(0.0, handle(pressing + 0.05, 0.0)),
            row(1.0, handle(pressing, 0.0)),
            row(1.5, handle(pressing, 0.01)),
            row(2.0, handle(pressing, 0.01)),
        ],
    };
    let mut ported = scene(SafetySettings::default());
    ported.right_hand_mut().instruments = vec![Instrument {
        port: Some(fulcrum),
        ..Instrument::default()
    }];
    let mut haptic = HapticLoop::new(&ported, scripted(trajectory)).unwrap();
    haptic.keep_trace();
    run(&mut haptic, 2000);
    let on_axis = fulcrum.pose(&handle(pressing, 0.0)).unwrap().tip_m;
    assert!((on_axis - (target.point_m + n * (TIP_RADIUS_M - 0.004))).norm() < 1e-12);
    let tool = haptic.hand::<Tool>(0).unwrap();
    let (pose, tip) = (tool.pose.unwrap(), tool.sample.unwrap().tip_m);
    let expected = fulcrum.pose(&handle(pressing, 0.01)).unwrap();
    assert!((tip - expected.tip_m).norm() < 1e-12);
    let pointing = tool.sample.unwrap().orientation * pgd_surgery::devices::HANDLE_AXIS;
    assert!(
        (pointing - pose.along).norm() < 1e-12,
        "the instrument is not along the shaft"
    );
    let swing = (tip - on_axis).dot(&side);
    let ratio = pose.inside_m / pose.outside_m;
    assert!(
        (swing + 0.01 * ratio).abs() < 0.1 * 0.01 * ratio,
        "the tip swung {swing} m for the hand's 0.01 m, inside/outside {ratio}"
    );
    let desired = haptic.hand::<DeviceForce>(0).unwrap().desired_n;
    let world = haptic.world_mut();
    let mut touches = world.query::<&HandTouches>();
    let at_tip: Vector3<f64> = -touches
        .iter(world)
        .filter_map(|t| t.0[0].contact.map(|c| c.force_n))
        .sum::<Vector3<f64>>();
    assert!(at_tip.norm() > 0.01, "the tip does not press: {at_tip:?}");
    let lever = Fulcrum::hand_force(&pose, &at_tip);
    assert!((desired - lever).norm() < 1e-12 * at_tip.norm());
    let across = at_tip - pose.along * at_tip.dot(&pose.along);
    assert!(
        across.norm() > 0.05 * at_tip.norm(),
        "nothing across the shaft to check"
    );
    eprintln!(
        "tip force {at_tip:?} N, hand force {desired:?} N; {:.0} mm in, {:.0} mm out",
        pose.inside_m * 1e3,
        pose.outside_m * 1e3
    );
}

/// Through a port the instrument points along the shaft whatever way the handle is held, and
/// the hand's roll of the handle about its own axis rolls the instrument (a blade's edge)
/// about the shaft by as much: the edge stays across the shaft and turns with the hand.
#[test]
fn the_instrument_lies_along_the_shaft_and_rolls_with_the_handle() {
    use nalgebra::UnitQuaternion;
    use pgd_surgery::devices::HANDLE_AXIS;
    let fulcrum = port();
    let pose = fulcrum.pose(&Vector3::new(0.04, 0.09, -0.03)).unwrap();
    let tilted = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.5);
    for roll in [0.0, 0.4, 1.3, -2.0] {
        let handle = tilted * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), roll);
        let instrument = Fulcrum::instrument_orientation(&pose, &handle);
        assert!((instrument * HANDLE_AXIS - pose.along).norm() < 1e-12);
        let edge = instrument * Vector3::x();
        assert!(
            edge.dot(&pose.along).abs() < 1e-12,
            "the edge is not across the shaft"
        );
        let unrolled = Fulcrum::instrument_orientation(&pose, &tilted) * Vector3::x();
        // The roll between the two edges, about the shaft (−y of the handle is the shaft: a
        // turn by `roll` about +y is one by −roll about the shaft's direction).
        let turned = unrolled
            .cross(&edge)
            .dot(&pose.along)
            .atan2(unrolled.dot(&edge));
        let expected =
            (-roll + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        assert!(
            (turned - expected).abs() < 1e-12,
            "rolled {turned}, expected {expected}"
        );
    }
}
