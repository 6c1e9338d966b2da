//! Cutting, plain Rust, no Bevy: incisions as data ([`Incision`]: the faces the blade sweeps),
//! the Heaviside enrichment they give a mesh ([`Enrichment`]), and the reference solvers every
//! reduced cut is checked against: the full X-FEM solve ([`xfem::solve`]) and, for a cut along
//! element faces, plain FEM on the mesh with the cut's nodes doubled
//! ([`split_mesh::split_along`]); and the cut state online ([`CutState`]), whose condensed
//! system gains rows and columns as incisions advance, on a worker thread beside the haptic
//! one ([`CutWorker`]); and the scalpel that makes incisions ([`Scalpel`]). See
//! `docs/cutting.md`.

mod clip;
mod enrichment;
mod factor;
mod incision;
pub mod keratotomy;
mod local;
mod response;
mod scalpel;
pub mod split_mesh;
mod state;
mod validation;
mod view;
mod worker;
pub mod xfem;

pub use enrichment::{ElementCut, Enriched, Enrichment, Front, Piece, SLIVER, Supports};
pub use incision::{CutFace, Extent, Incision, MIN_SEGMENT_M};
pub use response::{ExactResponse, Response, UncutResponse};
pub use scalpel::{
    Blade, BladeContact, CORNEA_TOUGHNESS_J_PER_M2, CutStep, LIVER_TOUGHNESS_J_PER_M2, Scalpel,
    Stroke,
};
pub use state::CutState;
pub use validation::{
    CutCase, CutPattern, CutValidationReport, CutValidationSettings, tool_patch,
    validate_incisions, validate_keratotomy,
};
pub use view::{CutAnswer, CutScratch, CutView, PatchCut};
pub use worker::{CutWorker, LatestCut};
pub use xfem::CutSolution;

/// Why a cut cannot be made or solved.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CutError {
    #[error("a degenerate cut: {0}")]
    Degenerate(String),
    #[error("the cut detaches a piece of tissue: nothing holds it any more")]
    Detached,
    #[error(
        "the cut reaches node {node}, outside the region the cut vademecum covers: rebuild it \
         with a deeper --cut-depth-mm, or cut nearer the accessible face"
    )]
    OutsideRegion { node: usize },
    #[error("the cut organ cannot be solved: {0}")]
    Solve(String),
}
