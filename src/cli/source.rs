//! What `pgd` commands accept as a mesh: a generated organ's name or a mesh file.

use std::path::Path;

use crate::mesh::TetMesh;
use crate::mesh::io::{ImportOptions, load};
use crate::mesh::organs::{self, Organ, OrganSettings};

/// How to get the mesh, with the knobs of both kinds of source.
pub struct MeshSource<'a> {
    pub name: &'a str,
    pub organ: OrganSettings,
    pub import: ImportOptions,
}

/// The organ, if the source names one, and its mesh; errors are ready to print.
pub fn load_source(source: &MeshSource) -> Result<(Option<Organ>, TetMesh), String> {
    match Organ::from_name(source.name) {
        Some(organ) => organs::generate(organ, &source.organ)
            .map(|mesh| (Some(organ), mesh))
            .map_err(|e| format!("{}: {e}", source.name)),
        None => load(Path::new(source.name), &source.import)
            .map(|mesh| (None, mesh))
            .map_err(|e| e.to_string()),
    }
}
