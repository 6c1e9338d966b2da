//! Terminal helpers shared by the binaries: progress bars and organ/mesh lookup. Kept out of
//! the binaries so they stay thin, and out of the numerical core so it stays quiet.

mod progress;
mod source;

pub use progress::Bar;
pub use source::{MeshSource, load_source};
