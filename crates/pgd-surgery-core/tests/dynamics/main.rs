//! Reduced dynamics: the polynomial KSV force against full FEM, energy and momentum
//! conservation, stability far beyond the step's resolution, settling under damping onto the
//! static answer, and the swing's frequency against a full FEM modal analysis.

mod common;
mod conservation;
mod grasp;
mod modal;
mod mode_fit;
mod polynomial;
mod restraint;
