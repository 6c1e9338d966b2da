//! Thin tubular structures — the cystic duct, the common bile duct, the cystic artery — as
//! rods ([`rod`]), solved over a banded tangent ([`banded`]). `docs/rods.md` has the model,
//! why it was chosen and what it costs.

pub mod banded;
pub mod rod;

pub use banded::Banded;
pub use rod::{Rod, RodError, Settled, TubeSection};
