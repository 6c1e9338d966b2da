//! The distance field's file, `<vademecum>.vdf` beside the master's vademecum: the
//! distance-field vademecum, precomputed offline (`pgd build --distance-field`) or on a
//! scene's first use, then loaded.
//!
//! The [`container`] layout with the magic `PGDDISTF`; the header (JSON) holds the hash of the
//! field's inputs, the lattice settings and its layout; the payload the lattice's rest
//! distances, its modes' displacements, the per-mode bounds and each node's closest rest
//! point. A field built from another vademecum or with other lattice settings is refused, so
//! the trainer never runs on a stale one.

use std::fmt;
use std::path::Path;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::{ClosestPoint, ContactSurface, DistanceField, DistanceSettings, HEAD};
use crate::pgd::container::{self, Kind, Reader, put};
use crate::pgd::{Vademecum, VademecumError};

const KIND: Kind = Kind {
    magic: b"PGDDISTF",
    // 2: each lattice node's closest rest point, for the near-field corrections.
    // 3: the rest distances apart from the modes' displacements.
    version: 3,
    name: "distance field",
};

#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct FieldHeader {
    inputs: String,
    settings: DistanceSettings,
    origin_m: [f64; 3],
    dims: [usize; 3],
    modes: usize,
}

/// Where a scene's distance field came from.
#[derive(Debug)]
pub enum FieldOrigin {
    Loaded,
    /// Built now, because the stored one could not be used (`why`); `saved` says whether it
    /// was stored for the next time.
    Built {
        why: VademecumError,
        saved: Result<(), VademecumError>,
    },
}

impl fmt::Display for FieldOrigin {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Self::Loaded => write!(f, "loaded"),
            Self::Built { why, saved } => {
                match why {
                    VademecumError::Io { file, source }
                        if source.kind() == std::io::ErrorKind::NotFound =>
                    {
                        write!(f, "{}: not built yet; built it now", file.display())?
                    }
                    _ => write!(f, "{why}; built it now")?,
                }
                match saved {
                    Ok(()) => write!(f, " and saved it for the next time"),
                    Err(e) => write!(f, ", but could not save it: {e}"),
                }
            }
        }
    }
}

/// A hash of what a field is built from: the master's accessible surface at rest and its
/// modes there.
pub fn inputs_of(vademecum: &Vademecum) -> String {
    let mut hasher = blake3::Hasher::new();
    for p in vademecum.position_coords_m.as_flattened() {
        hasher.update(&p.to_le_bytes());
    }
    for t in vademecum.triangles.as_flattened() {
        hasher.update(&t.to_le_bytes());
    }
    for step in 0..vademecum.steps.len() {
        for mode in 0..vademecum.modes(step) {
            for &node in &vademecum.positions {
                let u = vademecum.mode_at_node(step, mode, node as usize);
                u.iter().for_each(|c| {
                    hasher.update(&(*c as f32).to_le_bytes());
                });
            }
        }
    }
    hasher.finalize().to_hex()[..16].to_owned()
}

impl DistanceField {
    /// The field of `vademecum` stored at `path` if it was built from the same vademecum with
    /// the same `settings`; otherwise built now and saved there.
    pub fn load_or_build(
        vademecum: &Vademecum,
        surface: &ContactSurface,
        settings: &DistanceSettings,
        path: &Path,
    ) -> (Self, FieldOrigin) {
        let stored = Self::load(path).and_then(|field| {
            field.check_for(path, vademecum, settings)?;
            Ok(field)
        });
        match stored {
            Ok(field) => (field, FieldOrigin::Loaded),
            Err(why) => {
                let field = Self::build(vademecum, surface, settings);
                let saved = field.save(path);
                (field, FieldOrigin::Built { why, saved })
            }
        }
    }

