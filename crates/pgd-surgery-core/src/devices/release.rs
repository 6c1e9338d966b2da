//! Zero force on every way out of the program. A hardware backend registers what releases its
//! device (zero force, its servo stopped, the device closed); a panic on any thread and
//! SIGINT, SIGTERM or SIGHUP release every registered device before anything else happens,
//! and a backend's own `Drop` releases it on the ordinary ways out (the window closing, the
//! run ending, an error returned). Releasing is idempotent: whichever comes first does it.
//!
//! On a panic or a signal every servo link is halted first, without any lock
//! ([`super::halt_every_link`]): from its next frame no servo renders force, even while
//! another thread holds the registry. The release proper (servo stopped, device closed)
//! follows as soon as the registry is free, waiting for it a bounded time. The servo's
//! watchdog zeroes a stale command within 10 ms whatever the program does; the release is what
//! hands the device back to its driver.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, TryLockError, Weak};
use std::time::{Duration, Instant};

/// What releases one open device: zero force, its servo stopped, the device closed. Called
/// from any thread, possibly while the haptic loop is still using the device; every call after
/// the first does nothing.
pub trait Release: Send + Sync {
    fn release(&self);
}

/// The devices open now, weakly: a device closed in the ordinary way leaves its entry dead.
static OPEN: Mutex<Vec<Weak<dyn Release>>> = Mutex::new(Vec::new());

/// Set by a termination signal: the run should end as soon as it can (after the devices have
/// been released).
static STOP_REQUESTED: AtomicBool = AtomicBool::new(false);

/// Keeps `device` among the devices released on a panic or a signal, for as long as it lives.
pub fn register(device: &Arc<dyn Release>) {
    let mut open = OPEN.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    open.retain(|entry| entry.strong_count() > 0);
    open.push(Arc::downgrade(device));
}

/// How long a panic or a signal waits for another thread to let go of the registry before it
/// gives the release up (the links are halted already).
const REGISTRY_WAIT: Duration = Duration::from_millis(200);

/// Releases every registered device that is still open; how many there were. Waits for the
/// registry up to [`REGISTRY_WAIT`] while another thread holds it (`None` if it never came
/// free: a panic inside a release, on the thread holding it, must not deadlock).
pub fn release_all() -> Option<usize> {
    let open = registry_within(REGISTRY_WAIT)?;
    let devices: Vec<Arc<dyn Release>> = open.iter().filter_map(Weak::upgrade).collect();
    drop(open);
    devices.iter().for_each(|device| device.release());
    Some(devices.len())
}

/// The registry, once it is free, if that is within `wait`.
fn registry_within(wait: Duration) -> Option<MutexGuard<'static, Vec<Weak<dyn Release>>>> {
    let give_up = Instant::now() + wait;
    loop {
        match OPEN.try_lock() {
            Ok(open) => return Some(open),
            Err(TryLockError::Poisoned(poisoned)) => return Some(poisoned.into_inner()),
            Err(TryLockError::WouldBlock) if Instant::now() >= give_up => return None,
            Err(TryLockError::WouldBlock) => std::thread::sleep(Duration::from_micros(100)),
        }
    }
}

/// Holds the registry for `duration` on the calling thread: how the tests show that a panic
/// or a signal zeroes every device while another thread holds it.
#[doc(hidden)]
pub fn hold_registry_for(duration: Duration) {
    let _open = OPEN.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    std::thread::sleep(duration);
}

/// Every link halted at once, then every device released: what a panic and a signal do.
#[cfg(not(target_arch = "wasm32"))]
fn halt_and_release_all() -> Option<usize> {
    super::halt_every_link();
    release_all()
}

/// Whether a termination signal asked the run to end.
pub fn stop_requested() -> bool {
    STOP_REQUESTED.load(Ordering::Acquire)
}

/// Installs, once per process, the panic hook and the signal handler that release every open
/// device. The hook then runs the one it replaced (which prints the panic); the handler asks
/// the run to stop ([`stop_requested`]) and calls `on_stop` (the window closes as its close
/// button would, so that the attempt is still scored and kept). A second signal ends the
/// process at once.
#[cfg(not(target_arch = "wasm32"))]
pub fn install_exit_guards(on_stop: fn()) -> Result<(), String> {
    static INSTALLED: std::sync::Once = std::sync::Once::new();
    let mut result = Ok(());
    INSTALLED.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if halt_and_release_all().is_none() {
                eprintln!(
                    "trainer: the device registry stayed locked: every servo halted at zero \
                     force, the devices not released"
                );
            }
            previous(info);
        }));
        result = ctrlc::set_handler(move || on_termination_signal(on_stop))
            .map_err(|e| format!("cannot handle SIGINT and SIGTERM: {e}"));
    });
    result
}

/// The signal handler (ctrlc runs it on a thread of its own, not in the signal's context).
#[cfg(not(target_arch = "wasm32"))]
fn on_termination_signal(on_stop: fn()) {
    let released = halt_and_release_all();
    if STOP_REQUESTED.swap(true, Ordering::AcqRel) {
        eprintln!("trainer: a second signal: stopping at once");
        std::process::exit(130);
    }
    match released {
        Some(released) => eprintln!(
            "trainer: signal received: {released} device(s) released at zero force; stopping \
             (a second signal stops at once)"
        ),
        None => eprintln!(
            "trainer: signal received: every servo halted at zero force (the device registry \
             stayed locked); stopping (a second signal stops at once)"
        ),
    }
    on_stop();
}
