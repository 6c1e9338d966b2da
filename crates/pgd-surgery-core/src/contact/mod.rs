//! Contact, plain Rust, no Bevy: the haptic tick calls it every millisecond.
//!
//! **The tool against an organ** (`press.rs`: [`press`]): the tool tip against the organ's
//! accessible surface (`contact_surface.rs`: [`ContactSurface`]), the patch it loads, and how it
//! holds that patch while other loads move it (`hold.rs`: [`ToolHold`]).
//!
//! **Organ against organ** ([`Coupling`], paper 000's voxmap-pointshell). One tick, top to
//! bottom, file by file:
//! 1. `coupling.rs`: [`Coupling::tick`] clears last tick's coupling, carries each attached
//!    organ by the organ it hangs from (`attachment.rs`), then ticks each pair with both
//!    organs' poses (`pose.rs`: modal coefficients and carry);
//! 2. `pair.rs`: [`ContactPair::tick`] measures the pointshell nodes within reach:
//!    - `pointshell.rs`: the nodes, nearest the master first, in blocks;
//!    - `clearance.rs`: which of them are surely still clear and are passed over;
//!    - `distance/`: the master's deformed distance field read at each node (`cell.rs`, one
//!      cell; `near.rs`, the tool's near field on the master);
//! 3. `pair.rs` again: the penalty forces solved as one bounded convex problem
//!    (`projected_cg.rs`) through how the forces move the surfaces (`normal_compliance.rs`:
//!    both organs' modes, the tool's hold; `local_compliance/`: the dimples the modes miss),
//!    a force change that flips from tick to tick taken in part (`relaxation.rs`);
//! 4. `pair.rs`, last: the forces become modal coefficients and point loads of both organs
//!    (`modal_rows.rs`), which [`Coupling::write`] hands to each organ's deformation.

mod attachment;
mod clearance;
mod contact_surface;
mod coupling;
mod distance;
mod hold;
mod local_compliance;
mod modal_rows;
mod normal_compliance;
mod pair;
mod pointshell;
mod pose;
mod press;
mod projected_cg;
mod relaxation;

pub use attachment::Attachment;
pub use contact_surface::{ContactError, ContactSurface, SurfaceHit};
pub use coupling::{AttachmentSpec, Coupling, CouplingSettings};
pub use distance::{
    DistanceField, DistanceSample, DistanceSettings, FieldOrigin, LatticeCache, MasterShape,
    NearField,
};
pub use hold::ToolHold;
pub use modal_rows::ModalRows;
pub use pair::{ContactPair, PairOutput, PairReport, PairSide, PenaltySettings};
pub use pointshell::{
    Pointshell, PointshellDensity, SPARSE_SPACINGS_MM, SUBDIVISIONS, check_spacing,
    check_subdivisions,
};
pub use pose::OrganPose;
pub use press::{Probe, Target, ToolContact, follow, press};
pub use projected_cg::Convergence;
