//! Organ geometry: meshing implicit solids, quality reports, organs, import and export.

mod import;
mod organs;
mod quality;
mod stuffing;
