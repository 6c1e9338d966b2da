//! Organ geometry: meshing implicit solids, quality reports, organs, import and export.

mod quality;
mod stuffing;
