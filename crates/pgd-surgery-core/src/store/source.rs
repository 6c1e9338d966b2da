//! Where an organ's mesh comes from: a generated organ or a mesh file, as `pgd` commands take
//! it (by name or path) and as the trainer's scenarios give it.

use std::path::PathBuf;

use crate::mesh::TetMesh;
use crate::mesh::io::{ImportOptions, MeshFile, load};
use crate::mesh::organs::{self, Organ, OrganSettings};

/// How to get the mesh, with the knobs of both kinds of source.
pub struct MeshSource<'a> {
    pub name: &'a str,
    pub organ: OrganSettings,
    pub import: ImportOptions,
}

/// The organ, if the source names one, and its mesh; errors are ready to print.
pub fn load_source(source: &MeshSource) -> Result<(Option<Organ>, TetMesh), String> {
    let origin = match Organ::from_name(source.name) {
        Some(organ) => OrganSource::Generated(organ),
        None => OrganSource::File(MeshFile {
            path: PathBuf::from(source.name),
            regions: source.import.regions.clone(),
        }),
    };
    let mesh = origin.load(&source.organ, &source.import)?;
    Ok((origin.organ(), mesh))
}

/// Where an organ's mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum OrganSource {
    /// Generated (at the given settings).
    Generated(Organ),
    /// Read from a mesh file; its tissue is the liver's unless given.
    File(MeshFile),
}

impl OrganSource {
    /// The generated organ, if it is one.
    pub fn organ(&self) -> Option<Organ> {
        match self {
            OrganSource::Generated(organ) => Some(*organ),
            OrganSource::File(_) => None,
        }
    }

    /// The generated organ whose material is the default (the liver's for a mesh file).
    pub fn material_of(&self) -> Organ {
        self.organ().unwrap_or(Organ::Liver)
    }

    /// The mesh: generated at `settings`, or read with `import`; an error names the organ or
    /// the file.
    pub fn load(
        &self,
        settings: &OrganSettings,
        import: &ImportOptions,
    ) -> Result<TetMesh, String> {
        match self {
            OrganSource::Generated(organ) => {
                organs::generate(*organ, settings).map_err(|e| format!("{}: {e}", organ.name()))
            }
            OrganSource::File(file) => {
                let import = ImportOptions {
                    regions: file.regions.clone(),
                    ..import.clone()
                };
                load(&file.path, &import).map_err(|e| e.to_string())
            }
        }
    }
}
