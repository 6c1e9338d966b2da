//! Rerunnable benchmarks of the numerical core, reported as medians and as ratios to a
//! baseline measured in the same run. Run them with `pgd bench …`. They depend on the core
//! only; the haptic loop's benchmark runs the app's world and lives with it (`app::bench`).

pub mod contact;
pub mod cutting;
pub mod dynamics;
pub mod fem;
pub mod frame;
pub mod import;
pub mod rods;
pub mod vademecum;
