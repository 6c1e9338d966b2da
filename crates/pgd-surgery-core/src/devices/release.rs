//! Zero force on every way out of the program. A hardware backend registers what releases its
//! device (zero force, its servo stopped, the device closed); a panic on any thread and
//! SIGINT, SIGTERM or SIGHUP release every registered device before anything else happens,
//! and a backend's own `Drop` releases it on the ordinary ways out (the window closing, the
//! run ending, an error returned). Releasing is idempotent: whichever comes first does it.
//!
//! The servo's watchdog zeroes a stale command within 10 ms whatever the program does; this
//! is what stops the motors at once and hands the device back to its driver.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, TryLockError, Weak};

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

/// Releases every registered device that is still open; how many there were.
pub fn release_all() -> usize {
    // A panic inside a release would find the list locked by this very thread: it is skipped
    // then (the watchdog still zeroes the force), rather than deadlocking.
    let open = match OPEN.try_lock() {
        Ok(open) => open,
        Err(TryLockError::Poisoned(poisoned)) => poisoned.into_inner(),
        Err(TryLockError::WouldBlock) => return 0,
    };
    let devices: Vec<Arc<dyn Release>> = open.iter().filter_map(Weak::upgrade).collect();
    drop(open);
    devices.iter().for_each(|device| device.release());
    devices.len()
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
            release_all();
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
    let released = release_all();
    if STOP_REQUESTED.swap(true, Ordering::AcqRel) {
        eprintln!("trainer: a second signal: stopping at once");
        std::process::exit(130);
    }
    eprintln!(
        "trainer: signal received: {released} device(s) released at zero force; stopping \
         (a second signal stops at once)"
    );
    on_stop();
}
