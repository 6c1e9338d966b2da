//! Zero force on every way out, against the vendor fakes: a panic on a thread that does not hold
//! the device, a panic inside the haptic schedule, a panic while another thread holds the
//! device registry, and SIGTERM and SIGINT each leave the fake at zero force with its device
//! released. Each runs in a process of its own (this test
//! binary run again on that one test), since the panic hook and the signal handler are the
//! process's, and would release the devices of tests running beside it.

use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{HapticLoop, HapticScene, HapticThread, Scheduling};
use pgd_surgery::devices::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, ForceDimension, HapticDevice, OpenHaptics,
    TimerMode, hold_registry_for, install_exit_guards, stop_requested,
};

use crate::vendor_fake::VendorFake;

/// The environment variable naming the one test a child process runs for real.
const CHILD: &str = "PGD_EXIT_TEST_CHILD";

/// Runs `body` in a child process of this test binary (filtered to the test `name`), and
/// fails with the child's output unless it passed.
fn in_own_process(name: &str, body: impl FnOnce()) {
    if std::env::var(CHILD).as_deref() == Ok(name) {
        body();
        return;
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([&format!("exits::{name}"), "--exact", "--nocapture"])
        .env(CHILD, name)
        .output()
        .unwrap();
    let output = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{output}");
    assert!(out.status.success(), "the child failed: {output}");
    assert!(
        output.contains("1 passed"),
        "the child ran no test: {output}"
    );
}

/// The fake HD library's copy for `test`, a device open on it commanding 1 N.
fn touch_pressing(test: &str) -> (VendorFake, OpenHaptics) {
    let fake = VendorFake::new("fake_hd", test);
    let mut device = OpenHaptics::open(Some(&fake.path), None).unwrap();
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    fake.wait("fake_hd_frames", 3);
    assert_ne!(fake.vector("fake_hd_last_force"), Vector3::zeros());
    (fake, device)
}

/// The fake Force Dimension library's copy for `test`, a device open on it commanding 1 N.
fn omega_pressing(test: &str) -> (VendorFake, ForceDimension) {
    let fake = VendorFake::new("fake_dhd", test);
    let mut device = ForceDimension::open(Some(&fake.path), None).unwrap();
    device.write_force(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
    fake.wait("fake_dhd_frames", 3);
    assert_ne!(fake.vector("fake_dhd_last_force"), Vector3::zeros());
    (fake, device)
}

/// The HD fake shows zero force, its scheduler stopped and the device disabled.
fn assert_touch_released(fake: &VendorFake) {
    assert_eq!(fake.vector("fake_hd_last_force"), Vector3::zeros());
    assert_eq!(fake.int("fake_hd_running"), 0, "the scheduler still runs");
    assert_eq!(
        fake.int("fake_hd_disabled"),
        1,
        "the device was not disabled"
    );
}

/// The dhd fake shows zero force and the device closed.
fn assert_omega_released(fake: &VendorFake) {
    assert_eq!(fake.vector("fake_dhd_last_force"), Vector3::zeros());
    assert_eq!(fake.int("fake_dhd_closed"), 1, "the device was not closed");
}

/// A panic on a thread that does not hold the devices (the window's, a worker's): the hook
/// releases both while the test still holds them, and dropping them afterwards is harmless.
#[test]
fn a_panic_on_any_thread_releases_every_device() {
    in_own_process("a_panic_on_any_thread_releases_every_device", || {
        let (touch_fake, touch) = touch_pressing("panic-elsewhere");
        let (omega_fake, omega) = omega_pressing("panic-elsewhere");
        install_exit_guards(|| {}).unwrap();
        let panicked = std::thread::spawn(|| panic!("a bug on another thread")).join();
        assert!(panicked.is_err());
        assert_touch_released(&touch_fake);
        assert_omega_released(&omega_fake);
        drop((touch, omega));
        assert_touch_released(&touch_fake);
    });
}

/// A device whose read panics from `after_s` on: a bug inside the haptic schedule. The device
/// itself is shared with the test, as a window or a recorder could hold it, so that unwinding
/// the haptic thread does not drop it: only the panic hook can release it.
struct PanicsInTheSchedule {
    inner: Arc<Mutex<OpenHaptics>>,
    after_s: f64,
}

impl PanicsInTheSchedule {
    fn device(&self) -> MutexGuard<'_, OpenHaptics> {
        self.inner
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

impl HapticDevice for PanicsInTheSchedule {
    fn name(&self) -> &str {
        "panics in the schedule"
    }

    fn limits(&self) -> DeviceLimits {
        self.device().limits()
    }

    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError> {
        assert!(time_s < self.after_s, "a bug inside the haptic schedule");
        self.device().read(time_s)
    }

    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.device().write_force(force.newtons())
    }
}

/// A system of the 1 kHz schedule panics on the haptic thread while the device is held
/// elsewhere too; whether it was released (its scheduler stopped, the device disabled) by the
/// time the thread has ended, with the exit guards installed or not. Stopping the thread hands
/// the panic on either way.
fn panic_in_the_schedule(test: &str, guarded: bool) -> bool {
    let (fake, touch) = touch_pressing(test);
    if guarded {
        install_exit_guards(|| {}).unwrap();
    }
    let shared = Arc::new(Mutex::new(touch));
    let device = Box::new(PanicsInTheSchedule {
        inner: shared.clone(),
        after_s: 0.05,
    });
    let haptic = HapticLoop::new(&HapticScene::without_organs(), device).unwrap();
    let thread = HapticThread::spawn(haptic, TimerMode::default(), Scheduling::Normal).unwrap();
    let give_up = Instant::now() + Duration::from_secs(2);
    while fake.int("fake_hd_disabled") == 0 && Instant::now() < give_up {
        std::thread::sleep(Duration::from_millis(1));
    }
    let stopped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| thread.stop()));
    assert!(stopped.is_err(), "the thread's panic is handed on");
    let released = fake.int("fake_hd_disabled") == 1;
    if released {
        assert_touch_released(&fake);
    }
    drop(shared);
    assert_touch_released(&fake);
    released
}

