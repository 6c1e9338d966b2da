//! The OpenHaptics backend against a fake HD library (`fake_hd.c`): a scheduler thread at
//! 1 kHz, a stylus the test places, the forces the servo renders recorded.

use std::path::Path;
use std::time::{Duration, Instant};

use bevy::ecs::entity::Entity;
use nalgebra::Vector3;
use pgd_surgery::app::haptic::{Device, FaultLog, HandIndex, HapticLoop, HapticThread, Scheduling};
use pgd_surgery::devices::{HapticDevice, OpenHaptics, SafetySettings, TimerMode};

use crate::common::{TIP_RADIUS_M, scene, target};
use crate::fakes::{
    assert_each_device_renders_its_hand, assert_edge_guarded, assert_faded, assert_held_to_ceiling,
    assert_left_alone_faded, assert_watchdog_held, press_then_fault, pressing_at, pressing_tip_m,
    tick_hands,
};
use crate::two_hands::{APART_M, left_target, two_hands};
use crate::vendor_fake::VendorFake;

/// This test's own copy of the fake HD library, and its controls.
struct Fake(VendorFake);

impl Fake {
    fn new(test: &str) -> Self {
        Self(VendorFake::new("fake_hd", test))
    }

    fn path(&self) -> &Path {
        &self.0.path
    }

    fn set_stylus(&self, mm: [f64; 3], buttons: i32) {
        let f = self
            .0
            .call::<unsafe extern "C" fn(f64, f64, f64, i32)>("fake_hd_set_stylus");
        // SAFETY: plain values.
        unsafe { f(mm[0], mm[1], mm[2], buttons) };
    }

    fn last_force(&self) -> Vector3<f64> {
        self.0.vector("fake_hd_last_force")
    }

    fn flag(&self, name: &str) -> i32 {
        self.0.int(name)
    }

    fn inject_error(&self, code: u32) {
        // SAFETY: a plain value.
        unsafe {
            self.0
                .call::<unsafe extern "C" fn(u32)>("fake_hd_inject_error")(code)
        };
    }

    fn open(&self) -> OpenHaptics {
        OpenHaptics::open(Some(self.path()), None).unwrap()
    }

    /// Places device `handle`'s stylus so that the tool's tip is at `tip_m` in the scene.
    fn place_tip(&self, handle: u32, tip_m: &Vector3<f64>) {
        let f = self
            .0
            .call::<unsafe extern "C" fn(u32, f64, f64, f64, i32)>("fake_hd_set_stylus_of");
        // SAFETY: plain values. The scene's (x, y, z) m is the device's (x, z, −y) mm.
        unsafe { f(handle, tip_m.x * 1e3, tip_m.z * 1e3, -tip_m.y * 1e3, 0) };
    }

    /// The force device `handle` last rendered, in its own frame.
    fn last_force_of(&self, handle: u32) -> Vector3<f64> {
        let f = self
            .0
            .call::<unsafe extern "C" fn(u32, *mut f64)>("fake_hd_last_force_of");
        let mut out = [0.0; 3];
        // SAFETY: room for three doubles.
        unsafe { f(handle, out.as_mut_ptr()) };
        Vector3::from(out)
    }

    /// A control taking a device's handle and returning an int.
    fn flag_of(&self, name: &str, handle: u32) -> i32 {
        // SAFETY: a plain value.
        unsafe { self.0.call::<unsafe extern "C" fn(u32) -> i32>(name)(handle) }
    }

    /// Waits until the fake's scheduler has run `frames` more frames.
    fn wait_frames(&self, frames: i64) {
        self.0.wait("fake_hd_frames", frames);
    }
}

/// A library that is not there: one message naming the file, what to install and the variable
/// that names another file; no panic.
#[test]
fn a_missing_library_is_named_with_how_to_install_it() {
    let error = OpenHaptics::open(Some(Path::new("/nowhere/libHD.so")), None)
        .err()
        .unwrap()
        .to_string();
    eprintln!("{error}");
    assert!(error.contains("/nowhere/libHD.so"), "{error}");
    assert!(error.contains("install OpenHaptics"), "{error}");
    assert!(error.contains("PGD_OPENHAPTICS_LIB"), "{error}");
}

/// A device the library cannot initialize: its HD error, explained.
#[test]
fn a_device_that_fails_to_initialize_says_why() {
    let fake = Fake::new("absent");
    let error = OpenHaptics::open(Some(fake.path()), Some("absent"))
        .err()
        .unwrap()
        .to_string();
    eprintln!("{error}");
    assert!(error.contains("cannot initialize"), "{error}");
    assert!(error.contains("HD_COMM_CONFIG_ERROR"), "{error}");
}

