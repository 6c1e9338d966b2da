//! A build split in shards and merged gives the whole build's vademecum, to the last bit;
//! parts that are not one build's, or not all of it, are refused by name.

use pgd_surgery_core::fem::{FemModel, Law};
use pgd_surgery_core::pgd::{
    BuildSettings, MergeError, PartFile, Shard, Silent, Vademecum, build, build_shard, load_part,
    merge, save_part,
};

use super::common::{block_mesh, block_model_of, organ, settings, temp_dir};

/// A block whose top face holds more than two blocks of 48 positions.
fn model(law: Law) -> FemModel {
    block_model_of(block_mesh([12, 8, 2]), law)
}

fn ksv_settings() -> BuildSettings {
    BuildSettings {
        load_steps_m: vec![0.5e-3, 1.0e-3],
        ..settings(30, 1e-3)
    }
}

/// The parts of `count` shards, written to files and read back.
fn parts(model: &FemModel, settings: &BuildSettings, count: usize, dir: &str) -> Vec<PartFile> {
    let dir = temp_dir(dir);
    (1..=count)
        .map(|index| {
            let shard = Shard { index, count };
            let part = build_shard(
                &organ(model),
                settings,
                shard,
                vec!["block".into()],
                &Silent,
            )
            .unwrap();
            let path = dir.join(format!("block.part-{index}-of-{count}"));
            save_part(&path, &part).unwrap();
            load_part(&path).unwrap()
        })
        .collect()
}

/// The file's bytes, less the build's time in its header.
fn bytes(mut vademecum: Vademecum) -> Vec<u8> {
    vademecum.header.build_seconds = 0.0;
    pgd_surgery_core::pgd::encode(&vademecum)
}

fn assert_merged_equals_whole(law: Law, settings: &BuildSettings, counts: &[usize]) {
    let model = model(law);
    let (whole, whole_report) = build(&organ(&model), settings, &Silent).unwrap();
    assert!(
        whole.positions.len() > 96,
        "{} positions",
        whole.positions.len()
    );
    for &count in counts {
        let dir = format!("shards-{}-{count}", law.name());
        let mut parts = parts(&model, settings, count, &dir);
        parts.reverse(); // any order
        let (merged, report) = merge(&organ(&model), settings, parts, &Silent).unwrap();
        assert_eq!(report.steps.len(), whole_report.steps.len());
        assert_eq!(report.positions_loaded, whole_report.positions_loaded);
        assert!(
            bytes(merged) == bytes(whole.clone()),
            "{}: {count} shards merged differ from the whole build",
            law.name()
        );
    }
}

#[test]
fn merged_linear_shards_are_the_whole_build() {
    // Six shards of the block's four blocks of positions: two of them empty.
    assert_merged_equals_whole(Law::Linear, &settings(30, 1e-3), &[1, 2, 3, 6]);
}

#[test]
fn merged_ksv_shards_are_the_whole_build() {
    assert_merged_equals_whole(Law::KirchhoffSaintVenant, &ksv_settings(), &[1, 2, 3]);
}

#[test]
fn parts_of_another_build_or_missing_ones_are_refused() {
    let model = model(Law::Linear);
    let settings = settings(30, 1e-3);
    let refused = |parts| merge(&organ(&model), &settings, parts, &Silent).unwrap_err();
    let mut three = parts(&model, &settings, 3, "refused");
    three.remove(1);
    let missing = refused(three);
    assert!(
        matches!(&missing, MergeError::Missing { count: 3, missing } if missing == &[2]),
        "{missing}"
    );
    let mut doubled = parts(&model, &settings, 2, "doubled");
    doubled[1] = parts(&model, &settings, 2, "doubled-again").remove(0);
    let twice = refused(doubled);
    assert!(matches!(twice, MergeError::Twice { .. }), "{twice}");
    assert!(twice.to_string().contains("shard 1/2"), "{twice}");
    let mut mixed = parts(&model, &settings, 2, "mixed");
    let fewer_modes = super::common::settings(20, 1e-3);
    mixed[1] = parts(&model, &fewer_modes, 2, "mixed-other").remove(1);
    let other = refused(mixed);
    assert!(
        other.to_string().contains("build settings differ"),
        "{other}"
    );
    assert!(matches!(refused(Vec::new()), MergeError::NoParts));
}
