//! The Bevy layer over the numerical core: the haptic world and its 1 kHz thread
//! ([`haptic`]), the default scene ([`scene`]), a session of the trainer, headless or not
//! ([`session`]), and the trainer window ([`window`]).

pub mod haptic;
pub mod scene;
pub mod session;
pub mod window;

/// Why a window cannot be opened here, if that is known before trying.
pub fn missing_display() -> Option<&'static str> {
    if cfg!(target_os = "linux") && std::env::var_os("DISPLAY").is_none_or(|d| d.is_empty()) {
        Some("no X display is available (DISPLAY is not set)")
    } else {
        None
    }
}
