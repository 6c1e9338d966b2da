//! The laparoscope against hand-computed cases: a 0° optic looks along its shaft; an angled
//! one, aimed at a point, has it at the centre of its view at the asked distance, with the
//! lens where the triangle port–lens–target puts it; the round image holds what lies within
//! half the field of view and nothing behind the lens; steering pivots about the port and
//! undoes itself; and a scenario's laparoscope times the tip out of view.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, PI};

use nalgebra::{Unit, Vector3};
use pgd_surgery::devices::{Laparoscope, MIN_INSIDE_M, ScopePose, ScopeScript, Steer};
use pgd_surgery::scenario::{Exercise, Sample, Sites, parse};

/// An optic through a port at the origin, 70° across its image.
fn optic(angle_rad: f64) -> Laparoscope {
    Laparoscope {
        port_m: Vector3::zeros(),
        angle_rad,
        fov_rad: 70f64.to_radians(),
    }
}

fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a.dot(b) / (a.norm() * b.norm())).clamp(-1.0, 1.0).acos()
}

#[test]
fn a_zero_degree_optic_looks_along_its_shaft() {
    let scope = optic(0.0);
    let target = Vector3::new(0.03, -0.2, 0.04);
    let pose = scope.aim(&target, 0.08, 0.0).unwrap();
    let along = target.normalize();
    assert!((pose.axis.into_inner() - along).norm() < 1e-12);
    assert!((pose.inside_m - (target.norm() - 0.08)).abs() < 1e-12);
    let view = scope.view(&pose);
    assert!((view.forward.into_inner() - along).norm() < 1e-12);
    assert!((view.eye_m + view.forward.into_inner() * 0.08 - target).norm() < 1e-12);
}

/// Straight down 200 mm from the port, seen from 100 mm through a 30° optic: by hand, the lens
/// is L = −d cos α + √(D² − d² sin² α) = −0.0866 + √(0.04 − 0.0025) = 0.107 05 m in, and the
/// shaft turns asin(d sin α / D) = 14.48° from the target, away from the side it looks to.
#[test]
fn an_angled_optic_aimed_at_a_point_has_it_at_the_centre() {
    let scope = optic(FRAC_PI_6);
    let target = Vector3::new(0.0, -0.2, 0.0);
    let (d, alpha) = (0.1_f64, FRAC_PI_6);
    let lens_by_hand = -d * alpha.cos() + (0.04 - (d * alpha.sin()).powi(2)).sqrt();
    let turn_by_hand = (d * alpha.sin() / 0.2).asin();
    for roll in [0.0, 1.0, FRAC_PI_2, PI, -2.0] {
        let pose = scope.aim(&target, d, roll).unwrap();
        let view = scope.view(&pose);
        let centre = view.eye_m + view.forward.into_inner() * d;
        assert!((centre - target).norm() < 1e-12, "roll {roll}: {centre:?}");
        assert!((pose.inside_m - lens_by_hand).abs() < 1e-12, "roll {roll}");
        assert!((angle_between(&pose.axis, &target) - turn_by_hand).abs() < 1e-12);
        assert!((angle_between(&pose.axis, &view.forward) - alpha).abs() < 1e-12);
        // The image's up is across the view and towards the patient's front and head.
        assert!(view.up.dot(&view.forward).abs() < 1e-12);
        assert!(view.up.y + view.up.z > 0.0, "roll {roll}: up {:?}", view.up);
    }
    // Rolled half a turn, the optic looks 2α away from where it looked.
    let pose = scope.aim(&target, d, 0.0).unwrap();
    let rolled = ScopePose {
        roll_rad: pose.roll_rad + PI,
        ..pose
    };
    let turned = angle_between(&scope.forward(&pose), &scope.forward(&rolled));
    assert!((turned - 2.0 * alpha).abs() < 1e-12, "{turned}");
}

#[test]
fn a_target_too_near_the_port_cannot_be_aimed_at() {
    let scope = optic(FRAC_PI_6);
    assert!(
        scope
            .aim(&Vector3::new(0.0, -0.05, 0.0), 0.08, 0.0)
            .is_none()
    );
    assert!(scope.aim(&Vector3::zeros(), 0.08, 0.0).is_none());
}

