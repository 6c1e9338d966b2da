//! The Force Dimension backend against a fake dhd library (`fake_dhd.c`): our servo thread
//! reads the end effector the test places and sends the forces the fake records.

use std::path::Path;
use std::time::{Duration, Instant};

use nalgebra::Vector3;
use pgd_surgery::app::haptic::HapticLoop;
use pgd_surgery::devices::{ForceDimension, HapticDevice, SafetySettings};

use crate::common::target;

use crate::fakes::{
    assert_each_device_renders_its_hand, assert_edge_guarded, assert_faded, assert_held_to_ceiling,
    assert_left_alone_faded, assert_watchdog_held, press_then_fault, pressing_at, pressing_tip_m,
    tick_hands,
};
use crate::two_hands::{APART_M, left_target, two_hands};
use crate::vendor_fake::VendorFake;

/// This test's own copy of the fake dhd library, and its controls.
struct Fake(VendorFake);

impl Fake {
    fn new(test: &str) -> Self {
        Self(VendorFake::new("fake_dhd", test))
    }

    /// Places the end effector at `m` in the device's frame (x towards the user, y right, z up).
    fn set_effector(&self, m: [f64; 3], buttons: u32) {
        let f = self
            .0
            .call::<unsafe extern "C" fn(f64, f64, f64, u32)>("fake_dhd_set_effector");
        // SAFETY: plain values.
        unsafe { f(m[0], m[1], m[2], buttons) };
    }

    /// Places device `id`'s end effector so that the tool's tip is at `tip_m` in the scene.
    fn place_tip(&self, id: i32, tip_m: &Vector3<f64>) {
        let f = self
            .0
            .call::<unsafe extern "C" fn(i32, f64, f64, f64, u32)>("fake_dhd_set_effector_of");
        // SAFETY: plain values. The scene's (x, y, z) is the device's (−y, x, z).
        unsafe { f(id, -tip_m.y, tip_m.x, tip_m.z, 0) };
    }

    fn last_force(&self) -> Vector3<f64> {
        self.0.vector("fake_dhd_last_force")
    }

    /// The force last sent to device `id`, in the device's frame.
    fn last_force_of(&self, id: i32) -> Vector3<f64> {
        let f = self
            .0
            .call::<unsafe extern "C" fn(i32, *mut f64)>("fake_dhd_last_force_of");
        let mut out = [0.0; 3];
        // SAFETY: room for three doubles.
        unsafe { f(id, out.as_mut_ptr()) };
        Vector3::from(out)
    }

    fn open(&self) -> Result<ForceDimension, String> {
        self.open_index(None)
    }

    /// Opens the device at `index` in the SDK's list (the first available without).
    fn open_index(&self, index: Option<u8>) -> Result<ForceDimension, String> {
        ForceDimension::open(Some(&self.0.path), index).map_err(|e| e.to_string())
    }

    fn wait_frames(&self, frames: i64) {
        self.0.wait("fake_dhd_frames", frames);
    }

    /// A control taking one int.
    fn control(&self, name: &str, value: i32) {
        // SAFETY: a plain value.
        unsafe { self.0.call::<unsafe extern "C" fn(i32)>(name)(value) };
    }

    /// A control taking a device's ID and one int.
    fn control_of(&self, name: &str, id: i32, value: i32) {
        // SAFETY: plain values.
        unsafe { self.0.call::<unsafe extern "C" fn(i32, i32)>(name)(id, value) };
    }
}

/// No library, or no device: one message each, naming what is missing.
#[test]
fn a_missing_library_or_device_is_named() {
    let error = ForceDimension::open(Some(Path::new("/nowhere/libdhd.so")), None)
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("/nowhere/libdhd.so") && error.contains("Force Dimension SDK"));
    assert!(error.contains("PGD_FORCEDIMENSION_LIB"), "{error}");
    let fake = Fake::new("absent");
    // SAFETY: a plain value.
    fake.control("fake_dhd_set_absent", 1);
    let error = fake.open().err().unwrap();
    eprintln!("{error}");
    assert!(error.contains("no device found"), "{error}");
}

/// The effector at (10, 20, 30) mm in the device's frame (x towards the user, y right, z up) is
/// the tool at (20, −10, 30) mm in the scene's; (1, 2, 3) N in the scene is sent as
/// (−2, 1, 3) N; the peak is the SDK's force limit (the fake's 9.5 N); force output enabled.
#[test]
fn the_servo_reads_the_effector_and_sends_the_force_in_the_devices_frame() {
    let fake = Fake::new("frames");
    fake.set_effector([0.010, 0.020, 0.030], 2);
    let mut device = fake.open().unwrap();
    assert_eq!(fake.0.int("fake_dhd_force_enabled"), 1);
    fake.wait_frames(3);
    let sample = device.read(0.0).unwrap();
    assert!((sample.tip_m - Vector3::new(0.020, -0.010, 0.030)).norm() < 1e-12);
    assert_eq!(sample.buttons, 2);
    assert_eq!(device.limits().peak_force_n, 9.5);
    device.write_force(&Vector3::new(1.0, 2.0, 3.0)).unwrap();
    fake.wait_frames(3);
    assert_eq!(fake.last_force(), Vector3::new(-2.0, 1.0, 3.0));
}

/// The haptic loop over the fake, the effector 4 mm into the liver: pushed back, no fault. An
/// SDK error mid-run fades the force to zero within 5 ticks, the log gives the SDK's words.
#[test]
fn an_sdk_error_mid_run_fades_the_force_to_zero() {
    let fake = Fake::new("error");
    let tip = pressing_tip_m();
    // The scene's (x, y, z) is the device's (−y, x, z).
    fake.set_effector([-tip.y, tip.x, tip.z], 0);
    let inject = || fake.control("fake_dhd_inject_error", 7);
    let run = press_then_fault(
        Box::new(fake.open().unwrap()),
        || fake.wait_frames(1),
        inject,
    );
    assert_faded(&run, "communication error");
}

