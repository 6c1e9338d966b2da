//! Trajectory files, device names on the command line, the safety filter's limits and the
//! tick-time histogram, each against what it must say.

use std::time::Duration;

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{HapticLoop, HapticScene};
use pgd_surgery::devices::{
    DeviceLimits, DeviceSpec, EdgeForce, EdgeRefusal, Fault, HapticDevice, Histogram,
    MAX_FORCE_LIMIT_N, Recorder, SafetyFilter, SafetySettings, Scripted, TICK_S, Trajectory,
    TrajectoryError, VirtualDevice,
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

/// A bimanual file: the right hand's columns and the left's (`left_…`, in any order, its
/// orientation left out) on one time column; each hand interpolates its own. A one-hand
/// reader refuses it, naming both counts; written back it reads the same.
#[test]
fn a_bimanual_trajectory_carries_both_hands() {
    let path = write(
        "hands.csv",
        "time_s,x_m,left_buttons,y_m,z_m,buttons,left_x_m,left_y_m,left_z_m\n\
         0.0,0.0,1,0.1,0.0,0,-0.05,0.1,0.0\n\
         1.0,0.02,0,0.1,-0.04,1,-0.03,0.12,0.0\n",
    );
    let hands = Trajectory::load_hands(&path).unwrap();
    assert_eq!(hands.len(), 2);
    let (right, left) = (hands[0].sample(0.5), hands[1].sample(0.5));
    assert!((right.tip_m - Vector3::new(0.01, 0.1, -0.02)).norm() < 1e-15);
    assert!((left.tip_m - Vector3::new(-0.04, 0.11, 0.0)).norm() < 1e-15);
    assert_eq!((right.buttons, left.buttons), (0, 1));
    assert_eq!(hands[1].sample(1.0).buttons, 0);
    let message = Trajectory::load(&path).unwrap_err().to_string();
    assert!(
        message.contains("2 hand(s)") && message.contains("has 1"),
        "{message}"
    );
    let again = write("hands-again.csv", "");
    Trajectory::save_hands(&again, &hands).unwrap();
    assert_eq!(Trajectory::load_hands(&again).unwrap(), hands);
    let bad = write(
        "hands-bad.csv",
        "time_s,x_m,y_m,z_m,left_x_m,left_y_m,left_z_m\n0,0,0,0,0,0,0\n0.5,0,0,0,0,nan,0\n",
    );
    let message = Trajectory::load_hands(&bad).unwrap_err().to_string();
    assert!(
        message.contains("line 3") && message.contains("not finite"),
        "{message}"
    );
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

/// A driver's figure over the product's 20 N ceiling is held to it, with a warning naming the
/// device and both figures; one within it passes as it is, without a warning.
#[test]
fn a_reported_peak_is_held_to_the_ceiling() {
    let (held, warning) = DeviceLimits::peak_only(100.0).within_ceiling("Fake Touch");
    assert_eq!(held.peak_force_n, MAX_FORCE_LIMIT_N);
    assert_eq!(held.continuous_force_n, MAX_FORCE_LIMIT_N);
    let warning = warning.unwrap();
    assert!(
        warning.contains("Fake Touch") && warning.contains("100.0 N"),
        "{warning}"
    );
    assert!(warning.contains("20 N"), "{warning}");
    let touch = DeviceLimits::touch();
    assert_eq!(touch.within_ceiling("Touch"), (touch, None));
}

/// The filter at `force_n` along z, reached at the rate limit under `settings`.
fn filter_at(settings: SafetySettings, force_n: f64) -> SafetyFilter {
    let mut filter = SafetyFilter::new(settings, DeviceLimits::peak_only(10.0));
    let desired = Vector3::new(0.0, 0.0, force_n);
    (0..1000).for_each(|_| {
        filter.filter(&desired, &[]);
    });
    filter
}

/// A scene with a 0.5 N limit after one sending 3 N: the first tick under the new settings
/// sends no more than 0.5 N (not 140 ms of 20 mN steps down); a fade begun above the new limit
/// fades from the limit. A raised limit moves at the rate limit, as within a scene.
#[test]
fn a_lowered_limit_bites_within_one_tick() {
    let strong = SafetySettings::default();
    let weak = SafetySettings {
        max_force_n: 0.5,
        ..strong
    };
    let pressing = Vector3::new(0.0, 0.0, 3.0);
    let mut filter = filter_at(strong, 3.0);
    filter.retune(weak, DeviceLimits::peak_only(10.0));
    let sent = filter.filter(&pressing, &[]);
    assert!(sent.norm() <= 0.5 * (1.0 + 1e-12), "{sent:?}");
    let mut fading = filter_at(strong, 3.0);
    fading.filter(&pressing, &[Fault::NonFiniteDevice]);
    fading.retune(weak, DeviceLimits::peak_only(10.0));
    let sent = fading.filter(&pressing, &[Fault::NonFiniteDevice]);
    assert!(sent.norm() <= 0.5 * (1.0 + 1e-12), "{sent:?}");
    let mut raised = filter_at(weak, 3.0);
    raised.retune(strong, DeviceLimits::peak_only(10.0));
    let sent = raised.filter(&pressing, &[]);
    assert!((sent.norm() - (0.5 + strong.max_change_n_per_tick)).abs() < 1e-12);
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

/// No force limit can turn the force against the hand: a negative, non-finite or too large
/// limit is refused by the settings' check (naming the field, the value and the range) and by
/// a haptic loop built on it; a filter given one anyway (bypassing the check) sends nothing,
/// never a reversed force or a NaN, whatever is asked of it.
#[test]
fn no_force_limit_can_reverse_the_force() {
    for bad in [-1.0, -1e-9, f64::NAN, f64::INFINITY, 20.5] {
        let settings = SafetySettings {
            max_force_n: bad,
            ..SafetySettings::default()
        };
        let e = settings.check().unwrap_err();
        assert!(e.contains("max_force_n") && e.contains("0 to 20 N"), "{e}");
        let scene = HapticScene {
            safety: settings,
            ..HapticScene::without_organs()
        };
        let device = Box::new(Scripted::new("still", Trajectory::default()));
        let refused = HapticLoop::new(&scene, device).err().unwrap().to_string();
        assert!(refused.contains("max_force_n"), "{refused}");
        let mut filter = SafetyFilter::new(settings, DeviceLimits::touch());
        for desired in [Vector3::new(10.0, 0.0, 0.0), Vector3::zeros()] {
            for _ in 0..500 {
                let sent = filter.filter(&desired, &[]);
                assert!(sent.iter().all(|c| c.is_finite()), "limit {bad}: {sent:?}");
                assert!(sent.dot(&desired) >= 0.0, "limit {bad} reversed: {sent:?}");
                match bad > 0.0 && bad.is_finite() {
                    // Too large to set, yet not one to reverse: the device's peak holds.
                    true => assert!(sent.norm() <= DeviceLimits::touch().peak_force_n),
                    false => assert_eq!(sent, Vector3::zeros(), "limit {bad}: {sent:?}"),
                }
            }
        }
    }
    let rate = SafetySettings {
        max_change_n_per_tick: -0.02,
        ..SafetySettings::default()
    };
    assert!(rate.check().unwrap_err().contains("max_change_n_per_tick"));
    assert!(SafetySettings::default().check().is_ok());
}

/// The command line refuses a force limit or a duration that is not one before anything runs:
/// exit 2, no panic, the option, the value and the range named.
#[test]
fn the_trainer_refuses_limits_that_are_not_ones() {
    let cases = [
        ("--max-force-n=-1", "0 to 20 N"),
        ("--max-force-n=NaN", "0 to 20 N"),
        ("--max-force-n=25", "0 to 20 N"),
        ("--exit-after-s=-1", "more than 0"),
        ("--screenshot-after-s=inf", "0 or more"),
    ];
    for (option, range) in cases {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_trainer"))
            .args(["--headless", "--coarse", option, "--json"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let (name, value) = option.split_once('=').unwrap();
        assert_eq!(out.status.code(), Some(2), "{option}: {stderr}");
        assert!(stderr.contains(name) && stderr.contains(value), "{stderr}");
        assert!(
            stderr.contains(range) && !stderr.contains("panicked"),
            "{stderr}"
        );
        assert!(out.stdout.is_empty(), "{option} ran");
    }
}

/// The guard at the device's edge, apart from the filter: a force within the peak passes as
/// it is; one over it is brought to the peak along itself and refused; a non-finite one is
/// zero and refused; a device whose peak is not a positive number renders nothing.
#[test]
fn the_edge_guard_passes_clamps_or_zeroes() {
    let within = Vector3::new(0.0, 0.6, 0.8);
    assert_eq!(
        EdgeForce::guard(&within, 3.3),
        (EdgeForce::guard(&within, 3.3).0, None)
    );
    assert_eq!(*EdgeForce::guard(&within, 3.3).0.newtons(), within);
    let (clamped, refusal) = EdgeForce::guard(&(within * 100.0), 3.3);
    assert!((clamped.newtons() - within * 3.3).norm() < 1e-12);
    assert_eq!(
        refusal,
        Some(EdgeRefusal::OverPeak {
            asked_n: 100.0,
            peak_n: 3.3
        })
    );
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let (zero, refusal) = EdgeForce::guard(&Vector3::new(0.1, bad, 0.0), 3.3);
        assert_eq!(
            (zero, refusal),
            (EdgeForce::ZERO, Some(EdgeRefusal::NonFinite))
        );
    }
    for peak in [-3.3, f64::NAN, 0.0] {
        let (sent, _) = EdgeForce::guard(&within, peak);
        assert_eq!(*sent.newtons(), Vector3::zeros(), "peak {peak}");
    }
}

/// The recorder guards what it passes on too, and the device it wraps again: 100 N asked of
/// a recorded mouse (3.3 N peak) reaches it as 3.3 N, a NaN as zero, each with its refusal.
#[test]
fn the_recorder_guards_what_it_passes_on() {
    let (mouse, handle) = VirtualDevice::new(&Vector3::zeros());
    let path = std::env::temp_dir().join(format!("{}-guarded.csv", std::process::id()));
    let mut recorded = Recorder::new(Box::new(mouse), &path);
    let over = recorded
        .write_force(&Vector3::new(0.0, 0.0, 100.0))
        .unwrap_err();
    assert!(
        over.to_string().contains("over the device's 3.300 N peak"),
        "{over}"
    );
    assert!((handle.force_n() - Vector3::new(0.0, 0.0, 3.3)).norm() < 1e-12);
    let nan = recorded
        .write_force(&Vector3::new(f64::NAN, 0.0, 0.0))
        .unwrap_err();
    assert!(nan.to_string().contains("not finite"), "{nan}");
    assert_eq!(handle.force_n(), Vector3::zeros());
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
