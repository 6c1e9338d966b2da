//! A build split in shards run as local processes through the cluster script, then merged by
//! `pgd merge`, writes the whole build's vademecum; a merge with a shard missing is refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pgd(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pgd"))
        .args(args)
        .output()
        .unwrap()
}

fn succeeded(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The vademecum's bytes, less the build's time in its header.
fn bytes(path: &Path) -> Vec<u8> {
    let mut vademecum = pgd_surgery::pgd::load(path).unwrap();
    vademecum.header.build_seconds = 0.0;
    pgd_surgery::pgd::encode(&vademecum)
}

#[test]
fn shards_run_as_processes_merge_into_the_whole_build() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pgd-shards");
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).unwrap();
    let block = pgd_surgery::mesh::box_mesh([0.06, 0.04, 0.02], [12, 8, 2]).unwrap();
    let mesh = folder.join("block.vtu");
    pgd_surgery::mesh::io::write_vtu(&mesh, &block, &[]).unwrap();
    let path = |name: &str| folder.join(name).to_str().unwrap().to_owned();
    let mesh = mesh.to_str().unwrap();
    let build = [
        "build",
        mesh,
        "--clamp",
        "region:z0",
        "--accessible",
        "region:z1",
        "--tool-radius-mm",
        "12",
        "--local-radius-mm",
        "15",
    ];
    let whole = path("whole.vdm");
    succeeded(&pgd(&[&build[..], &["--out", &whole]].concat()));

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/cluster/pgd-shard.sh");
    let vademecum = path("block.vdm");
    let shards: Vec<_> = (0..3)
        .map(|index| {
            Command::new(&script)
                .arg("3")
                .args(&build[1..])
                .args(["--out", &vademecum])
                .env("PGD", env!("CARGO_BIN_EXE_pgd"))
                .env("JOB_COMPLETION_INDEX", index.to_string())
                .env_remove("SLURM_ARRAY_TASK_ID")
                .spawn()
                .unwrap()
        })
        .collect();
    for mut shard in shards {
        assert!(shard.wait().unwrap().success());
    }
    let parts: Vec<PathBuf> = (1..=3)
        .map(|k| folder.join(format!("block.part-{k}-of-3.vdp")))
        .collect();
    let part_names: Vec<&str> = parts.iter().rev().map(|p| p.to_str().unwrap()).collect();
    let merged = path("merged.vdm");
    let stdout = succeeded(&pgd(
        &[&["merge"], &part_names[..], &["--out", &merged]].concat()
    ));
    assert!(stdout.contains("wrote"), "{stdout}");
    assert!(bytes(Path::new(&merged)) == bytes(Path::new(&whole)));

    let out = pgd(&["merge", part_names[0], part_names[2], "--out", &merged]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("shards [2] of 3 are missing"), "{stderr}");
}
