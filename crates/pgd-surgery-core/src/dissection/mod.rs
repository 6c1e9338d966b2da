//! Freeing one organ from another: the connective tissue between them as cohesive ties that
//! hold, give and tear ([`cohesive`]). `docs/dissection.md` has the model and its sources.

pub mod cohesive;

pub use cohesive::{CohesiveError, CohesiveLaw, CohesiveTie};