/// The stylus at (10, 20, 30) mm in the device's frame (x right, y up, z towards the user) is
/// the tool at (10, −30, 20) mm in the scene's (z up); a force of (0.5, 1, 1.5) N in the scene
/// is rendered as (0.5, 1.5, −1) N in the device's frame; the limits are the device's own (the
/// fake says 3.0 N peak and 0.75 N continuous).
#[test]
fn the_servo_reads_the_stylus_and_renders_the_force_in_the_devices_frame() {
    let fake = Fake::new("frames");
    fake.set_stylus([10.0, 20.0, 30.0], 1);
    let mut device = fake.open();
    assert_eq!(fake.flag("fake_hd_force_output"), 1);
    fake.wait_frames(3);
    let sample = device.read(0.0).unwrap();
    assert!((sample.tip_m - Vector3::new(0.010, -0.030, 0.020)).norm() < 1e-12);
    assert_eq!(sample.buttons, 1);
    assert!(sample.orientation.angle() < 1e-12);
    let limits = device.limits();
    assert_eq!(
        (limits.peak_force_n, limits.continuous_force_n),
        (3.0, 0.75)
    );
    device.write_force(&Vector3::new(0.5, 1.0, 1.5)).unwrap();
    fake.wait_frames(3);
    assert_eq!(fake.last_force(), Vector3::new(0.5, 1.5, -1.0));
}

/// No NaN and nothing over the device's 3.0 N peak reaches the HD library's force call.
#[test]
fn the_last_guard_keeps_nan_and_excess_from_the_device() {
    let fake = Fake::new("edge");
    let mut device = fake.open();
    assert_edge_guarded(&mut device, &fake.0, "fake_hd");
}

/// A driver reporting a 100 N peak is held to the product's 20 N ceiling: the device's peak is
/// 20 N, and a 100 N command reaches the HD library as 20 N.
#[test]
fn a_driver_reporting_100_n_is_held_to_the_ceiling() {
    let fake = Fake::new("100-newtons");
    // SAFETY: a plain value.
    unsafe {
        fake.0
            .call::<unsafe extern "C" fn(f64)>("fake_hd_set_nominal_max_force")(100.0)
    };
    let mut device = fake.open();
    assert_held_to_ceiling(&mut device, &fake.0, "fake_hd");
}

/// A device the library initializes but reports an error for is released before the error
/// is returned, not left open.
#[test]
fn a_device_that_opens_with_an_error_is_released() {
    let fake = Fake::new("half-open");
    let error = OpenHaptics::open(Some(fake.path()), Some("half-open"))
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("HD_DEVICE_ALREADY_INITIATED"), "{error}");
    assert_eq!(fake.flag("fake_hd_disabled"), 1);
}

/// The haptic loop over the fake, its stylus 4 mm into the liver: the trainee is pushed back,
/// with no fault (the device opens with the servo's first sample in hand). An HD error mid-run
/// is a device fault: the force fades to zero within the filter's 5 ticks, the log names the
/// HD error, and the fake renders zero.
#[test]
fn an_hd_error_mid_run_fades_the_force_to_zero() {
    let fake = Fake::new("error");
    let tip = pressing_tip_m();
    // The scene's (x, y, z) m is the device's (x, z, −y) mm.
    fake.set_stylus([tip.x * 1e3, tip.z * 1e3, -tip.y * 1e3], 0);
    let run = press_then_fault(
        Box::new(fake.open()),
        || fake.wait_frames(1),
        || fake.inject_error(0x0201),
    );
    assert_faded(&run, "HD_EXCEEDED_MAX_FORCE");
    fake.wait_frames(3);
    assert_eq!(fake.last_force(), Vector3::zeros());
}

/// The loop stops commanding (a stall, a panic, a hang): the servo renders zero once the last
/// command is older than the watchdog's 10 ms, measured in the servo's own frames (their
/// spacing is the machine's business, so a loaded machine cannot fail this).
#[test]
fn a_stalled_loop_leaves_the_device_at_zero_force() {
    let fake = Fake::new("stall");
    let mut device = fake.open();
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    fake.wait_frames(2);
    assert_eq!(fake.last_force(), Vector3::new(0.0, 1.0, 0.0));
    let commanded = Instant::now();
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    while fake.last_force() != Vector3::zeros() {
        assert!(commanded.elapsed() < Duration::from_secs(5), "never zeroed");
        std::thread::sleep(Duration::from_micros(100));
    }
    assert_watchdog_held(device.link(), commanded.elapsed().as_secs_f64());
}

