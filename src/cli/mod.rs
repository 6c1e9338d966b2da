//! Terminal helpers shared by the binaries: progress bars and organ/mesh lookup. Kept out of
//! the binaries so they stay thin, and out of the numerical core so it stays quiet.

mod contact;
mod convergence;
mod plot;
mod progress;
mod report;
mod source;
mod vademecums;

pub use contact::{parse_spacing, parse_stiffness_ratio, parse_subdivisions};
pub use convergence::{StepCurve, write as write_convergence, write_of_header};
pub use progress::Bar;
pub use report::{summary, write_report};
pub use source::{MeshSource, OrganSource, load_source};
pub use vademecums::{OnStale, VademecumSpec, ensure_vademecum, parse_inclusion};
