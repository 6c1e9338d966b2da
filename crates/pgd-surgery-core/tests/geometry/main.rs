//! Organ geometry: meshing implicit solids, quality reports, organs, import and export, and the
//! mesh readers fuzzed.

// Shared with `tests/scenarios`, which uses all of it; the fuzzing here uses `measure`.
#[allow(dead_code)]
#[path = "../support/counting.rs"]
mod counting;
#[path = "../support/fuzz.rs"]
mod fuzz;
mod fuzz_files;
mod import;
mod msh_binary;
mod organs;
mod quality;
mod rebuilt;
mod slivers;
mod stuffing;
mod vtk_binary;
mod vtu_binary;

/// Counts a reader's allocations (`fuzz_files.rs`); the system allocator otherwise.
#[global_allocator]
static ALLOCATOR: counting::Counting = counting::Counting;