/// Dropped (the trainer closing, or unwinding from a panic) while commanding 1 N: the servo is
/// stopped, the last force written is zero, and the device is released.
#[test]
fn closing_leaves_zero_force_and_releases_the_device() {
    let fake = Fake::new("close");
    let mut device = fake.open();
    device.write_force(&Vector3::new(1.0, 0.0, 0.0)).unwrap();
    fake.wait_frames(3);
    assert_eq!(fake.last_force(), Vector3::new(1.0, 0.0, 0.0));
    drop(device);
    assert_eq!(fake.flag("fake_hd_running"), 0);
    assert_eq!(fake.flag("fake_hd_disabled"), 1);
    assert_eq!(fake.last_force(), Vector3::zeros());
}

/// The trainer asked for an OpenHaptics device whose library is missing: it says so on its
/// error stream, with what to install, and exits non-zero without a panic; `trainer devices`
/// lists the backend as unusable with the same reason, and as usable with the fake's path.
#[test]
fn the_trainer_says_what_is_missing_and_lists_what_is_found() {
    let trainer = env!("CARGO_BIN_EXE_trainer");
    let run = |library: &Path, args: &[&str]| {
        std::process::Command::new(trainer)
            .args(args)
            .env("PGD_OPENHAPTICS_LIB", library)
            .output()
            .unwrap()
    };
    let missing = Path::new("/nowhere/libHD.so");
    let headless = [
        "--headless",
        "--realtime",
        "--ticks",
        "10",
        "--device",
        "openhaptics",
    ];
    let out = run(missing, &headless);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stderr}");
    assert!(!out.status.success());
    assert!(stderr.contains("install OpenHaptics"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let listed = |library: &Path| {
        let out = run(library, &["devices"]);
        assert!(out.status.success());
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        stdout
            .lines()
            .find(|l| l.starts_with("openhaptics"))
            .unwrap()
            .to_owned()
    };
    let absent = listed(missing);
    assert!(
        absent.contains(" no ") && absent.contains("install OpenHaptics"),
        "{absent}"
    );
    let fake = Fake::new("listed");
    let found = listed(fake.path());
    eprintln!("{absent}\n{found}");
    assert!(
        found.contains(" yes ") && found.contains("libfake_hd-listed.so"),
        "{found}"
    );
}

/// The round trip through the real schedule: the haptic loop on its 1 kHz thread, the fake's
/// servo on its own. The stylus steps from 5 mm above the liver to 4 mm into it, 40 times; each
/// time, the time until the fake renders a force (polled every 50 µs) is the latency from a
/// position to the force written: a servo frame to read it, a tick to compute, a frame to
/// render. Printed as p50 and p99; the test holds only that every step is answered, within
/// a liveness bound of 200 ms.
#[test]
fn the_force_answers_the_stylus_through_the_real_schedule() {
    let fake = Fake::new("latency");
    let target = target();
    let device_mm = |depth_m: f64| {
        let tip = target.point_m + target.normal * (TIP_RADIUS_M - depth_m);
        [tip.x * 1e3, tip.z * 1e3, -tip.y * 1e3]
    };
    fake.set_stylus(device_mm(-0.005), 0);
    let device = Box::new(fake.open());
    let haptic = HapticLoop::new(&scene(SafetySettings::default()), device).unwrap();
    let thread = HapticThread::spawn(haptic, TimerMode::default(), Scheduling::RealTime).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let mut latencies_ms = Vec::new();
    for _ in 0..40 {
        fake.set_stylus(device_mm(-0.005), 0);
        let give_up = Instant::now() + Duration::from_millis(500);
        while fake.last_force() != Vector3::zeros() && Instant::now() < give_up {
            std::thread::sleep(Duration::from_micros(50));
        }
        std::thread::sleep(Duration::from_millis(20));
        let stepped = Instant::now();
        fake.set_stylus(device_mm(0.004), 0);
        while fake.last_force() == Vector3::zeros()
            && stepped.elapsed() < Duration::from_millis(200)
        {
            std::thread::sleep(Duration::from_micros(50));
        }
        latencies_ms.push(stepped.elapsed().as_secs_f64() * 1e3);
    }
    let (report, haptic) = thread.stop();
    latencies_ms.sort_by(f64::total_cmp);
    let quantile = |q: f64| latencies_ms[((latencies_ms.len() - 1) as f64 * q).round() as usize];
    eprintln!(
        "stylus to force: p50 {:.2} ms, p99 {:.2} ms, largest {:.2} ms over {} steps; tick compute p99 {:.0} µs",
        quantile(0.5),
        quantile(0.99),
        latencies_ms.last().unwrap(),
        latencies_ms.len(),
        report.compute.p99_us
    );
    // Should a step go unanswered, the faults and the thread's timing say why.
    let faults: Vec<String> = haptic
        .hand::<FaultLog>(0)
        .unwrap()
        .log
        .iter()
        .map(|(tick, fault)| format!("tick {tick}: {fault}"))
        .collect();
    assert!(
        latencies_ms.iter().all(|&l| l < 200.0),
        "{latencies_ms:?}\nfaults: {faults:?}\n{report:?}"
    );
}

/// Takes hand `hand`'s device out of the loop.
fn take_device(haptic: &mut HapticLoop, hand: usize) -> Box<dyn HapticDevice> {
    let world = haptic.world_mut();
    let mut hands = world.query::<(Entity, &HandIndex)>();
    let (entity, _) = (hands.iter(world))
        .find(|(_, index)| index.0 == hand)
        .unwrap();
    world.entity_mut(entity).take::<Device>().unwrap().0
}

/// Two Geomagic devices by their configuration names, one a hand, both pressing the liver
/// 35 mm apart through one HD scheduler: each renders its own hand's force (the scene's force
/// in the device's axes, to 1e-12 N); an HD error on the left device fades the left hand
/// alone. Closing the left device ends its servo at zero force and disables it while the
/// scheduler runs on for the right, which goes on rendering; closing the right stops it.
#[test]
fn two_devices_by_name_each_serve_their_own_hand() {
    let fake = Fake::new("two-devices");
    let targets = [target(), left_target(APART_M)];
    let open = |name: &str| OpenHaptics::open(Some(fake.path()), Some(name)).unwrap();
    let (right, left) = (open("RIGHT"), open("LEFT"));
    assert!(left.name().ends_with("(LEFT)"), "{}", left.name());
    for (handle, t) in [1, 2].into_iter().zip(&targets) {
        fake.place_tip(handle, &pressing_at(t));
    }
    fake.wait_frames(3);
    let devices: Vec<Box<dyn HapticDevice>> = vec![Box::new(right), Box::new(left)];
    let mut haptic = HapticLoop::with_devices(&two_hands(), devices).unwrap();
    let frame = || fake.wait_frames(2);
    // The device's (x, y, z) is the scene's (x, z, −y), forces as positions.
    let in_scene = |hand: usize| {
        let f = fake.last_force_of(hand as u32 + 1);
        Vector3::new(f.x, -f.z, f.y)
    };
    let sent = tick_hands(&mut haptic, 0..400, frame);
    assert_each_device_renders_its_hand(&sent, &targets, in_scene);
    let inject = fake
        .0
        .call::<unsafe extern "C" fn(u32, u32)>("fake_hd_inject_error_of");
    // SAFETY: plain values.
    unsafe { inject(2, 0x0201) };
    fake.wait_frames(2);
    let fade = SafetySettings::default().fade_ticks as u64;
    let sent = tick_hands(&mut haptic, 400..405 + fade, frame);
    assert_left_alone_faded(&haptic, &sent, &targets[0], "HD_EXCEEDED_MAX_FORCE");
    let mut right = take_device(&mut haptic, 0);
    drop(take_device(&mut haptic, 1));
    assert_eq!(fake.last_force_of(2), Vector3::zeros());
    assert_eq!(fake.flag_of("fake_hd_disabled_of", 2), 1);
    assert_eq!(fake.flag("fake_hd_running"), 1);
    assert_eq!(fake.flag("fake_hd_scheduled"), 1);
    right.write_force(&Vector3::new(0.0, 0.0, 0.5)).unwrap();
    fake.wait_frames(3);
    assert_eq!(fake.last_force_of(1), Vector3::new(0.0, 0.5, 0.0));
    drop(right);
    assert_eq!(fake.flag("fake_hd_running"), 0);
    assert_eq!(fake.flag_of("fake_hd_disabled_of", 1), 1);
    assert_eq!(fake.last_force_of(1), Vector3::zeros());
}
