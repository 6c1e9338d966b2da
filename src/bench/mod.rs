//! Rerunnable benchmarks of the numerical core, reported as medians and as ratios to a
//! baseline measured in the same run. Run them with `pgd bench …`.

pub mod contact;
pub mod fem;
pub mod haptics;
pub mod vademecum;