/// A panic inside the haptic schedule releases the device at once, though another part of the
/// program still holds it: the panic hook's work.
#[test]
fn a_panic_inside_the_haptic_schedule_releases_the_device() {
    let name = "a_panic_inside_the_haptic_schedule_releases_the_device";
    in_own_process(name, || {
        assert!(panic_in_the_schedule("panic-in-schedule", true));
    });
}

/// The same panic without the exit guards leaves the device open until its holder lets go:
/// the test above passes because of the hook, not because unwinding drops the device.
#[test]
fn without_the_hook_a_panic_in_the_schedule_leaves_the_device_open() {
    let name = "without_the_hook_a_panic_in_the_schedule_leaves_the_device_open";
    in_own_process(name, || {
        assert!(!panic_in_the_schedule("panic-unguarded", false));
    });
}

/// Another thread holds the device registry for a second when a panic comes, while the haptic
/// loop goes on commanding 1 N every millisecond: every servo renders zero at once all the
/// same (the links are halted without the registry), and the devices are released once it is
/// free.
#[test]
fn a_panic_zeroes_every_device_while_the_registry_is_held() {
    let name = "a_panic_zeroes_every_device_while_the_registry_is_held";
    in_own_process(name, || {
        let (touch_fake, touch) = touch_pressing("registry-held");
        let (omega_fake, omega) = omega_pressing("registry-held");
        install_exit_guards(|| {}).unwrap();
        let commanding = Arc::new(AtomicBool::new(true));
        let commander = command_every_millisecond(touch, omega, commanding.clone());
        let holder = std::thread::spawn(|| hold_registry_for(Duration::from_secs(1)));
        std::thread::sleep(Duration::from_millis(50));
        let panicked = std::thread::spawn(|| panic!("a bug on another thread")).join();
        assert!(panicked.is_err());
        touch_fake.wait("fake_hd_frames", 3);
        omega_fake.wait("fake_dhd_frames", 3);
        assert!(
            !holder.is_finished(),
            "the registry was let go too soon for the test"
        );
        assert_eq!(touch_fake.vector("fake_hd_last_force"), Vector3::zeros());
        assert_eq!(omega_fake.vector("fake_dhd_last_force"), Vector3::zeros());
        holder.join().unwrap();
        commanding.store(false, Ordering::Relaxed);
        let (touch, omega) = commander.join().unwrap();
        drop((touch, omega));
        assert_touch_released(&touch_fake);
        assert_omega_released(&omega_fake);
    });
}

/// A thread commanding 1 N on both devices every millisecond while `commanding` holds; it
/// hands the devices back when it ends.
fn command_every_millisecond(
    mut touch: OpenHaptics,
    mut omega: ForceDimension,
    commanding: Arc<AtomicBool>,
) -> JoinHandle<(OpenHaptics, ForceDimension)> {
    std::thread::spawn(move || {
        while commanding.load(Ordering::Relaxed) {
            let _ = touch.write_force(&Vector3::new(0.0, 0.0, 1.0));
            let _ = omega.write_force(&Vector3::new(0.0, 0.0, 1.0));
            std::thread::sleep(Duration::from_millis(1));
        }
        (touch, omega)
    })
}

/// `signal` (SIGTERM as `kill` or a session's end sends it, SIGINT as Ctrl-C does): the
/// handler releases both devices at zero force while the program still holds them, and asks
/// the run to stop.
fn a_signal_releases_every_device(signal: &str) {
    let (touch_fake, _touch) = touch_pressing(signal);
    let (omega_fake, _omega) = omega_pressing(signal);
    install_exit_guards(|| {}).unwrap();
    let pid = std::process::id().to_string();
    let sent = Command::new("kill").args([signal, &pid]).status().unwrap();
    assert!(sent.success());
    let give_up = Instant::now() + Duration::from_secs(5);
    while !stop_requested() && Instant::now() < give_up {
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(stop_requested(), "the signal was not handled");
    assert_touch_released(&touch_fake);
    assert_omega_released(&omega_fake);
}

#[test]
fn a_termination_signal_releases_every_device_and_asks_to_stop() {
    let name = "a_termination_signal_releases_every_device_and_asks_to_stop";
    in_own_process(name, || a_signal_releases_every_device("-TERM"));
}

#[test]
fn an_interrupt_releases_every_device_and_asks_to_stop() {
    let name = "an_interrupt_releases_every_device_and_asks_to_stop";
    in_own_process(name, || a_signal_releases_every_device("-INT"));
}
