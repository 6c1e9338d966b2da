//! The Bevy layer over the numerical core: the haptic loop's world and its 1 kHz thread
//! ([`haptic`]), the default scene ([`scene`]), one attempt at a scenario ([`attempt`]), a
//! run of the trainer, headless or in its window ([`launch`]), the trainer window
//! ([`window`]) and the benchmark of the whole loop ([`bench`](mod@bench)).

pub mod attempt;
#[cfg(not(target_arch = "wasm32"))]
pub mod bench;
#[cfg(not(target_arch = "wasm32"))]
pub mod bench_operation;
#[cfg(not(target_arch = "wasm32"))]
pub mod bench_scalpel;
pub mod haptic;
#[cfg(not(target_arch = "wasm32"))]
pub mod launch;
pub mod scene;
pub mod shipped;
#[cfg(not(target_arch = "wasm32"))]
pub mod soak;
#[cfg(target_arch = "wasm32")]
pub mod web;
pub mod window;

pub use shipped::SHIPPED_SCENARIOS;

/// The trainer's default exercise (its shipped file and its text), built in like every
/// shipped scenario so that it runs from any directory.
pub const DEFAULT_SCENARIO: (&str, &str) = SHIPPED_SCENARIOS[0];

/// Why a window cannot be opened here, if that is known before trying: no `DISPLAY`, or a
/// local X display whose server does not answer (winit would panic on either).
#[cfg(not(target_arch = "wasm32"))]
pub fn missing_display() -> Option<String> {
    if !cfg!(target_os = "linux") {
        return None;
    }
    let display = std::env::var("DISPLAY").unwrap_or_default();
    if display.is_empty() {
        return Some("no X display is available (DISPLAY is not set)".into());
    }
    let socket = local_x_socket(&display)?;
    match std::os::unix::net::UnixStream::connect(&socket) {
        Ok(_) => None,
        Err(e) => Some(format!(
            "no X server answers on DISPLAY={display} ({}: {e})",
            socket.display()
        )),
    }
}

/// The socket of a local display (`:N`, `:N.S`, `unix:N`); `None` for a remote one.
#[cfg(not(target_arch = "wasm32"))]
fn local_x_socket(display: &str) -> Option<std::path::PathBuf> {
    let number = display
        .strip_prefix(':')
        .or_else(|| display.strip_prefix("unix:"))?
        .split('.')
        .next()?;
    number.parse::<u32>().ok()?;
    Some(format!("/tmp/.X11-unix/X{number}").into())
}
