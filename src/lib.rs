//! A real-time surgery trainer built on PGD computational vademecums.
//!
//! The numerical core is plain Rust with no Bevy: [`mesh`] (tetrahedral meshes and their
//! regions), [`fem`] (finite elements, the reference every vademecum is checked against) and
//! [`pgd`] (the vademecums).
//! [`bench`] times it. [`app`] is the Bevy layer on top; the binaries in `src/bin` stay thin.

pub mod app;
pub mod bench;
pub mod cli;
pub mod contact;
pub mod fem;
pub mod haptics;
pub mod kernels;
pub mod mesh;
pub mod pgd;
pub mod scenario;
pub mod seam;
