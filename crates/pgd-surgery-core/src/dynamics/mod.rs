//! Organs that move: reduced dynamics `M q̈ + C q̇ + f_int(q) = f_ext` in a small basis per
//! organ, integrated at the haptic tick by an energy–momentum conserving scheme.
//!
//! - [`ModalBasis`]: the organ's lowest vibration modes, by subspace iteration from the
//!   vademecum's spatial modes: mass-orthonormal, so the reduced mass is the identity and
//!   the rest stiffness is diagonal.
//! - [`ReducedKsv`]: the Kirchhoff–Saint Venant energy and internal force in that basis, as
//!   precomputed polynomial coefficients (cost independent of the mesh), and the Simo–Tarnow
//!   algorithmic force that makes the step conserve energy exactly.
//! - [`EnergyMomentum`]: the implicit midpoint step with that force and a stated Rayleigh
//!   damping, solved by Newton's method with the rest Jacobian.
//! - [`GraspedOrgan`]: a grasper on such an organ: a virtual coupling to the hand, slip,
//!   release that fades the hand's force, damage.
//! - [`ModeFit`]: the kept modes in the vademecum's own modes, so that contact and
//!   attachments, which read an organ through those, see it move.

mod basis;
mod error;
mod grasp;
mod integrator;
mod mode_fit;
mod organ;
mod polynomial;
mod small_spd;

pub use basis::ModalBasis;
pub use error::DynamicsError;
pub use grasp::{GraspPoint, GraspSettings, GraspTick, GraspedOrgan, Jaws, Tether};
pub use integrator::{EnergyMomentum, RayleighDamping, ReducedState, StepReport};
pub use mode_fit::ModeFit;
pub use organ::{DynamicModel, TISSUE_DAMPING_RATIO, TRAINER_MODES};
pub use polynomial::ReducedKsv;