/// The round image: a point 1° inside half the field of view is seen, 1° outside it is not,
/// and nothing behind the lens is.
#[test]
fn the_round_image_holds_half_the_field_of_view_around_the_centre() {
    let scope = optic(FRAC_PI_6);
    let pose = scope
        .aim(&Vector3::new(0.02, -0.2, 0.01), 0.08, 0.7)
        .unwrap();
    let view = scope.view(&pose);
    let across = Unit::new_normalize(view.forward.cross(&view.up));
    let at = |degrees: f64, distance: f64| {
        let tilted = nalgebra::Rotation3::from_axis_angle(&across, degrees.to_radians())
            * view.forward.into_inner();
        view.eye_m + tilted * distance
    };
    for distance in [0.01, 0.08, 0.3] {
        assert!(scope.sees(&pose, &at(34.0, distance)));
        assert!(scope.sees(&pose, &at(-34.0, distance)));
        assert!(!scope.sees(&pose, &at(36.0, distance)));
        assert!(!scope.sees(&pose, &at(180.0, distance)));
    }
    assert!(!scope.sees(&pose, &view.eye_m));
}

/// Steering pivots the shaft about the port: the lens stays as deep, a step to the right
/// brings a point right of the centre nearer it, and the opposite step undoes the first.
#[test]
fn steering_pivots_about_the_port_and_undoes_itself() {
    let scope = optic(FRAC_PI_6);
    let pose = scope
        .aim(&Vector3::new(0.0, -0.2, 0.05), 0.08, 0.4)
        .unwrap();
    let view = scope.view(&pose);
    let right = view.forward.cross(&view.up);
    let aside = view.eye_m + (view.forward.into_inner() + right * 0.3) * 0.08;
    let step = Steer {
        right_rad: 0.05,
        ..Steer::default()
    };
    let moved = scope.steer(&pose, &step);
    assert!((moved.inside_m - pose.inside_m).abs() < 1e-15);
    let off_centre = |p: &ScopePose| {
        let v = scope.view(p);
        angle_between(&v.forward, &(aside - v.eye_m))
    };
    assert!(off_centre(&moved) < off_centre(&pose));
    // A step and its opposite pivot about axes that differ as the view moved: they undo
    // each other to second order in the step, exactly along and about the shaft.
    let round_trip = |steer: Steer| {
        let back = Steer {
            right_rad: -steer.right_rad,
            up_rad: -steer.up_rad,
            in_m: -steer.in_m,
            roll_rad: -steer.roll_rad,
        };
        let again = scope.steer(&scope.steer(&pose, &steer), &back);
        assert!((again.inside_m - pose.inside_m).abs() < 1e-12);
        let axis = (again.axis.into_inner() - pose.axis.into_inner()).norm();
        let forward =
            (scope.forward(&again).into_inner() - scope.forward(&pose).into_inner()).norm();
        axis.max(forward)
    };
    let half = |s: Steer| Steer {
        right_rad: s.right_rad / 2.0,
        up_rad: s.up_rad / 2.0,
        ..s
    };
    for pivot in [
        step,
        Steer {
            right_rad: -0.04,
            up_rad: -0.1,
            ..Steer::default()
        },
    ] {
        let size = pivot.right_rad.hypot(pivot.up_rad);
        let (whole, halved) = (round_trip(pivot), round_trip(half(pivot)));
        assert!(whole < size * size, "{whole} for a step of {size} rad");
        assert!(
            halved < whole / 3.0,
            "{halved} against {whole}: not second order"
        );
    }
    let shaft_only = Steer {
        in_m: 0.02,
        roll_rad: 0.3,
        ..Steer::default()
    };
    assert!(round_trip(shaft_only) < 1e-12);
    let withdrawn = scope.steer(
        &pose,
        &Steer {
            in_m: -1.0,
            ..Steer::default()
        },
    );
    assert_eq!(withdrawn.inside_m, MIN_INSIDE_M);
}

