//! The web form of the project's binary files: what a web page downloads instead of a
//! `.vdm` or `.vdf`. A vademecum's response values (its modes, local compliances and near-field
//! corrections, and the reference compliances) are rounded to [`MANTISSA_BITS`] bits of
//! mantissa, a relative change of at most 2^-(bits+1) per value, far below what the hand
//! feels; its geometry is kept exact. The payload's four-byte words are then split into four
//! planes, one per byte (the rounded values' low bytes are zeros, and their high bytes, sign
//! and exponent, repeat), which deflate (RFC 1951) packs far better than interleaved words.
//! Expanded, a web form is an ordinary file of its kind, checked as any other.

use std::path::Path;

use nalgebra::Vector3;

use super::container;
use super::error::VademecumError;
use super::file;
use super::vademecum::{SurfacePoint, Vademecum};

/// Mantissa bits kept of each response value: as many as a half-precision float has, with
/// single precision's range.
pub const MANTISSA_BITS: u32 = 10;

/// What a web form's file name adds to its file's (`liver.vdm` → `liver.vdm.web`).
pub const EXTENSION: &str = "web";

/// The largest file a web form may expand into, against a damaged or hostile download.
const MAX_EXPANDED_BYTES: usize = 1 << 30;

/// The web form of `vademecum`.
pub fn vademecum(vademecum: &Vademecum) -> Vec<u8> {
    let mut rounded = vademecum.clone();
    let round_all = |values: &mut [f32]| values.iter_mut().for_each(|v| *v = round(*v));
    round_all(&mut rounded.reference_compliance_m_per_n);
    for step in &mut rounded.steps {
        round_all(&mut step.spatial);
        round_all(&mut step.parametric);
        round_all(&mut step.local.compliance);
        round_all(&mut step.local.correction);
    }
    deflated(&file::encode(&rounded))
}

/// The web form of a file kept exactly (a distance field), or of a vademecum once rounded:
/// its lengths, its prefix and header as they are, its payload's words in byte planes, all
/// deflated.
pub fn deflated(file: &[u8]) -> Vec<u8> {
    let start = container::payload_start(file);
    let words = (file.len() - start) / 4;
    let body = &file[start..start + 4 * words];
    let mut planed = Vec::with_capacity(16 + file.len());
    planed.extend((file.len() as u64).to_le_bytes());
    planed.extend((start as u64).to_le_bytes());
    planed.extend(&file[..start]);
    for plane in 0..4 {
        planed.extend(body.chunks_exact(4).map(|word| word[plane]));
    }
    planed.extend(&file[start + 4 * words..]);
    miniz_oxide::deflate::compress_to_vec(&planed, 9)
}

/// The file a web form read from `path` expands into.
pub fn expand(path: &Path, web_form: &[u8]) -> Result<Vec<u8>, VademecumError> {
    let malformed = |why: String| VademecumError::Malformed {
        file: path.to_path_buf(),
        what: format!("web form ({why})"),
    };
    let planed = miniz_oxide::inflate::decompress_to_vec_with_limit(web_form, MAX_EXPANDED_BYTES)
        .map_err(|e| malformed(format!("it does not inflate: {e}")))?;
    let length = |at: usize| {
        planed
            .get(at..at + 8)
            .and_then(|b| usize::try_from(u64::from_le_bytes(b.try_into().ok()?)).ok())
    };
    let (Some(len), Some(start)) = (length(0), length(8)) else {
        return Err(malformed("it is too short".into()));
    };
    let planed = &planed[16..];
    if planed.len() != len || start > len {
        return Err(malformed("its lengths do not agree".into()));
    }
    let words = (len - start) / 4;
    let mut file = Vec::with_capacity(len);
    file.extend(&planed[..start]);
    let planes = &planed[start..start + 4 * words];
    for k in 0..words {
        file.extend((0..4).map(|plane| planes[plane * words + k]));
    }
    file.extend(&planed[start + 4 * words..]);
    Ok(file)
}

/// How much the felt force changes from `full` to `web` (the same vademecum through its web
/// form): the relative change of the force for a 1 mm press along the surface normal at the
/// centre of each surface triangle.
pub fn felt_force_changes(full: &Vademecum, web: &Vademecum) -> Vec<f64> {
    full.triangles
        .iter()
        .enumerate()
        .map(|(triangle, corners)| {
            let at = SurfacePoint {
                triangle,
                barycentric: [1.0 / 3.0; 3],
            };
            let normal: Vector3<f64> = corners
                .iter()
                .map(|&p| Vector3::from(full.position_normals[p as usize].map(f64::from)))
                .sum();
            let press = -1e-3 * normal.normalize();
            let exact = full.force_for_indentation(&at, &press);
            let rounded = web.force_for_indentation(&at, &press);
            (rounded - exact).norm() / exact.norm()
        })
        .collect()
}

/// `value` to the nearest number with [`MANTISSA_BITS`] bits of mantissa.
fn round(value: f32) -> f32 {
    let dropped = f32::MANTISSA_DIGITS - 1 - MANTISSA_BITS;
    let half = 1u32 << (dropped - 1);
    // Adding half a unit to the bit pattern rounds to nearest, carrying into the exponent when
    // the mantissa overflows: the bits of finite floats order like their magnitudes.
    f32::from_bits(((value.to_bits() + half) >> dropped) << dropped)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rounding keeps the sign, changes a value by at most 2^-11 of it, and maps a value that
    /// already fits to itself.
    #[test]
    fn rounding_is_to_the_nearest_short_mantissa() {
        for &v in &[1.0f32, -3.25e-7, 0.1, 123_456.79, -9.999_999e-3, 1.999_999] {
            let r = round(v);
            assert_eq!(r.signum(), v.signum());
            assert!(
                ((r - v) / v).abs() <= 2f32.powi(-(MANTISSA_BITS as i32) - 1),
                "{v} → {r}"
            );
            assert_eq!(round(r), r);
            assert_eq!(r.to_bits() & ((1 << 13) - 1), 0);
        }
        assert_eq!(round(0.0), 0.0);
    }

    /// Any bytes come back exactly, a file's or not.
    #[test]
    fn expanding_undoes_deflating() {
        let bytes: Vec<u8> = (0..1001u32).map(|k| (k * 7 % 251) as u8).collect();
        assert_eq!(expand(Path::new("x"), &deflated(&bytes)).unwrap(), bytes);
        assert_eq!(
            expand(Path::new("x"), &deflated(&[])).unwrap(),
            Vec::<u8>::new()
        );
    }

    #[test]
    fn a_damaged_web_form_is_refused_with_its_file() {
        let mut bytes = deflated(b"a distance field");
        bytes.truncate(bytes.len() / 2);
        let error = expand(Path::new("site/field.vdf.web"), &bytes).unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("site/field.vdf.web: malformed web form")
        );
    }
}
