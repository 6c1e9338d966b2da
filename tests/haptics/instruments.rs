//! Several instruments, one in the device's hand: the change button takes up the next only
//! while the one in hand touches nothing, the taken one starts where it was put down (the
//! device re-indexed), and one taken up for the first time reaches 30 mm in from its port
//! towards the tip just put down. Checked on the rack alone against hand-computed places, and
//! through the trainer's schedule on the liver.

use nalgebra::Vector3;
use pgd_surgery::devices::{Action, CHANGE_BUTTON, Fulcrum, Instrument, Rack};

/// Two probes: port A at the origin, port B 100 mm to +x; 300 mm shafts.
fn two_probes() -> [Instrument; 2] {
    let at = |x: f64| Instrument {
        action: Action::Press,
        port: Some(Fulcrum {
            port_m: Vector3::new(x, 0.0, 0.0),
            shaft_m: 0.3,
        }),
    };
    [at(0.0), at(0.1)]
}

/// The tip of the instrument in hand for the device at `device_m`.
fn tip(rack: &Rack, device_m: &Vector3<f64>) -> Vector3<f64> {
    let port = rack.in_hand().1.port.unwrap();
    port.pose(&rack.handle_m(device_m)).unwrap().tip_m
}

#[test]
fn the_change_button_takes_up_the_next_instrument_where_it_was_put_down() {
    let instruments = two_probes();
    let mut rack = Rack::new(&instruments);
    // A's handle 100 mm above its port: its tip 200 mm below it.
    let hand = Vector3::new(0.0, 0.1, 0.0);
    let tip_a = tip(&rack, &hand);
    assert!((tip_a - Vector3::new(0.0, -0.2, 0.0)).norm() < 1e-15);

    // Pressing something: the button does nothing.
    assert!(!rack.take(CHANGE_BUTTON, &hand, &tip_a, || false));
    assert_eq!(rack.in_hand().0, 0);
    // Held down while the tip comes free: still nothing, the button must go down again.
    assert!(!rack.take(CHANGE_BUTTON, &hand, &tip_a, || true));
    assert!(!rack.take(0, &hand, &tip_a, || true));
    assert!(rack.take(CHANGE_BUTTON, &hand, &tip_a, || true));
    assert_eq!(rack.in_hand().0, 1);
    assert_eq!(rack.put_down(0), Some(hand));

    // B, taken up for the first time, reaches 30 mm in from its port towards A's tip.
    let port_b = Vector3::new(0.1, 0.0, 0.0);
    let towards = (tip_a - port_b).normalize();
    let tip_b = tip(&rack, &hand);
    assert!(
        (tip_b - (port_b + towards * 0.03)).norm() < 1e-12,
        "{tip_b:?}"
    );
    // The device's motion moves B's handle from there, one for one.
    let moved = hand + Vector3::new(0.0, -0.02, 0.01);
    let offset = rack.handle_m(&hand) - hand;
    assert!((rack.handle_m(&moved) - (moved + offset)).norm() < 1e-15);

    // Back to A, the device wherever it now is: A's handle is where it was put down, and B's
    // where the device left it.
    assert!(!rack.take(0, &moved, &tip_b, || true));
    assert!(rack.take(CHANGE_BUTTON, &moved, &tip_b, || true));
    assert_eq!(rack.in_hand().0, 0);
    assert!((rack.handle_m(&moved) - hand).norm() < 1e-15);
    assert!((tip(&rack, &moved) - tip_a).norm() < 1e-15);
    assert!((rack.put_down(1).unwrap() - (moved + offset)).norm() < 1e-15);
    assert_eq!(
        rack.put_down(0),
        None,
        "the instrument in hand is not put down"
    );
}

#[test]
fn one_instrument_is_never_changed() {
    let mut rack = Rack::new(&two_probes()[..1]);
    let hand = Vector3::new(0.0, 0.1, 0.0);
    assert!(!rack.take(CHANGE_BUTTON, &hand, &Vector3::zeros(), || true));
    assert_eq!(rack.in_hand().0, 0);
    assert_eq!(rack.handle_m(&hand), hand);
}