/// A scenario's laparoscope looking at the liver: a tip held at the point looked at is in
/// view, one held behind the port is not, and the task's metrics time it to the tick.
#[test]
fn the_exercise_times_the_tip_out_of_view() {
    let text = r#"Scenario(
        title: "look", briefing: "",
        organs: ["liver"],
        laparoscope: Laparoscope(port_mm: (0, 150, 0), look_at_mm: (0, 20, 0), angle_deg: 0,
                                 keep_in_view_mm: Some((0, 20, 5))),
        tasks: [SafeNavigation(targets: [(at_mm: (0, 0, 300), radius_mm: 5)],
                               forbidden: [], max_force_n: 1, time_limit_s: 1)],
        rubric: (view: 1, completion: 0, speed: 0, force: 0, accuracy: 0),
    )"#;
    let scenario = parse(std::path::Path::new("look.scenario.ron"), text).unwrap();
    let entry = scenario.laparoscope.clone().unwrap();
    let scope = entry.laparoscope();
    let pose = entry.start().unwrap();
    let seen = Vector3::new(0.0, 0.02, 0.0);
    let behind = Vector3::new(0.0, 0.2, 0.0);
    assert!(scope.sees(&pose, &seen) && !scope.sees(&pose, &behind));
    let mut exercise = Exercise::new(scenario.clone(), Sites::default());
    for tick in 0..=1000 {
        let tip = if tick < 300 { seen } else { behind };
        exercise.step(&Sample {
            time_s: tick as f64 * 1e-3,
            tip_m: Some(tip),
            tip_in_view: Some(scope.sees(&pose, &tip)),
            target_in_view: Some(scope.sees(&pose, &metres(entry.keep_in_view_mm.unwrap()))),
            ..Sample::default()
        });
    }
    let finished = exercise.finish();
    let (scenario, tasks) = (finished.scenario, finished.tasks);
    let out_s = tasks[0].motion.out_of_view_s.unwrap();
    assert!((out_s - 0.7).abs() < 1.5e-3, "{out_s}");
    assert_eq!(tasks[0].target_out_of_view_s, Some(0.0));
    let card = pgd_surgery::scenario::score(&scenario, tasks);
    // The view's share: the tip in view 30 % of the time, the target all of it.
    assert!(
        (card.score - 100.0 * (0.3 + 1.0) / 2.0).abs() < 0.2,
        "{}",
        card.score
    );
    assert!(
        card.feedback
            .iter()
            .any(|l| l.contains("out of the camera's view")),
        "{:?}",
        card.feedback
    );
}

fn metres(at_mm: (f64, f64, f64)) -> Vector3<f64> {
    pgd_surgery::scenario::metres(at_mm)
}

/// A scripted camera: at its keys it is aimed as the keys say; between them the view is
/// centred on the point between theirs; before the first and after the last it holds.
#[test]
fn a_scripted_camera_goes_from_key_to_key() {
    let scope = optic(FRAC_PI_6);
    let (a, b) = (
        Vector3::new(0.0, -0.2, 0.05),
        Vector3::new(0.06, -0.18, -0.02),
    );
    let script = ScopeScript {
        keys: vec![(1.0, a, 0.08), (3.0, b, 0.1)],
        roll_rad: PI,
    };
    let centre = |time_s: f64, distance: f64| {
        let view = scope.view(&script.pose_at(&scope, time_s).unwrap());
        view.eye_m + view.forward.into_inner() * distance
    };
    assert_eq!(script.pose_at(&scope, 1.0), scope.aim(&a, 0.08, PI));
    assert_eq!(script.pose_at(&scope, 3.0), scope.aim(&b, 0.1, PI));
    assert_eq!(script.pose_at(&scope, 0.0), script.pose_at(&scope, 1.0));
    assert_eq!(script.pose_at(&scope, 9.0), script.pose_at(&scope, 3.0));
    assert!((centre(2.0, 0.09) - (a + b) / 2.0).norm() < 1e-12);
    assert!((centre(1.5, 0.085) - (a * 0.75 + b * 0.25)).norm() < 1e-12);
}
