//! Why a vademecum or distance-field file cannot be used: unreadable, not ours, another
//! version, truncated, corrupted, malformed, or built for another mesh, material or settings.
//! Each message names the file, and the stale ones the command that rebuilds it.

use std::path::PathBuf;

use thiserror::Error;

#[derive(Debug, Error)]
pub enum VademecumError {
    #[error("{file}: {source}")]
    Io {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: not a {kind} file (it does not start with {magic})")]
    NotAVademecum {
        file: PathBuf,
        kind: &'static str,
        magic: String,
    },
    #[error(
        "{file}: format version {found}, but this build reads version {expected}; rebuild it with `pgd build`"
    )]
    Version {
        file: PathBuf,
        found: u32,
        expected: u32,
    },
    #[error(
        "{file}: its nonlinear load steps were built with {found:?} loads, where this version pushes the tool's patch along the inward normal; rebuild it with `pgd build`"
    )]
    OlderLoadSteps {
        file: PathBuf,
        found: super::StepLoads,
    },
    #[error("{file}: truncated: {found} bytes where the header announces {expected}")]
    Truncated {
        file: PathBuf,
        expected: u64,
        found: u64,
    },
    #[error("{file}: corrupted: the checksum does not match the contents")]
    Corrupted { file: PathBuf },
    #[error("{file}: malformed {what}")]
    Malformed { file: PathBuf, what: String },
    #[error(
        "{file}: built for another mesh (mesh hash {found}, this mesh {expected}); rebuild it with `pgd build`"
    )]
    OtherMesh {
        file: PathBuf,
        expected: String,
        found: String,
    },
    #[error(
        "{file}: built for another material ({found}, wanted {expected}); rebuild it with `pgd build`"
    )]
    OtherMaterial {
        file: PathBuf,
        expected: String,
        found: String,
    },
    #[error(
        "{file}: built with other settings ({found}, wanted {expected}); rebuild it with `pgd build`"
    )]
    OtherSettings {
        file: PathBuf,
        expected: String,
        found: String,
    },
    #[error(
        "{file}: built for another vademecum (inputs hash {found}, this one {expected}); it is rebuilt"
    )]
    OtherVademecum {
        file: PathBuf,
        expected: String,
        found: String,
    },
    #[error(
        "{file}: not written: its header would not read back the same ({why}); nothing was saved"
    )]
    Unwritable { file: PathBuf, why: String },
}
