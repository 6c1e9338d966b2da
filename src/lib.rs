//! A real-time surgery trainer built on PGD computational vademecums, in four layers
//! (`docs/architecture.md`), each using only those below it:
//!
//! - the numerical core, plain Rust with no Bevy: [`mesh`], [`fem`] (the reference every
//!   vademecum is checked against), [`pgd`] (the vademecums), [`contact`], [`cutting`],
//!   [`dynamics`] (organs that move),
//!   [`devices`] (the device layer), [`scenario`] (exercises), [`dense_sums`],
//!   [`parry_interop`], and [`bench`](mod@bench), which times them;
//! - services: [`store`] (organs and vademecums on disk) and [`report`] (files for people);
//! - [`app`], the Bevy layer: the 1 kHz haptic loop, the scene, the trainer window;
//! - [`cli`], what the binaries' commands do and print; the binaries in `src/bin` stay thin.

pub mod app;
pub mod bench;
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
pub mod contact;
pub mod cutting;
pub mod dense_sums;
pub mod devices;
pub mod dynamics;
pub mod fem;
pub mod mesh;
pub mod parry_interop;
pub mod pgd;
pub mod report;
pub mod scenario;
pub mod store;
