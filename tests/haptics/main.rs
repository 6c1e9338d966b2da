//! The real-time core, as headless Bevy haptic worlds: forces against full FEM, smooth sliding,
//! deterministic replay, faults and the clamp; and the device files and timing pieces.

mod common;
mod deformed;
mod devices;
mod faults;
mod grasp;
mod openhaptics;
mod press;
mod range;
mod replay;
mod superposition;
mod workspace;
