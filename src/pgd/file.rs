//! The vademecum file: `vademecums/<organ>.vdm`.
//!
//! Layout (little-endian): the magic `PGDVADEM`, the format version (u32), the byte lengths of
//! the header and the payload (u64 each), the header as JSON (self-describing: mesh hash,
//! material, regions, load directions and steps, build settings), the payload (arrays, each
//! prefixed by its length, modes as f32), and a BLAKE3 checksum of everything before it.
//! Saving writes a temporary file and renames it, so a failed save never leaves half a file.

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::BuildSettings;
use super::local::LocalPart;
use super::vademecum::{Header, Step, Vademecum};
use crate::fem::{Inclusion, Material};
use crate::mesh::TetMesh;

/// Bumped on any change of layout or meaning; older files are refused, not misread.
pub const FORMAT_VERSION: u32 = 2;
const MAGIC: &[u8; 8] = b"PGDVADEM";
const PREFIX_BYTES: usize = 8 + 4 + 8 + 8;
const CHECKSUM_BYTES: usize = 32;

#[derive(Debug, Error)]
pub enum VademecumError {
    #[error("{file}: {source}")]
    Io {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: not a vademecum file (it does not start with PGDVADEM)")]
    NotAVademecum { file: PathBuf },
    #[error(
        "{file}: format version {found}, but this build reads version {expected}; rebuild it with `pgd build`"
    )]
    Version {
        file: PathBuf,
        found: u32,
        expected: u32,
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
        "{file}: not written: its header would not read back the same ({why}); nothing was saved"
    )]
    Unwritable { file: PathBuf, why: String },
}

/// Writes `vademecum` to `path` atomically.
pub fn save(path: &Path, vademecum: &Vademecum) -> Result<(), VademecumError> {
    let io = |source| VademecumError::Io {
        file: path.to_path_buf(),
        source,
    };
    check_round_trip(&vademecum.header).map_err(|why| VademecumError::Unwritable {
        file: path.to_path_buf(),
        why,
    })?;
    let bytes = encode(vademecum);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let temporary = path.with_extension("vdm.partial");
    std::fs::write(&temporary, &bytes).map_err(io)?;
    std::fs::rename(&temporary, path).map_err(io)
}

/// The bytes of the file `save` writes.
/// A header with a non-finite number would be written as JSON `null` and never load again: the
/// header must read back equal to itself before anything is written.
fn check_round_trip(header: &Header) -> Result<(), String> {
    let json = serde_json::to_vec(header).map_err(|e| e.to_string())?;
    let back: Header = serde_json::from_slice(&json).map_err(|e| e.to_string())?;
    if &back == header {
        Ok(())
    } else {
        Err("a number in it is not finite".into())
    }
}

pub fn encode(vademecum: &Vademecum) -> Vec<u8> {
    let header = serde_json::to_vec_pretty(&vademecum.header).expect("plain data serializes");
    let payload = payload(vademecum);
    let mut bytes = Vec::with_capacity(PREFIX_BYTES + header.len() + payload.len() + 32);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(header.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&header);
    bytes.extend_from_slice(&payload);
    let checksum = blake3::hash(&bytes);
    bytes.extend_from_slice(checksum.as_bytes());
    bytes
}

/// Reads only the header of `path` (cheap: for staleness checks and listings).
pub fn read_header(path: &Path) -> Result<Header, VademecumError> {
    let bytes = read_bytes(path)?;
    let (header, _) = checked_parts(path, &bytes)?;
    Ok(header)
}

/// Reads and checks a vademecum file.
pub fn load(path: &Path) -> Result<Vademecum, VademecumError> {
    decode(path, &read_bytes(path)?)
}

