//! The trainer's numerical core, plain Rust with no Bevy (`docs/architecture.md`), in two
//! layers, each using only those below it:
//!
//! - the numerics: [`mesh`], [`fem`] (the reference every vademecum is checked against),
//!   [`pgd`] (the vademecums), [`contact`], [`cutting`], [`dissection`] (organs freed from
//!   one another), [`rods`] (ducts and vessels), [`biliary`] (the ducts and the artery of a
//!   cholecystectomy, their clips and division, the critical view of safety), [`dynamics`] (organs that move),
//!   [`devices`] (the device layer), [`scenario`] (exercises), [`dense_sums`],
//!   [`parry_interop`], and [`bench`](mod@bench), which times them;
//! - services: [`store`] (organs and vademecums on disk) and [`report`] (files for people).
//!
//! Its own crate so that it builds and tests without Bevy: `cargo test -p pgd-surgery-core`
//! compiles no renderer, and Cargo, not a convention, keeps Bevy out of it. The trainer
//! (`pgd_surgery`) re-exports every module under the same name.

pub mod bench;
pub mod biliary;
pub mod contact;
pub mod cutting;
pub mod dense_sums;
pub mod devices;
pub mod dissection;
pub mod dynamics;
pub mod fem;
pub mod mesh;
pub mod parry_interop;
pub mod pgd;
pub mod report;
pub mod rods;
pub mod scenario;
pub mod store;
