//! Trajectory files, device names on the command line, the safety filter's limits and the
//! tick-time histogram, each against what it must say.

use std::time::Duration;

use nalgebra::Vector3;
use pgd_surgery::devices::{
    DeviceLimits, DeviceSpec, Fault, Histogram, SafetyFilter, SafetySettings, TICK_S, Trajectory,
    TrajectoryError,
};

fn write(name: &str, text: &str) -> std::path::PathBuf {
    let path = std::env::temp_dir().join(format!("{}-{name}", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_trajectory_interpolates_between_its_rows() {
    let path = write(
        "ok.csv",
        "time_s,x_m,y_m,z_m,buttons\n0.0,0.0,0.1,0.0,0\n1.0,0.02,0.1,-0.04,1\n",
    );
    let t = Trajectory::load(&path).unwrap();
    let mid = t.sample(0.25);
    assert!((mid.tip_m - Vector3::new(0.005, 0.1, -0.01)).norm() < 1e-15);
    assert_eq!(mid.buttons, 0);
    assert_eq!(t.sample(1.0).buttons, 1);
    assert_eq!(t.sample(5.0).tip_m, Vector3::new(0.02, 0.1, -0.04));
    assert_eq!(t.sample(-1.0).tip_m, Vector3::new(0.0, 0.1, 0.0));
}

#[test]
fn a_bad_trajectory_is_refused_with_its_line() {
    let cases = [
        ("time_s,x_m,y_m,z_m\n0,0,0,0\n0.5,0,oops,0\n", "line 3"),
        ("time_s,x_m,y_m,z_m\n0,0,0,0\n0.5,0,NaN,0\n", "not finite"),
        (
            "time_s,x_m,y_m,z_m\n0,0,0,0\n0.5,0,0,0\n0.5,0,0,0\n",
            "times must increase",
        ),
        ("time_s,x_m,y_m,z_m\n", "no samples"),
        ("time_s,x_m,y_m\n0,0,0\n", "z_m"),
    ];
    for (k, (text, expected)) in cases.iter().enumerate() {
        let path = write(&format!("bad{k}.csv"), text);
        let error = Trajectory::load(&path).unwrap_err();
        let message = error.to_string();
        assert!(message.contains(&*path.to_string_lossy()), "{message}");
        assert!(message.contains(expected), "case {k}: {message}");
        if k < 3 {
            assert!(matches!(error, TrajectoryError::Row { .. }), "{message}");
        }
    }
    let missing = Trajectory::load(std::path::Path::new("/nonexistent/t.csv")).unwrap_err();
    assert!(matches!(missing, TrajectoryError::Io { .. }));
}

#[test]
fn device_names_parse() {
    assert_eq!(
        "scripted:a/b.csv".parse::<DeviceSpec>(),
        Ok(DeviceSpec::Scripted("a/b.csv".into()))
    );
    assert_eq!("virtual".parse::<DeviceSpec>(), Ok(DeviceSpec::Virtual));
    assert_eq!(
        "openhaptics".parse::<DeviceSpec>(),
        Ok(DeviceSpec::OpenHaptics(None))
    );
    assert_eq!(
        "openhaptics:Left Touch".parse::<DeviceSpec>(),
        Ok(DeviceSpec::OpenHaptics(Some("Left Touch".into())))
    );
    for bad in ["scripted:", "touch", "virtual:x", "openhaptics:"] {
        let e = bad.parse::<DeviceSpec>().unwrap_err();
        assert!(e.contains(bad), "{e}");
    }
}

/// A step from zero to 10 N: clamped to 3.3 N, reached in steps of 20 mN, in the direction
/// asked for.
#[test]
fn the_safety_filter_clamps_and_limits_the_rate() {
    let settings = SafetySettings::default();
    let mut filter = SafetyFilter::new(settings, DeviceLimits::peak_only(10.0));
    let desired = Vector3::new(0.0, 6.0, 8.0);
    let mut last: Vector3<f64> = Vector3::zeros();
    let mut ticks = 0;
    while (last.norm() - 3.3).abs() > 1e-12 {
        let out = filter.filter(&desired, &[]);
        assert!((out - last).norm() <= settings.max_change_n_per_tick * (1.0 + 1e-12));
        assert!(out.norm() <= 3.3 * (1.0 + 1e-12));
        last = out;
        ticks += 1;
        assert!(ticks < 1000);
    }
    assert_eq!(
        ticks,
        (3.3 / settings.max_change_n_per_tick).ceil() as usize
    );
    assert!((last.normalize() - desired.normalize()).norm() < 1e-12);
    // A device weaker than the settings caps the force at its own limit.
    assert_eq!(
        SafetyFilter::new(settings, DeviceLimits::peak_only(1.0)).max_force_n(),
        1.0
    );
}

/// A Touch (3.3 N peak, 0.88 N continuous over a 2 s window) asked for 2 N for 10 s: the force
/// starts at 2 N with the motors cold, never passes the peak or changes faster than the rate
/// limit, and settles on the continuous limit; its mean square over the thermal window,
/// recomputed here from the forces sent, never passes the continuous limit's square. Asked for
/// 0.5 N, under the continuous limit, it gives 0.5 N throughout.
#[test]
fn a_sustained_force_is_held_to_the_continuous_limit() {
    let settings = SafetySettings::default();
    let limits = DeviceLimits::touch();
    let run = |asked_n: f64| {
        let mut filter = SafetyFilter::new(settings, limits);
        let desired = Vector3::new(0.0, 0.0, asked_n);
        (0..10_000)
            .map(|_| filter.filter(&desired, &[]).norm())
            .collect::<Vec<f64>>()
    };
    let sent = run(2.0);
    let window = limits.thermal_window_s / TICK_S;
    let mut heat = 0.0_f64;
    let mut hottest = 0.0_f64;
    for f in &sent {
        heat += (f * f - heat) / window;
        hottest = hottest.max(heat);
    }
    let largest_step = sent
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    let settled = sent.last().unwrap();
    eprintln!(
        "2 N asked: {:.3} N at 0.5 s, {:.3} N at 2 s, {settled:.4} N at 10 s; RMS over the window at most {:.4} N",
        sent[500],
        sent[2000],
        hottest.sqrt()
    );
    assert!(
        (sent[200] - 2.0).abs() < 1e-9,
        "a cold device renders the peak"
    );
    assert!(sent.iter().all(|&f| f <= limits.peak_force_n));
    assert!(largest_step <= settings.max_change_n_per_tick * (1.0 + 1e-12));
    assert!((settled - limits.continuous_force_n).abs() < 0.01 * limits.continuous_force_n);
    assert!(hottest.sqrt() <= limits.continuous_force_n * (1.0 + 1e-9));
    let gentle = run(0.5);
    assert!(gentle[100..].iter().all(|&f| (f - 0.5).abs() < 1e-12));
}

/// After a fault the force fades linearly to zero in `fade_ticks`, is held at zero while the
/// fault lasts and for `recovery_ticks` after, then ramps back at the rate limit.
#[test]
fn the_safety_filter_fades_holds_and_recovers() {
    let settings = SafetySettings::default();
    let mut filter = SafetyFilter::new(settings, DeviceLimits::peak_only(3.3));
    let desired = Vector3::new(0.0, 0.0, 0.1);
    for _ in 0..10 {
        filter.filter(&desired, &[]);
    }
    let fault = [Fault::NonFiniteDevice];
    let fade: Vec<f64> = (0..settings.fade_ticks)
        .map(|_| filter.filter(&desired, &fault).z)
        .collect();
    let expected: Vec<f64> = (1..=settings.fade_ticks)
        .map(|k| 0.1 * (settings.fade_ticks - k) as f64 / settings.fade_ticks as f64)
        .collect();
    for (got, want) in fade.iter().zip(&expected) {
        assert!((got - want).abs() < 1e-15, "{fade:?} vs {expected:?}");
    }
    assert!(filter.is_faulted());
    for _ in 0..settings.recovery_ticks - 1 {
        assert_eq!(filter.filter(&desired, &[]), Vector3::zeros());
    }
    assert!((filter.filter(&desired, &[]).z - settings.max_change_n_per_tick).abs() < 1e-15);
    assert!(!filter.is_faulted());
    // A non-finite force is a fault by itself.
    assert_eq!(
        filter.filter(&Vector3::new(f64::NAN, 0.0, 0.0), &[]).z,
        settings.max_change_n_per_tick * (settings.fade_ticks - 1) as f64
            / settings.fade_ticks as f64
    );
}

#[test]
fn the_histogram_gives_quantiles_to_the_microsecond() {
    let mut h = Histogram::default();
    for us in 1..=1000u64 {
        h.record(Duration::from_nanos(us * 1000 - 500));
    }
    assert_eq!(h.count(), 1000);
    assert_eq!(h.quantile(0.5), Duration::from_micros(500));
    assert_eq!(h.quantile(0.99), Duration::from_micros(990));
    assert_eq!(h.max(), Duration::from_nanos(999_500));
    assert_eq!(h.count_above(Duration::from_micros(900)), 100);
}
