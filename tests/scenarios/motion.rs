//! The motion metrics on synthetic trajectories whose path, economy, movements, idle time and
//! jerk are known in closed form, fed tick by tick as the haptic loop feeds them.

use std::f64::consts::PI;

use nalgebra::Vector3;
use pgd_surgery::devices::TICK_S;
use pgd_surgery::scenario::{IDLE_M_PER_S, MotionMetrics, MotionTracker, STRIDE};

/// The metrics of the tip at `tip(t)` sampled every tick for `duration_s`.
fn measure(duration_s: f64, tip: impl Fn(f64) -> Vector3<f64>) -> MotionMetrics {
    let mut tracker = MotionTracker::default();
    let ticks = (duration_s / TICK_S).round() as u64;
    for k in 0..=ticks {
        tracker.step(Some(tip(k as f64 * TICK_S)), TICK_S);
    }
    tracker.metrics()
}

/// Three strokes out and back along x, `x = A (1 − cos ωt)`, A = 20 mm, 0.5 Hz, 6 s: the path
/// is 12 A = 240 mm; the farthest point 2A out and the end at the start, so the shortest path
/// is 4A and the economy 3; six movements (the tip stops at each turn); idle where
/// `|Aω sin ωt| < 5 mm/s`, `(12/π) asin(v/Aω)` s of the 6, within a subsample per stop; jerk
/// `−Aω³ sin ωt`, its RMS `Aω³/√2`, within 1 % (the third difference's error is `(ωh)²/4`).
#[test]
fn strokes_out_and_back_measure_as_their_closed_forms() {
    let (a, omega) = (0.020, PI);
    let m = measure(6.0, |t| {
        Vector3::new(a * (1.0 - (omega * t).cos()), 0.0, 0.0)
    });
    let idle_s = 12.0 / PI * (IDLE_M_PER_S / (a * omega)).asin();
    let jerk = a * omega.powi(3) / 2f64.sqrt();
    eprintln!("{m:?}; idle expected {idle_s:.3} s, jerk {jerk:.4} m/s³");
    assert!((m.path_length_mm - 240.0).abs() < 1e-6 * 240.0);
    assert!((m.economy.unwrap() - 3.0).abs() < 1e-6);
    assert_eq!(m.movements, 6);
    let subsample_s = STRIDE as f64 * TICK_S;
    assert!(
        (m.idle_s - idle_s).abs() <= 7.0 * subsample_s,
        "{} vs {idle_s}",
        m.idle_s
    );
    assert!((m.rms_jerk_m_per_s3 / jerk - 1.0).abs() < 0.01);
}

/// In 30 mm at 20 mm/s, held 2 s, back out: the path 60 mm, no wasted motion (economy 1), two
/// movements, idle through the hold (2 s, within a subsample at each end).
#[test]
fn a_press_held_and_withdrawn_wastes_no_motion() {
    let depth = |t: f64| match t {
        t if t < 1.5 => 0.020 * t,
        t if t < 3.5 => 0.030,
        t => (0.030 - 0.020 * (t - 3.5)).max(0.0),
    };
    let m = measure(5.0, |t| Vector3::new(0.0, 0.0, -depth(t)));
    eprintln!("{m:?}");
    assert!((m.path_length_mm - 60.0).abs() < 1e-6);
    assert!((m.economy.unwrap() - 1.0).abs() < 1e-9);
    assert_eq!(m.movements, 2);
    assert!(
        (m.idle_s - 2.0).abs() <= 2.0 * STRIDE as f64 * TICK_S,
        "{}",
        m.idle_s
    );
}

/// A tip that stays put: no path, no economy to speak of, no movement, idle throughout, no
/// jerk.
#[test]
fn a_still_tip_is_idle() {
    let m = measure(2.0, |_| Vector3::new(0.01, 0.02, 0.03));
    assert_eq!(m.path_length_mm, 0.0);
    assert_eq!(m.economy, None);
    assert_eq!(m.movements, 0);
    assert!(
        (m.idle_s - 2.0).abs() <= STRIDE as f64 * TICK_S,
        "{}",
        m.idle_s
    );
    // The third difference of equal positions is zero but for round-off, over h³ = 1e-6 s³.
    assert!(m.rms_jerk_m_per_s3 < 1e-9, "{}", m.rms_jerk_m_per_s3);
}

/// Two instruments: the first's tip moves 10 mm at 10 mm/s and is put down; the second's,
/// taken up 100 mm away, moves 20 mm and is put down; the first's, taken up again where it
/// was left, moves 5 mm. The path is their 35 mm (not the 200 mm of jumps between tips), 15 mm
/// and 20 mm by instrument, two changes, three movements (a jump is no movement), and no
/// wasted motion.
#[test]
fn each_instrument_keeps_its_own_path_and_a_change_is_no_motion() {
    let x = |mm: f64| Vector3::new(mm * 1e-3, 0.0, 0.0);
    let far = Vector3::new(0.0, 0.1, 0.0);
    let mut tracker = MotionTracker::default();
    let mut feed = |instrument: usize, from: Vector3<f64>, to: Vector3<f64>, speed: f64| {
        let ticks = ((to - from).norm() / speed / TICK_S).round() as u64;
        // Held still for a second before and after: each movement ends.
        for k in 0..=(ticks + 2000) {
            let t = (k.saturating_sub(1000) as f64 / ticks as f64).min(1.0);
            tracker.in_hand(instrument);
            tracker.step(Some(from.lerp(&to, t)), TICK_S);
        }
    };
    feed(0, x(0.0), x(10.0), 0.010);
    feed(1, far, far + x(20.0), 0.010);
    feed(0, x(10.0), x(15.0), 0.010);
    let m = tracker.metrics();
    eprintln!("{m:?}");
    assert!(
        (m.path_length_mm - 35.0).abs() < 1e-9,
        "{}",
        m.path_length_mm
    );
    assert_eq!(m.instrument_changes, Some(2));
    let by = &m.path_length_by_instrument_mm;
    assert_eq!(by.len(), 2);
    assert!(
        (by[0] - 15.0).abs() < 1e-9 && (by[1] - 20.0).abs() < 1e-9,
        "{by:?}"
    );
    assert_eq!(m.movements, 3);
    // Each spell went straight: no wasted motion, the jumps between tips not counted.
    assert!((m.economy.unwrap() - 1.0).abs() < 1e-9, "{:?}", m.economy);
}

/// One instrument throughout: nothing about changes in the metrics.
#[test]
fn one_instrument_reports_no_changes() {
    let m = measure(1.0, |t| Vector3::new(0.01 * t, 0.0, 0.0));
    assert_eq!(m.instrument_changes, None);
    assert!(m.path_length_by_instrument_mm.is_empty());
}
