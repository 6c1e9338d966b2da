//! The layout the project's binary files share: vademecums (`.vdm`) and the distance fields
//! precomputed from them (`.vdf`).
//!
//! Little-endian: an 8-byte magic, the format version (u32), the byte lengths of the header
//! and the payload (u64 each), the header (JSON), the payload (arrays of four-byte values,
//! each prefixed by its length), and a BLAKE3 checksum of everything before it. Saving writes
//! a temporary file and renames it, so a failed save never leaves half a file, and two
//! processes saving the same file never mix their bytes.
//!
//! A web page has no file system: it fetches the files its scene needs and [`provide`]s them
//! here, where [`read`] finds them before looking on disk.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use super::error::VademecumError;

const PREFIX_BYTES: usize = 8 + 4 + 8 + 8;
const CHECKSUM_BYTES: usize = 32;

/// What tells one kind of file from another.
pub struct Kind {
    pub magic: &'static [u8; 8],
    /// Bumped on any change of layout or meaning; older files are refused, not misread.
    pub version: u32,
    /// What the file is called in messages.
    pub name: &'static str,
}

/// The bytes of a file of `kind`.
pub fn encode(kind: &Kind, header: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(PREFIX_BYTES + header.len() + payload.len() + 32);
    bytes.extend_from_slice(kind.magic);
    bytes.extend_from_slice(&kind.version.to_le_bytes());
    bytes.extend_from_slice(&(header.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(header);
    bytes.extend_from_slice(payload);
    let checksum = blake3::hash(&bytes);
    bytes.extend_from_slice(checksum.as_bytes());
    bytes
}

/// Where the payload of a file's `bytes` starts (past the prefix and the header; the whole
/// length if they are shorter): the values from there on are four-byte words.
pub fn payload_start(bytes: &[u8]) -> usize {
    let header_len = bytes
        .get(12..20)
        .map_or(0, |b| u64::from_le_bytes(b.try_into().expect("8 bytes")));
    usize::try_from(header_len)
        .ok()
        .and_then(|h| h.checked_add(PREFIX_BYTES))
        .map_or(bytes.len(), |start| start.min(bytes.len()))
}

/// Checks magic, version, length and checksum; returns the header and the payload bytes.
pub fn checked_parts<'a>(
    kind: &Kind,
    path: &Path,
    bytes: &'a [u8],
) -> Result<(&'a [u8], &'a [u8]), VademecumError> {
    let file = || path.to_path_buf();
    if bytes.len() < PREFIX_BYTES || &bytes[..8] != kind.magic {
        return Err(VademecumError::NotAVademecum {
            file: file(),
            kind: kind.name,
            magic: String::from_utf8_lossy(kind.magic).into_owned(),
        });
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != kind.version {
        return Err(VademecumError::Version {
            file: file(),
            found: version,
            expected: kind.version,
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
    Ok((&bytes[PREFIX_BYTES..header_end], &bytes[header_end..body]))
}

/// Writes `bytes` to `path` through a temporary file of this process, renamed into place.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), VademecumError> {
    static SAVES: AtomicU64 = AtomicU64::new(0);
    let io = |source| VademecumError::Io {
        file: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let save = SAVES.fetch_add(1, Ordering::Relaxed);
    let mut temporary = path.as_os_str().to_owned();
    temporary.push(format!(".{}-{save}.partial", std::process::id()));
    std::fs::write(&temporary, bytes).map_err(io)?;
    std::fs::rename(&temporary, path).map_err(io)
}

/// The bytes of the file at `path`: the ones [`provide`]d for it, else the file's.
pub fn read(path: &Path) -> Result<Vec<u8>, VademecumError> {
    if let Some(bytes) = provided(path) {
        return Ok(bytes.to_vec());
    }
    std::fs::read(path).map_err(|source| VademecumError::Io {
        file: path.to_path_buf(),
        source,
    })
}

type Provided = Mutex<BTreeMap<PathBuf, Arc<[u8]>>>;

fn provided_files() -> &'static Provided {
    static FILES: std::sync::OnceLock<Provided> = std::sync::OnceLock::new();
    FILES.get_or_init(Provided::default)
}

/// Makes `bytes` the content of the file at `path` for [`read`] (a page's fetched files).
pub fn provide(path: &Path, bytes: Arc<[u8]>) {
    if let Ok(mut files) = provided_files().lock() {
        files.insert(path.to_path_buf(), bytes);
    }
}

/// Whether [`read`] would find `path` among the provided files.
pub fn is_provided(path: &Path) -> bool {
    provided(path).is_some()
}

fn provided(path: &Path) -> Option<Arc<[u8]>> {
    provided_files().lock().ok()?.get(path).cloned()
}

/// Four-byte little-endian values: the payloads' only element types.
pub trait Word: Copy {
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

/// Appends `values`, prefixed by their count.
pub fn put<T: Word>(out: &mut Vec<u8>, values: &[T]) {
    out.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for &v in values {
        out.extend_from_slice(&v.to_bytes());
    }
}

/// Appends `values` as eight-byte little-endian values, each two of the payload's words,
/// prefixed by the words' count: exact responses kept to the last bit for a later merge.
pub fn put_f64(out: &mut Vec<u8>, values: &[f64]) {
    out.extend_from_slice(&(2 * values.len() as u64).to_le_bytes());
    for &v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

/// Reads a payload back, array by array, naming the file and the array in errors.
pub struct Reader<'a> {
    file: &'a Path,
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    pub fn new(file: &'a Path, bytes: &'a [u8]) -> Self {
        Self { file, bytes }
    }

    pub fn malformed(&self, what: &str) -> VademecumError {
        VademecumError::Malformed {
            file: self.file.to_path_buf(),
            what: what.to_string(),
        }
    }

    /// The next array, `what` naming it in errors.
    pub fn take<T: Word>(&mut self, what: &str) -> Result<Vec<T>, VademecumError> {
        Ok(self
            .take_bytes(what)?
            .chunks_exact(4)
            .map(|c| T::from_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }

    /// The next array written by [`put_f64`].
    pub fn take_f64(&mut self, what: &str) -> Result<Vec<f64>, VademecumError> {
        let data = self.take_bytes(what)?;
        if data.len() % 8 != 0 {
            return Err(self.malformed(what));
        }
        Ok(data
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect())
    }

    /// The bytes of the next array's words.
    fn take_bytes(&mut self, what: &str) -> Result<&'a [u8], VademecumError> {
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
        Ok(data)
    }

    /// Refuses bytes left after the last array.
    pub fn finish(&self) -> Result<(), VademecumError> {
        match self.bytes.is_empty() {
            true => Ok(()),
            false => Err(self.malformed("payload (bytes left after the last array)")),
        }
    }
}
