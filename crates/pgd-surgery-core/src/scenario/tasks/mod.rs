//! The built-in task types, one module each, and their registration: adding a type is its
//! module and a line in [`built_in`].

mod clip_and_cut;
mod dissection;
mod force_control;
mod grasp;
mod incision;
mod palpation;
mod radial_keratotomy;
mod read;
mod region;
mod registry;
mod retraction;
mod safe_navigation;

pub use clip_and_cut::{ClipAndCut, ClipAndCutResult, ClipPlaced, DivisionMade};
pub use dissection::{BurnMade, Dissection, DissectionResult, EnergySpent};
pub use force_control::{ForceControl, ForceControlResult};
pub use grasp::{Grasp, GraspResult};
pub use incision::{COVERED_TO_FINISH, Incision, IncisionResult};
pub use palpation::{Palpation, PalpationResult};
pub use radial_keratotomy::{RadialKeratotomy, RadialKeratotomyResult};
pub use region::RegionResult;
pub use retraction::{Retraction, RetractionResult};
pub use safe_navigation::{SafeNavigation, SafeNavigationResult};

pub use registry::{register, registered_names};

use registry::Entry;

/// The task types every scenario may name, in the order the docs list them.
fn built_in() -> Vec<Entry> {
    vec![
        Entry::of::<ForceControl>(),
        Entry::of::<SafeNavigation>(),
        Entry::of::<Palpation>(),
        Entry::of::<Retraction>(),
        Entry::of::<Grasp>(),
        Entry::of::<Incision>(),
        Entry::of::<RadialKeratotomy>(),
        Entry::of::<Dissection>(),
        Entry::of::<ClipAndCut>(),
    ]
}
