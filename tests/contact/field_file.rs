//! The distance-field file (`.vdf`): a round trip is lossless, a scene's master loads its
//! field when it is the one for its vademecum and lattice and rebuilds it otherwise, and every
//! kind of bad file is refused with a message that names the file and the problem.

use std::path::PathBuf;

use pgd_surgery::contact::{ContactSurface, DistanceField, DistanceSettings, FieldOrigin};
use pgd_surgery::pgd::{VademecumError, save};

use crate::common::organ;

/// A coarse lattice: these tests are about the file, not the field's accuracy.
const LATTICE: DistanceSettings = DistanceSettings {
    spacing_m: 6e-3,
    margin_m: 6e-3,
};

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pgd-field-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn gallbladder_field() -> DistanceField {
    let (_, gallbladder) = organ("gallbladder");
    DistanceField::build(
        gallbladder,
        &ContactSurface::new(gallbladder).unwrap(),
        &LATTICE,
    )
}

#[test]
fn a_saved_field_loads_back_identical_and_fits_its_vademecum_and_lattice_only() {
    let (_, gallbladder) = organ("gallbladder");
    let field = gallbladder_field();
    let path = temp("roundtrip.vdf");
    field.save(&path).unwrap();
    let back = DistanceField::load(&path).unwrap();
    assert_eq!(back, field);
    back.check_for(&path, gallbladder, &LATTICE).unwrap();
    // One mode value changed by one part in a thousand: another vademecum.
    let mut other = gallbladder.clone();
    other.steps[0].spatial[3 * other.positions[0] as usize] *= 1.001;
    let err = back.check_for(&path, &other, &LATTICE).unwrap_err();
    assert!(
        matches!(err, VademecumError::OtherVademecum { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("roundtrip.vdf"), "{err}");
    let finer = DistanceSettings {
        spacing_m: 3e-3,
        ..LATTICE
    };
    let err = back.check_for(&path, gallbladder, &finer).unwrap_err();
    assert!(matches!(err, VademecumError::OtherSettings { .. }), "{err}");
}

#[test]
fn bad_field_files_are_refused_with_the_file_and_the_problem() {
    let field = gallbladder_field();
    let path = temp("bad.vdf");
    field.save(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let refused = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        let err = DistanceField::load(&path).unwrap_err();
        assert!(err.to_string().contains("bad.vdf"), "{err}");
        err
    };
    let err = refused(&bytes[..bytes.len() / 2]);
    assert!(matches!(err, VademecumError::Truncated { .. }), "{err}");
    let mut flipped = bytes.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 1;
    let err = refused(&flipped);
    assert!(matches!(err, VademecumError::Corrupted { .. }), "{err}");
    let mut newer = bytes.clone();
    newer[8] += 1;
    let err = refused(&newer);
    assert!(matches!(err, VademecumError::Version { .. }), "{err}");
    // A vademecum is not a distance field.
    let (_, gallbladder) = organ("gallbladder");
    save(&path, gallbladder).unwrap();
    let err = DistanceField::load(&path).unwrap_err();
    assert!(matches!(err, VademecumError::NotAVademecum { .. }), "{err}");
    assert!(
        err.to_string().contains("not a distance field file"),
        "{err}"
    );
}

/// The first scene builds the field and saves it; the next loads it; a stale or damaged one is
/// rebuilt and replaced, never used.
#[test]
fn a_scene_loads_its_stored_field_and_rebuilds_a_stale_one() {
    let (_, gallbladder) = organ("gallbladder");
    let surface = ContactSurface::new(gallbladder).unwrap();
    let path = temp("scene.vdf");
    let _ = std::fs::remove_file(&path);
    let load_or_build = || DistanceField::load_or_build(gallbladder, &surface, &LATTICE, &path);
    let (built, origin) = load_or_build();
    assert!(origin.to_string().contains("not built yet"), "{origin}");
    match origin {
        FieldOrigin::Built { why, saved } => {
            assert!(matches!(why, VademecumError::Io { .. }), "{why}");
            saved.unwrap();
        }
        FieldOrigin::Loaded => panic!("there was no file to load"),
    }
    let (loaded, origin) = load_or_build();
    assert!(matches!(origin, FieldOrigin::Loaded), "{origin}");
    assert_eq!(loaded, built);
    let finer = DistanceSettings {
        spacing_m: 5e-3,
        ..LATTICE
    };
    let (rebuilt, origin) = DistanceField::load_or_build(gallbladder, &surface, &finer, &path);
    assert!(
        matches!(
            &origin,
            FieldOrigin::Built {
                why: VademecumError::OtherSettings { .. },
                saved: Ok(())
            }
        ),
        "{origin}"
    );
    assert_eq!(rebuilt.spacing_m(), 5e-3);
    assert_eq!(DistanceField::load(&path).unwrap(), rebuilt);
}
