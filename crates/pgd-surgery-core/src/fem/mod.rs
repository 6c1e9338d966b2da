//! The finite-element core: linear tetrahedra, isotropic linear elasticity, Kirchhoff–Saint
//! Venant, neo-Hookean and exponential tissue (and the exponential law's fit to uniaxial tests),
//! sparse assembly, loads, mass, static solvers, and indentation by a rigid sphere. Plain Rust on faer and nalgebra, no Bevy: the offline PGD builder and
//! every validation stand on it.

mod dofs;
mod element;
mod error;
mod fit;
mod inclusion;
mod indentation;
mod linear_solver;
mod loads;
mod mass;
mod material;
mod model;
mod newton;
mod pattern;
mod tangent_solver;
mod volumetric;

pub use dofs::{Dirichlet, DofMap, PRESCRIBED};
pub use element::{ElementMatrix, ElementTissue, ElementVector, TetGeometry};
pub use error::FemError;
pub use fit::{ExponentialFit, UniaxialPoint, fit_exponential, uniaxial_nominal_stress_pa};
pub use inclusion::Inclusion;
pub use indentation::{ForceDepthPoint, Indentation, IndentationSettings, SphereIndenter};
pub use linear_solver::{DirectSolver, Factorization};
pub use loads::{Loads, PatchKernel, on_pressed_side, patch_weight};
pub use mass::{consistent_mass, lumped_mass};
pub use material::{DEFAULT_STIFFENING, Law, Material, TISSUE_DENSITY_KG_M3};
pub use model::FemModel;
pub use newton::{NewtonSettings, StaticSolution, StepReport};
pub use pattern::FreePattern;
pub use tangent_solver::{KrylovStatistics, TangentSolver};
