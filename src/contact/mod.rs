//! Contact between the tool and the organs, on the organs' accessible surfaces. Plain Rust, no
//! Bevy: the haptic schedule calls it every tick.

mod surface;
mod tool;

pub use surface::{ContactError, ContactSurface, SurfaceHit};
pub use tool::{Probe, Target, ToolContact, press};
