//! Finite-element core against independent references: analytic fields and beam theory,
//! finite differences, conservation laws, and the errors bad input must produce.

mod bad_input;
mod beams;
mod cantilever;
mod fit;
mod hyperelastic;
mod inclusion;
mod indentation;
mod ksv;
mod loads_and_mass;
mod patch;
mod surface;
mod tangent_solver;
#[path = "../support/uniaxial.rs"]
mod uniaxial;
