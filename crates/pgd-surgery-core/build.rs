//! The builder's own version: a hash of the source of every module a vademecum build runs
//! (`BUILDER_SOURCE_HASH`), so that what was built by other code is told apart from what this
//! code would build — the tests' shared cache of vademecums is keyed by it.

use std::hash::{DefaultHasher, Hasher};
use std::path::{Path, PathBuf};

/// What a build runs: the mesh, its FEM model, the PGD build with its contact fields and cut
/// sections, the dense sums, and the store that drives it.
const BUILDER: [&str; 9] = [
    "src/mesh",
    "src/fem",
    "src/pgd",
    "src/contact",
    "src/cutting",
    "src/dynamics",
    "src/store",
    "src/dense_sums.rs",
    "src/parry_interop.rs",
];

fn main() {
    let mut files = Vec::new();
    for path in BUILDER {
        println!("cargo:rerun-if-changed={path}");
        collect(Path::new(path), &mut files);
    }
    files.sort();
    let mut hasher = DefaultHasher::new();
    for file in &files {
        hasher.write(file.to_string_lossy().as_bytes());
        hasher.write(&std::fs::read(file).expect("a builder source file is readable"));
    }
    println!(
        "cargo:rustc-env=BUILDER_SOURCE_HASH={:016x}",
        hasher.finish()
    );
}

/// The Rust files at `path`, a file or a folder walked whole.
fn collect(path: &Path, files: &mut Vec<PathBuf>) {
    if path.is_file() {
        files.push(path.to_owned());
        return;
    }
    let entries = std::fs::read_dir(path).expect("a builder source folder is readable");
    for entry in entries {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() || path.extension().is_some_and(|e| e == "rs") {
            collect(&path, files);
        }
    }
}
