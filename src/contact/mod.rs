//! Contact, plain Rust, no Bevy: the haptic schedule calls it every tick.
//!
//! - the tool against the organs' accessible surfaces ([`press`]);
//! - organ against organ ([`Coupling`]): the master organ's distance field for every
//!   deformation ([`DistanceField`]), probed by the other organs' pointshells
//!   ([`Pointshell`]) with a penalty solved each tick ([`ContactPair`]), and attached organs carried by
//!   the organ they hang from ([`Attachment`]).

mod attachment;
mod clearance;
mod coupling;
mod distance;
mod hold;
mod local_compliance;
mod modal_rows;
mod normal_compliance;
mod penalty;
mod pointshell;
mod projected_cg;
mod relaxation;
mod surface;
mod tool;

pub use attachment::Attachment;
pub use coupling::{AttachmentSpec, Coupling, CouplingSettings};
pub use distance::{
    DistanceField, DistanceSample, DistanceSettings, FieldOrigin, LatticeCache, MasterShape,
    NearField,
};
pub use hold::ToolHold;
pub use modal_rows::ModalRows;
pub use penalty::{ContactPair, OrganPose, PairOutput, PairReport, PenaltySettings};
pub use pointshell::{
    Pointshell, PointshellDensity, SPARSE_SPACINGS_MM, SUBDIVISIONS, check_spacing,
    check_subdivisions,
};
pub use projected_cg::Convergence;
pub use surface::{ContactError, ContactSurface, SurfaceHit};
pub use tool::{Probe, Target, ToolContact, follow, press};