    /// Refuses a field built from another vademecum than `vademecum` or with other lattice
    /// settings than `settings`.
    pub fn check_for(
        &self,
        path: &Path,
        vademecum: &Vademecum,
        settings: &DistanceSettings,
    ) -> Result<(), VademecumError> {
        let expected = inputs_of(vademecum);
        if self.inputs != expected {
            return Err(VademecumError::OtherVademecum {
                file: path.to_path_buf(),
                expected,
                found: self.inputs.clone(),
            });
        }
        if self.settings != *settings {
            return Err(VademecumError::OtherSettings {
                file: path.to_path_buf(),
                expected: format!("{settings:?}"),
                found: format!("{:?}", self.settings),
            });
        }
        Ok(())
    }

    /// Writes the field to `path` atomically.
    pub fn save(&self, path: &Path) -> Result<(), VademecumError> {
        let header = FieldHeader {
            inputs: self.inputs.clone(),
            settings: self.settings,
            origin_m: self.origin_m.into(),
            dims: self.dims,
            modes: self.modes,
        };
        let header = serde_json::to_vec_pretty(&header).expect("plain data serializes");
        let rest = self.rest.as_flattened();
        let mut payload =
            Vec::with_capacity(4 * (rest.len() + self.modal.len() + self.mode_bounds.len()));
        put(&mut payload, rest);
        put(&mut payload, &self.modal);
        put(&mut payload, &self.mode_bounds);
        let corners: Vec<u32> = self.closest.iter().flat_map(|p| p.corners).collect();
        let weights: Vec<f32> = self.closest.iter().flat_map(|p| p.weights).collect();
        put(&mut payload, &corners);
        put(&mut payload, &weights);
        container::write_atomically(path, &container::encode(&KIND, &header, &payload))
    }

    /// Reads and checks a field file.
    pub fn load(path: &Path) -> Result<Self, VademecumError> {
        let bytes = container::read(path)?;
        let (header, payload) = container::checked_parts(&KIND, path, &bytes)?;
        let header: FieldHeader =
            serde_json::from_slice(header).map_err(|e| VademecumError::Malformed {
                file: path.to_path_buf(),
                what: format!("header: {e}"),
            })?;
        let mut reader = Reader::new(path, payload);
        let rest: Vec<f32> = reader.take("rest distances")?;
        let modal: Vec<f32> = reader.take("modes' displacements")?;
        let mode_bounds: Vec<f32> = reader.take("mode bounds")?;
        let corners: Vec<u32> = reader.take("closest points' corners")?;
        let weights: Vec<f32> = reader.take("closest points' weights")?;
        reader.finish()?;
        // The header's sizes are checked against the arrays read (which the file's length
        // bounds), in arithmetic that cannot overflow whatever the header claims.
        let nodes = header
            .dims
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d));
        let sized = |len: usize, per_node: Option<usize>| {
            nodes.zip(per_node).and_then(|(n, k)| n.checked_mul(k)) == Some(len)
        };
        if !sized(rest.len(), Some(HEAD))
            || !sized(modal.len(), header.modes.checked_mul(3))
            || mode_bounds.len() != header.modes
            || !sized(corners.len(), Some(3))
            || !sized(weights.len(), Some(3))
            || header.dims.iter().any(|&n| n < 2)
        {
            return Err(reader.malformed("lattice (its size does not match its header)"));
        }
        let closest = corners
            .chunks_exact(3)
            .zip(weights.chunks_exact(3))
            .map(|(c, w)| ClosestPoint {
                corners: [c[0], c[1], c[2]],
                weights: [w[0], w[1], w[2]],
            })
            .collect();
        Ok(Self {
            inputs: header.inputs,
            settings: header.settings,
            origin_m: Vector3::from(header.origin_m),
            dims: header.dims,
            modes: header.modes,
            rest: rest
                .chunks_exact(HEAD)
                .map(|r| [r[0], r[1], r[2], r[3]])
                .collect(),
            modal,
            mode_bounds,
            closest,
        })
    }
}
