//! The same script twice gives bit-identical forces, and so does a recorded run replayed.

use pgd_surgery::devices::{PressMotion, Recorder, SafetySettings, Trajectory};

use crate::common::{haptic, press, run, scripted, tick_at};

fn bits(forces: &[nalgebra::Vector3<f64>]) -> Vec<[u64; 3]> {
    forces
        .iter()
        .map(|f| [f.x, f.y, f.z].map(f64::to_bits))
        .collect()
}

#[test]
fn the_same_script_twice_gives_bit_identical_forces() {
    let motion = PressMotion::default();
    let ticks = tick_at(press(&motion).duration_s());
    let first = run(
        &mut haptic(scripted(press(&motion)), SafetySettings::default()),
        ticks,
    );
    let second = run(
        &mut haptic(scripted(press(&motion)), SafetySettings::default()),
        ticks,
    );
    assert!(first.sent_n.iter().any(|f| f.norm() > 0.05), "no contact");
    assert_eq!(bits(&first.sent_n), bits(&second.sent_n));
    assert_eq!(bits(&first.desired_n), bits(&second.desired_n));
}

#[test]
fn a_recorded_run_replays_to_the_same_forces() {
    let motion = PressMotion::default();
    let ticks = tick_at(press(&motion).duration_s());
    let file = std::env::temp_dir().join(format!("haptic-record-{}.csv", std::process::id()));
    let recorded = {
        let recorder = Box::new(Recorder::new(scripted(press(&motion)), &file));
        let mut live = haptic(recorder, SafetySettings::default());
        run(&mut live, ticks)
        // The recorder writes its file when the world holding it is dropped.
    };
    let replayed = run(
        &mut haptic(
            scripted(Trajectory::load(&file).unwrap()),
            SafetySettings::default(),
        ),
        ticks,
    );
    std::fs::remove_file(&file).unwrap();
    assert!(
        recorded.sent_n.iter().any(|f| f.norm() > 0.05),
        "no contact"
    );
    assert_eq!(bits(&recorded.sent_n), bits(&replayed.sent_n));
}
