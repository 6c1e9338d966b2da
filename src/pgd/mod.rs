//! Proper generalized decomposition: computational vademecums `u(x, p) ≈ Σ X^k(x) Y^k(p)` for a
//! unit load at any accessible surface point in any direction. Plain Rust, no Bevy.

mod linear;
mod load_patches;
mod separated;

pub use linear::{ModeReport, PgdSettings, build_linear};
pub use load_patches::LoadPatches;
pub use separated::SeparatedField;