/// Through the trainer's schedule on the liver: A presses, the change button pressed during
/// the press changes nothing; lifted off, the button changes to B, whose tip is where the rack
/// puts it and touches nothing, and the hand feels no force; the button again, and A's tip is
/// back where it was lifted to, wherever the device is.
#[test]
fn the_trainer_changes_instruments_only_off_the_tissue() {
    use crate::common::{TIP_RADIUS_M, run, scene, scripted, target};
    use pgd_surgery::app::haptic::{DeviceForce, HandTouches, HapticLoop, Tool};
    use pgd_surgery::devices::{DeviceSample, SafetySettings, Trajectory, TrajectoryRow};

    let target = target();
    let n = target.normal;
    let side = n.cross(&Vector3::x()).normalize();
    let port = |offset: Vector3<f64>| Fulcrum {
        port_m: target.point_m + n * 0.12 + offset,
        shaft_m: 0.3,
    };
    let (a, b) = (port(Vector3::zeros()), port(side * 0.06));
    let instruments = [a, b].map(|port| Instrument {
        action: Action::Press,
        port: Some(port),
    });
    // A down its port's axis until the tip presses 4 mm; then lifted 50 mm.
    let pressing = a.port_m + n * (0.3 - 0.12 + TIP_RADIUS_M - 0.004);
    let lifted = pressing + n * 0.05;
    let row = |t: f64, at: Vector3<f64>, buttons: u32| {
        let mut sample = DeviceSample::at(at);
        sample.buttons = buttons;
        TrajectoryRow::new(t, &sample)
    };
    let trajectory = Trajectory {
        rows: vec![
            row(0.0, lifted, 0),
            row(1.0, pressing, 0),
            row(1.2, pressing, CHANGE_BUTTON),
            row(1.4, pressing, 0),
            row(1.8, lifted, 0),
            row(2.0, lifted, CHANGE_BUTTON),
            row(2.2, lifted, 0),
            row(2.5, lifted + side * 0.01, 0),
            row(2.7, lifted + side * 0.01, CHANGE_BUTTON),
            row(3.0, lifted + side * 0.01, 0),
        ],
    };
    let mut scene = scene(SafetySettings::default());
    scene.right_hand_mut().instruments = instruments.to_vec();
    // The loop runs from the script's start at each call: one run to each moment looked at.
    let after = |ticks: u64| {
        let mut haptic = HapticLoop::new(&scene, scripted(trajectory.clone())).unwrap();
        haptic.keep_trace();
        run(&mut haptic, ticks);
        haptic
    };
    let touching = |haptic: &mut HapticLoop| {
        let world = haptic.world_mut();
        let mut touches = world.query::<&HandTouches>();
        touches.iter(world).any(|t| t.any())
    };
    let in_hand = |haptic: &mut HapticLoop| haptic.hand::<Tool>(0).unwrap().rack.in_hand().0;
    let tip = |haptic: &mut HapticLoop| haptic.hand::<Tool>(0).unwrap().sample.unwrap().tip_m;

    let mut pressed = after(1300);
    assert!(touching(&mut pressed), "A does not press the liver");
    assert_eq!(in_hand(&mut pressed), 0, "changed while pressing");

    let mut changed = after(2100);
    assert_eq!(in_hand(&mut changed), 1, "the button did not change to B");
    let tip_a = a.pose(&lifted).unwrap().tip_m;
    let towards = (tip_a - b.port_m).normalize();
    let tip_b = tip(&mut changed);
    assert!(
        (tip_b - (b.port_m + towards * 0.03)).norm() < 1e-9,
        "B's tip is at {tip_b:?}"
    );
    assert!(!touching(&mut changed), "B's tip starts in the tissue");
    let force = changed.hand::<DeviceForce>(0).unwrap().desired_n;
    assert_eq!(
        force,
        Vector3::zeros(),
        "the hand feels {force:?} N after the change"
    );

    let mut back = after(3000);
    assert_eq!(in_hand(&mut back), 0, "the button did not change back to A");
    let back = tip(&mut back);
    assert!(
        (back - tip_a).norm() < 1e-9,
        "A's tip is at {back:?}, not where it was put down, {tip_a:?}"
    );
}
