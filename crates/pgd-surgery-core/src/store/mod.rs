//! The organs and vademecums on disk, as the trainer and `pgd` find them: where an organ's
//! mesh comes from (generated or a file), the vademecum each organ runs on, checked against
//! its mesh, material and settings and rebuilt with progress shown when missing or stale. The
//! history of trainees' attempts is the trainer's (`pgd_surgery::history`).

#[cfg(not(target_arch = "wasm32"))]
mod background;
mod progress;
mod source;
mod vademecums;

pub use crate::mesh::io::MeshFile;
#[cfg(not(target_arch = "wasm32"))]
pub use background::{BackgroundStatus, Building, background_status, build_in_background};
pub use progress::Bar;
pub use source::{MeshSource, OrganSource, load_source};
pub use vademecums::{
    BuildJob, OnStale, VademecumSpec, build_and_save, build_part, ensure_vademecum, merge_and_save,
    vademecum_file_name,
};
