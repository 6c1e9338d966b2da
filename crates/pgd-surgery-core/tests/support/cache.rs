//! The vademecums tests build, kept in one folder that every test binary of the workspace and
//! the slow tier share, and that outlives a run: under the target directory, in a folder named
//! for the builder's source hash (`pgd::BUILDER_SOURCE_HASH`). A change to the builder's code
//! starts an empty folder, so a warm cache never passes what older code built; the folders of
//! other hashes are removed then. A vademecum in it is still checked against its mesh,
//! material and settings when loaded, as any other.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use pgd_surgery_core::pgd::BUILDER_SOURCE_HASH;

pub fn vademecum_cache() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("vademecum-cache");
        let dir = root.join(BUILDER_SOURCE_HASH);
        if !dir.is_dir() {
            remove_other_hashes(&root);
            std::fs::create_dir_all(&dir).unwrap();
        }
        dir
    })
}

fn remove_other_hashes(root: &Path) {
    let Ok(entries) = std::fs::read_dir(root) else {
        return;
    };
    for entry in entries.flatten() {
        // Another binary may be removing the same folder: what is gone is gone.
        let _ = std::fs::remove_dir_all(entry.path());
    }
}
