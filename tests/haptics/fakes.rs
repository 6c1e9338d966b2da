//! What the backends' tests against the vendor fakes share: the run every backend's fault test
//! makes, and the checks of the watchdog and the edge guard.

use std::ops::Range;

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{DeviceForce, FaultLog, HapticLoop, TickClock};
use pgd_surgery::devices::{
    HapticDevice, MAX_FORCE_LIMIT_N, PressTarget, SafetySettings, ServoLink, TICK_S, WATCHDOG_S,
};

use crate::common::{TIP_RADIUS_M, scene, target};
use crate::vendor_fake::VendorFake;

/// What [`press_then_fault`] saw: the force while pressing, every tick's force, the faults.
pub struct FaultRun {
    pub pressing: Vector3<f64>,
    pub sent: Vec<Vector3<f64>>,
    pub faults: Vec<(u64, String)>,
}

/// The haptic loop over `device` on the coarse liver, whose tool the fake holds 4 mm into it:
/// 400 ticks, then `fault` and 20 ticks more, `frame` waiting for a servo frame after each.
pub fn press_then_fault(
    device: Box<dyn HapticDevice>,
    frame: impl Fn(),
    fault: impl FnOnce(),
) -> FaultRun {
    let mut haptic = HapticLoop::new(&scene(SafetySettings::default()), device).unwrap();
    let mut sent = Vec::new();
    let mut tick = |haptic: &mut HapticLoop, n: u64| {
        haptic.tick(TickClock {
            tick: n,
            time_s: n as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        sent.push(haptic.hand::<DeviceForce>(0).unwrap().sent_n);
        frame();
    };
    (0..400).for_each(|n| tick(&mut haptic, n));
    fault();
    frame();
    frame();
    (400..420).for_each(|n| tick(&mut haptic, n));
    let faults = haptic.hand::<FaultLog>(0).unwrap().log.iter();
    FaultRun {
        pressing: sent[399],
        faults: faults.map(|(t, f)| (*t, f.to_string())).collect(),
        sent,
    }
}

/// The tool at 4 mm into the liver where the tests press (the scene's frame).
pub fn pressing_tip_m() -> Vector3<f64> {
    pressing_at(&target())
}

/// The tool at 4 mm into the liver at `target` (the scene's frame).
pub fn pressing_at(target: &PressTarget) -> Vector3<f64> {
    target.point_m + target.normal * (TIP_RADIUS_M - 0.004)
}

/// Ticks `haptic`'s two hands over `ticks`, `frame` waiting for the servos after each; each
/// hand's force sent at the last.
pub fn tick_hands(
    haptic: &mut HapticLoop,
    ticks: Range<u64>,
    frame: impl Fn(),
) -> [Vector3<f64>; 2] {
    let mut sent = [Vector3::zeros(); 2];
    for n in ticks {
        haptic.tick(TickClock {
            tick: n,
            time_s: n as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        frame();
        sent = [0, 1].map(|hand| haptic.hand::<DeviceForce>(hand).unwrap().sent_n);
    }
    sent
}

/// Both hands push back along their `targets`' normals, and each device renders its own
/// hand's force: `rendered(hand)` (the scene's axes) is what the hand sent, to 1e-12 N.
pub fn assert_each_device_renders_its_hand(
    sent: &[Vector3<f64>; 2],
    targets: &[PressTarget; 2],
    rendered: impl Fn(usize) -> Vector3<f64>,
) {
    for (hand, t) in targets.iter().enumerate() {
        assert!(
            sent[hand].dot(&t.normal) > 0.05,
            "hand {hand}: {:?}",
            sent[hand]
        );
        let device = rendered(hand);
        assert!(
            (device - sent[hand]).norm() < 1e-12,
            "hand {hand}: {device:?}"
        );
    }
}

/// After a fault of the left hand's device: the left hand's force is zero and its log says
/// so in words that contain `says`; the right hand still pushes back, with no fault.
pub fn assert_left_alone_faded(
    haptic: &HapticLoop,
    sent: &[Vector3<f64>; 2],
    right_target: &PressTarget,
    says: &str,
) {
    assert_eq!(sent[1], Vector3::zeros());
    assert!(sent[0].dot(&right_target.normal) > 0.05, "{:?}", sent[0]);
    assert!(haptic.hand::<FaultLog>(0).unwrap().log.is_empty());
    let left = &haptic.hand::<FaultLog>(1).unwrap().log;
    assert!(
        left.iter().any(|(_, f)| f.to_string().contains(says)),
        "{left:?}"
    );
}

/// The run pushed the trainee back with no fault, then faded the force to zero within the
/// filter's 5 ticks of the fault, whose log entry `says` what happened.
pub fn assert_faded(run: &FaultRun, says: &str) {
    eprintln!(
        "pressing {:.3} N; faults {:?}",
        run.pressing.norm(),
        run.faults
    );
    assert!(
        run.pressing.dot(&target().normal) > 0.05,
        "{:?}",
        run.pressing
    );
    assert!(run.sent[405..].iter().all(|f| *f == Vector3::zeros()));
    assert!(
        run.faults.iter().all(|(tick, _)| *tick >= 400),
        "{:?}",
        run.faults
    );
    assert!(
        run.faults.iter().any(|(_, f)| f.contains(says)),
        "{:?}",
        run.faults
    );
}

/// The servo rendered the last command while it was within the watchdog and zero from the
/// very next servo frame, past it: on the servo's own clock, the force reached zero no later
/// than the watchdog's 10 ms plus one servo period (that frame's spacing, whatever the
/// machine's load made it). Zero came no sooner than the watchdog in wall time either
/// (`zeroed_after_s`, from just before the command).
pub fn assert_watchdog_held(link: &ServoLink, zeroed_after_s: f64) {
    let record = link.watchdog_record();
    let (expired_s, expired_frame) = record.expired.expect("a servo frame found it expired");
    let period_s = expired_s - record.rendered_age_s;
    eprintln!(
        "zeroed {:.1} ms after the last command (watchdog {:.0} ms): rendered at {:.2} ms of \
         age in servo frame {}, zero from {:.2} ms in frame {expired_frame} ({:.2} ms later); \
         {} expired frames",
        zeroed_after_s * 1e3,
        WATCHDOG_S * 1e3,
        record.rendered_age_s * 1e3,
        record.rendered_frame,
        expired_s * 1e3,
        period_s * 1e3,
        link.expired_frames()
    );
    assert!(
        record.rendered_age_s <= WATCHDOG_S,
        "rendered at {} s of age",
        record.rendered_age_s
    );
    assert!(expired_s > WATCHDOG_S, "zeroed early, at {expired_s} s");
    assert_eq!(
        expired_frame,
        record.rendered_frame + 1,
        "frames between the last one rendering the command and the first rendering zero"
    );
    assert!(
        zeroed_after_s >= WATCHDOG_S,
        "zeroed early: {zeroed_after_s} s"
    );
}

/// The guard at `device`'s edge, apart from the safety filter, as the vendor library saw it:
/// a NaN commanded renders zero and a 100 N one the device's own peak (`peak_n`), each refused
/// with an error (a fault of the loop's next tick); neither reaches the library's force call
/// (`fake` prefixes the fake's controls: `fake_hd`, `fake_dhd`).
pub fn assert_edge_guarded(device: &mut dyn HapticDevice, fake: &VendorFake, prefix: &str) {
    let peak_n = device.limits().peak_force_n;
    let frames = format!("{prefix}_frames");
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    fake.wait(&frames, 3);
    assert_ne!(
        fake.vector(&format!("{prefix}_last_force")),
        Vector3::zeros()
    );
    let nan = device.write_force(&Vector3::new(f64::NAN, 0.0, 1.0));
    let nan = nan.unwrap_err().to_string();
    assert!(nan.contains("not finite"), "{nan}");
    fake.wait(&frames, 3);
    assert_eq!(
        fake.vector(&format!("{prefix}_last_force")),
        Vector3::zeros()
    );
    let over = device.write_force(&Vector3::new(0.0, 0.0, 100.0));
    let over = over.unwrap_err().to_string();
    assert!(over.contains("100.000 N was commanded"), "{over}");
    fake.wait(&frames, 3);
    let rendered = fake.vector(&format!("{prefix}_last_force"));
    assert!((rendered.norm() - peak_n).abs() < 1e-12, "{rendered:?}");
    assert_eq!(fake.long(&format!("{prefix}_nonfinite_forces")), 0);
    let largest = fake.double(&format!("{prefix}_largest_force"));
    assert!(
        largest <= peak_n * (1.0 + 1e-12),
        "{largest} N reached the motors"
    );
}

/// A driver reporting a 100 N peak (the fake told so before `device` opened): the device's peak
/// is the product's 20 N ceiling, and a 100 N command reaches the library's force call as 20 N
/// (`prefix` names the fake's controls).
pub fn assert_held_to_ceiling(device: &mut dyn HapticDevice, fake: &VendorFake, prefix: &str) {
    assert_eq!(device.limits().peak_force_n, MAX_FORCE_LIMIT_N);
    let refused = device.write_force(&Vector3::new(0.0, 0.0, 100.0));
    assert!(refused.is_err());
    fake.wait(&format!("{prefix}_frames"), 3);
    let rendered = fake.vector(&format!("{prefix}_last_force"));
    assert!(
        (rendered.norm() - MAX_FORCE_LIMIT_N).abs() < 1e-9,
        "{rendered:?}"
    );
    let largest = fake.double(&format!("{prefix}_largest_force"));
    assert!(largest <= MAX_FORCE_LIMIT_N * (1.0 + 1e-12), "{largest} N");
}