/// Checks and reads the bytes of a vademecum file; `path` names it in errors.
pub fn decode(path: &Path, bytes: &[u8]) -> Result<Vademecum, VademecumError> {
    let (header, payload) = checked_parts(path, bytes)?;
    let mut reader = Reader {
        file: path,
        bytes: payload,
    };
    let vademecum = read_payload(&mut reader, header)?;
    validate(path, &vademecum)?;
    Ok(vademecum)
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, VademecumError> {
    std::fs::read(path).map_err(|source| VademecumError::Io {
        file: path.to_path_buf(),
        source,
    })
}

impl Vademecum {
    /// Refuses a vademecum built for another mesh (or other regions) than `mesh`.
    pub fn check_mesh(&self, file: &Path, mesh: &TetMesh) -> Result<(), VademecumError> {
        let expected = super::mesh_hash(mesh);
        if expected != self.header.mesh_hash {
            return Err(VademecumError::OtherMesh {
                file: file.to_path_buf(),
                expected,
                found: self.header.mesh_hash.clone(),
            });
        }
        Ok(())
    }

    /// Refuses a vademecum built for another material law or constants than `material`, or
    /// with other inclusions in the tissue.
    pub fn check_material(
        &self,
        file: &Path,
        material: &Material,
        inclusions: &[Inclusion],
    ) -> Result<(), VademecumError> {
        let header = &self.header;
        if header.material != *material || header.inclusions != inclusions {
            return Err(VademecumError::OtherMaterial {
                file: file.to_path_buf(),
                expected: tissue(material, inclusions),
                found: tissue(&header.material, &header.inclusions),
            });
        }
        Ok(())
    }

    /// Refuses a vademecum built with other settings than `settings` (a tool tip of another
    /// radius would feel another stiffness).
    pub fn check_settings(
        &self,
        file: &Path,
        settings: &BuildSettings,
    ) -> Result<(), VademecumError> {
        if self.header.settings != *settings {
            return Err(VademecumError::OtherSettings {
                file: file.to_path_buf(),
                expected: settings.summary(),
                found: self.header.settings.summary(),
            });
        }
        Ok(())
    }
}

/// Checks magic, version, length and checksum; returns the header and the payload bytes.
fn checked_parts<'a>(path: &Path, bytes: &'a [u8]) -> Result<(Header, &'a [u8]), VademecumError> {
    let file = || path.to_path_buf();
    if bytes.len() < PREFIX_BYTES || &bytes[..8] != MAGIC {
        return Err(VademecumError::NotAVademecum { file: file() });
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != FORMAT_VERSION {
        return Err(VademecumError::Version {
            file: file(),
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    let header_len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let payload_len = u64::from_le_bytes(bytes[20..28].try_into().expect("8 bytes"));
    let expected = (PREFIX_BYTES as u64)
        .saturating_add(header_len)
        .saturating_add(payload_len)
        .saturating_add(CHECKSUM_BYTES as u64);
    if (bytes.len() as u64) < expected {
        return Err(VademecumError::Truncated {
            file: file(),
            expected,
            found: bytes.len() as u64,
        });
    }
    let body = expected as usize - CHECKSUM_BYTES;
    if blake3::hash(&bytes[..body]).as_bytes() != &bytes[body..expected as usize] {
        return Err(VademecumError::Corrupted { file: file() });
    }
    let header_end = PREFIX_BYTES + header_len as usize;
    let header = serde_json::from_slice(&bytes[PREFIX_BYTES..header_end]).map_err(|e| {
        VademecumError::Malformed {
            file: file(),
            what: format!("header: {e}"),
        }
    })?;
    Ok((header, &bytes[header_end..body]))
}

fn payload(v: &Vademecum) -> Vec<u8> {
    let mut out = Vec::new();
    put(&mut out, &v.positions);
    put(&mut out, v.position_coords_m.as_flattened());
    put(&mut out, &v.position_areas_m2);
    put(&mut out, v.triangles.as_flattened());
    put(&mut out, &v.reference_compliance_m_per_n);
    put(&mut out, &[v.steps.len() as u32]);
    for step in &v.steps {
        put(&mut out, &step.spatial);
        put(&mut out, &step.parametric);
        let l = &step.local;
        put(&mut out, &l.neighbour_offsets);
        put(&mut out, &l.neighbours);
        put(&mut out, &l.compliance);
        put(&mut out, &l.correction_offsets);
        put(&mut out, &l.correction_nodes);
        put(&mut out, &l.correction);
    }
    out
}

/// Four-byte little-endian values: the payload's only element types.
trait Word: Copy {
    fn to_bytes(self) -> [u8; 4];
    fn from_bytes(bytes: [u8; 4]) -> Self;
}

impl Word for u32 {
    fn to_bytes(self) -> [u8; 4] {
        self.to_le_bytes()
    }
    fn from_bytes(bytes: [u8; 4]) -> Self {
        Self::from_le_bytes(bytes)
    }
}

impl Word for f32 {
    fn to_bytes(self) -> [u8; 4] {
        self.to_le_bytes()
    }
    fn from_bytes(bytes: [u8; 4]) -> Self {
        Self::from_le_bytes(bytes)
    }
}

fn put<T: Word>(out: &mut Vec<u8>, values: &[T]) {
    out.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for &v in values {
        out.extend_from_slice(&v.to_bytes());
    }
}

struct Reader<'a> {
    file: &'a Path,
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn malformed(&self, what: &str) -> VademecumError {
        VademecumError::Malformed {
            file: self.file.to_path_buf(),
            what: what.to_string(),
        }
    }

    fn take<T: Word>(&mut self, what: &str) -> Result<Vec<T>, VademecumError> {
        if self.bytes.len() < 8 {
            return Err(self.malformed(what));
        }
        let (len, rest) = self.bytes.split_at(8);
        let len = u64::from_le_bytes(len.try_into().expect("8 bytes"));
        let size = len
            .checked_mul(4)
            .filter(|&s| s <= rest.len() as u64)
            .ok_or_else(|| self.malformed(what))? as usize;
        let (data, rest) = rest.split_at(size);
        self.bytes = rest;
        Ok(data
            .chunks_exact(4)
            .map(|c| T::from_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }
}

fn read_payload(r: &mut Reader, header: Header) -> Result<Vademecum, VademecumError> {
    let positions = r.take("positions")?;
    let coords: Vec<f32> = r.take("position coordinates")?;
    let position_coords_m = coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let position_areas_m2 = r.take("position areas")?;
    let flat: Vec<u32> = r.take("triangles")?;
    if !flat.len().is_multiple_of(3) {
        return Err(r.malformed("triangles"));
    }
    let triangles = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let reference_compliance_m_per_n = r.take("reference compliances")?;
    let count: Vec<u32> = r.take("step count")?;
    let count = *count.first().ok_or_else(|| r.malformed("step count"))?;
    let mut steps = Vec::new();
    for _ in 0..count {
        steps.push(Step {
            spatial: r.take("spatial modes")?,
            parametric: r.take("parametric modes")?,
            local: LocalPart {
                neighbour_offsets: r.take("neighbour offsets")?,
                neighbours: r.take("neighbours")?,
                compliance: r.take("compliances")?,
                correction_offsets: r.take("correction offsets")?,
                correction_nodes: r.take("correction nodes")?,
                correction: r.take("corrections")?,
            },
        });
    }
    if !r.bytes.is_empty() {
        return Err(r.malformed("payload (bytes left after the last step)"));
    }
    Ok(Vademecum {
        header,
        positions,
        position_coords_m,
        position_areas_m2,
        triangles,
        reference_compliance_m_per_n,
        steps,
    })
}

/// Checks that every array agrees with the header and with the others, so evaluation can
/// index without bounds surprises.
fn validate(path: &Path, v: &Vademecum) -> Result<(), VademecumError> {
    let fail = |what: &str| {
        Err(VademecumError::Malformed {
            file: path.to_path_buf(),
            what: what.to_string(),
        })
    };
    let (m, nodes) = (v.positions.len(), v.header.node_count as u32);
    if v.positions.iter().any(|&n| n >= nodes) {
        return fail("positions (a node beyond the header's node count)");
    }
    if v.triangles.iter().flatten().any(|&i| i as usize >= m) {
        return fail("triangles (an index beyond the positions)");
    }
    if v.position_coords_m.len() != m || v.position_areas_m2.len() != m {
        return fail("position coordinates or areas (one per position expected)");
    }
    if v.reference_compliance_m_per_n.len() != m {
        return fail("reference compliances (one per position expected)");
    }
    if v.steps.len() != v.header.indentation_levels_m.len() || v.steps.is_empty() {
        return fail("steps (their count differs from the header's load steps)");
    }
    for (k, step) in v.steps.iter().enumerate() {
        let modes = v
            .header
            .modes_per_step
            .get(k)
            .copied()
            .unwrap_or(usize::MAX);
        if step.spatial.len() != modes * v.dof_count()
            || step.parametric.len() != modes * v.parameter_count()
        {
            return fail(&format!("modes of step {k} (sizes differ from the header)"));
        }
        let l = &step.local;
        let rows = |offsets: &[u32], len: usize, per: usize, values: usize| {
            offsets.len() == m + 1
                && offsets.first() == Some(&0)
                && offsets.windows(2).all(|w| w[0] <= w[1])
                && offsets[m] as usize == len
                && values == per * len
        };
        if !rows(
            &l.neighbour_offsets,
            l.neighbours.len(),
            9,
            l.compliance.len(),
        ) || l.neighbours.iter().any(|&j| j as usize >= m)
        {
            return fail(&format!("compliances of step {k}"));
        }
        if !rows(
            &l.correction_offsets,
            l.correction_nodes.len(),
            9,
            l.correction.len(),
        ) || l.correction_nodes.iter().any(|&n| n >= nodes)
        {
            return fail(&format!("near-field corrections of step {k}"));
        }
    }
    Ok(())
}

/// A material and its inclusions, for a message.
fn tissue(material: &Material, inclusions: &[Inclusion]) -> String {
    match inclusions {
        [] => format!("{material:?}"),
        _ => format!("{material:?} with inclusions {inclusions:?}"),
    }
}
