//! The real-time core, as headless Bevy haptic worlds: forces against full FEM, smooth sliding,
//! deterministic replay, faults and the clamp; and the device files and timing pieces.

mod common;
mod deformed;
mod devices;
mod exits;
mod fakes;
mod faults;
mod forcedimension;
mod fulcrum;
mod grasp;
mod haply;
mod haply_fake;
mod instruments;
mod laparoscope;
mod openhaptics;
mod press;
mod range;
mod replay;
mod superposition;
mod two_hands;
mod vendor_fake;
mod workspace;