/// No NaN and nothing over the device's 9.5 N peak reaches `dhdSetForce`.
#[test]
fn the_last_guard_keeps_nan_and_excess_from_the_device() {
    let fake = Fake::new("edge");
    let mut device = fake.open().unwrap();
    assert_edge_guarded(&mut device, &fake.0, "fake_dhd");
}

/// The loop stops commanding: the servo sends zero once the last command is older than the
/// watchdog's 10 ms, measured in the servo's own frames (their spacing is the machine's
/// business); closed, the device is left at zero force and closed.
#[test]
fn a_stalled_loop_and_closing_leave_zero_force() {
    let fake = Fake::new("stall");
    let mut device = fake.open().unwrap();
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    fake.wait_frames(2);
    assert_eq!(fake.last_force(), Vector3::new(0.0, 0.0, 1.0));
    let commanded = Instant::now();
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    while fake.last_force() != Vector3::zeros() {
        assert!(commanded.elapsed() < Duration::from_secs(5), "never zeroed");
        std::thread::sleep(Duration::from_micros(100));
    }
    assert_watchdog_held(device.link(), commanded.elapsed().as_secs_f64());
    device.write_force(&Vector3::new(1.0, 0.0, 0.0)).unwrap();
    fake.wait_frames(3);
    assert_ne!(fake.last_force(), Vector3::zeros());
    drop(device);
    assert_eq!(fake.last_force(), Vector3::zeros());
    assert_eq!(fake.0.int("fake_dhd_closed"), 1);
}

/// The SDK cannot enable force output: the error gives the SDK's words, and the device opened
/// is closed before it is returned.
#[test]
fn a_device_whose_force_cannot_be_enabled_is_closed() {
    let fake = Fake::new("refuse-force");
    fake.control("fake_dhd_refuse_force", 1);
    let error = fake.open().err().unwrap();
    eprintln!("{error}");
    assert!(error.contains("cannot enable force output"), "{error}");
    assert!(error.contains("communication error"), "{error}");
    assert_eq!(fake.0.int("fake_dhd_closed"), 1);
}

/// `dhdSetForce` failing mid-run is a device fault: the force fades to zero within 5 ticks and
/// the log gives the SDK's words.
#[test]
fn a_failed_send_mid_run_fades_the_force_to_zero() {
    let fake = Fake::new("send-error");
    let tip = pressing_tip_m();
    fake.set_effector([-tip.y, tip.x, tip.z], 0);
    let run = press_then_fault(
        Box::new(fake.open().unwrap()),
        || fake.wait_frames(1),
        || fake.control("fake_dhd_fail_set_force", 7),
    );
    assert_faded(&run, "communication error");
}

/// A driver reporting a 100 N limit is held to the product's 20 N ceiling: the device's peak
/// is 20 N, and a 100 N command reaches `dhdSetForce` as 20 N.
#[test]
fn a_driver_reporting_100_n_is_held_to_the_ceiling() {
    let fake = Fake::new("100-newtons");
    // SAFETY: a plain value.
    unsafe {
        fake.0
            .call::<unsafe extern "C" fn(f64)>("fake_dhd_set_max_force")(100.0)
    };
    let mut device = fake.open().unwrap();
    assert_held_to_ceiling(&mut device, &fake.0, "fake_dhd");
}

/// Two devices by index, one a hand, both pressing the liver 35 mm apart: each device is sent
/// its own hand's force (the scene's force in the device's axes, to 1e-12 N), both push back;
/// an SDK error on device 1 fades the left hand to zero within the filter's ticks and names
/// it, while device 0 goes on being sent the right hand's force. An index past the devices
/// connected is refused, saying how many there are.
#[test]
fn two_devices_by_index_each_serve_their_own_hand() {
    let fake = Fake::new("two-devices");
    fake.control("fake_dhd_set_connected", 2);
    let missing = fake.open_index(Some(2)).err().unwrap();
    assert!(
        missing.contains("no device 2: the SDK finds 2"),
        "{missing}"
    );
    let targets = [target(), left_target(APART_M)];
    for (id, t) in targets.iter().enumerate() {
        fake.place_tip(id as i32, &pressing_at(t));
    }
    let devices: Vec<Box<dyn HapticDevice>> = [0, 1]
        .map(|index| Box::new(fake.open_index(Some(index)).unwrap()) as Box<dyn HapticDevice>)
        .into();
    assert!(devices[1].name().ends_with("(1)"), "{}", devices[1].name());
    let mut haptic = HapticLoop::with_devices(&two_hands(), devices).unwrap();
    let frame = || fake.wait_frames(2);
    // The device's (x, y, z) is the scene's (−y, x, z), forces as positions.
    let in_scene = |hand: usize| {
        let f = fake.last_force_of(hand as i32);
        Vector3::new(f.y, -f.x, f.z)
    };
    let sent = tick_hands(&mut haptic, 0..400, frame);
    assert_each_device_renders_its_hand(&sent, &targets, in_scene);
    assert!((sent[0] - sent[1]).norm() > 1e-3, "the hands feel apart");
    fake.control_of("fake_dhd_inject_error_of", 1, 7);
    let fade = SafetySettings::default().fade_ticks as u64;
    let sent = tick_hands(&mut haptic, 400..405 + fade, frame);
    assert_left_alone_faded(&haptic, &sent, &targets[0], "communication error");
    assert!((in_scene(0) - sent[0]).norm() < 1e-12);
}
