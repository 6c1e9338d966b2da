//! A real-time surgery trainer built on PGD computational vademecums, in four layers
//! (`docs/architecture.md`), each using only those below it:
//!
//! - the numerical core and its services, the crate `pgd_surgery_core` (no Bevy), re-exported
//!   here module by module: [`mesh`], [`fem`], [`pgd`], [`contact`], [`cutting`],
//!   [`dissection`], [`rods`], [`biliary`], [`dynamics`], [`devices`], [`scenario`], [`dense_sums`], [`parry_interop`],
//!   [`bench`](mod@bench), [`store`] and [`report`];
//! - [`history`], the trainees' attempts kept in SQLite;
//! - [`app`], the Bevy layer: the 1 kHz haptic loop, the scene, the trainer window;
//! - [`cli`], what the binaries' commands do and print; the binaries in `src/bin` stay thin.

pub use pgd_surgery_core::{
    bench, biliary, contact, cutting, dense_sums, devices, dissection, dynamics, fem, mesh,
    parry_interop, pgd, report, rods, scenario, store,
};

pub mod app;
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
#[cfg(not(target_arch = "wasm32"))]
pub mod history;
