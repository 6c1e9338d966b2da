//! Fakes of vendor haptic libraries (`tests/haptics/fake_*.c`), built once per run with the
//! system C compiler; each test loads its own copy, so that their states stay apart, and drives
//! it through the fake's `fake_*` controls. Shared by the haptics and the window tests.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use libloading::{Library, Symbol};
use nalgebra::Vector3;

/// The shared library built from `tests/haptics/<source>.c`, once per process.
fn built(source: &str) -> PathBuf {
    static BUILT: Mutex<Option<HashMap<String, PathBuf>>> = Mutex::new(None);
    let mut built = BUILT.lock().unwrap();
    let built = built.get_or_insert_with(HashMap::new);
    if let Some(path) = built.get(source) {
        return path.clone();
    }
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/haptics/{source}.c"));
    // Named after the process too: the exit tests run this binary again in child processes,
    // which build their own while this one copies its.
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lib{source}.{}.so", std::process::id()));
    let status = std::process::Command::new("cc")
        .args(["-shared", "-fPIC", "-O1", "-pthread", "-o"])
        .arg(&out)
        .arg(&file)
        .arg("-lm")
        .status()
        .expect("a C compiler (cc) builds the fake vendor library");
    assert!(status.success(), "cc failed on {}", file.display());
    built.insert(source.to_owned(), out.clone());
    out
}

/// One test's copy of a fake.
pub struct VendorFake {
    pub path: PathBuf,
    library: Library,
}

impl VendorFake {
    /// `test`'s own copy of the fake built from `source`.
    pub fn new(source: &str, test: &str) -> Self {
        let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("lib{source}-{test}.so"));
        std::fs::copy(built(source), &path).unwrap();
        // SAFETY: the fake is ours.
        let library = unsafe { Library::new(&path) }.unwrap();
        Self { path, library }
    }

    /// The control `name`, of C type `T`.
    pub fn call<T>(&self, name: &str) -> Symbol<'_, T> {
        // SAFETY: the test names each control with its C type.
        unsafe { self.library.get(name.as_bytes()) }.unwrap()
    }

    /// A control without arguments returning an int.
    pub fn int(&self, name: &str) -> i32 {
        // SAFETY: as named.
        unsafe { self.call::<unsafe extern "C" fn() -> i32>(name)() }
    }

    /// A control without arguments returning a long.
    pub fn long(&self, name: &str) -> i64 {
        // SAFETY: as named.
        unsafe { self.call::<unsafe extern "C" fn() -> i64>(name)() }
    }

    /// A control without arguments returning a double.
    pub fn double(&self, name: &str) -> f64 {
        // SAFETY: as named.
        unsafe { self.call::<unsafe extern "C" fn() -> f64>(name)() }
    }

    /// A control that writes three doubles.
    pub fn vector(&self, name: &str) -> Vector3<f64> {
        let mut out = [0.0; 3];
        // SAFETY: three doubles.
        unsafe { self.call::<unsafe extern "C" fn(*mut f64)>(name)(out.as_mut_ptr()) };
        Vector3::from(out)
    }

    /// Waits until the long control `counter` has grown by `by` (five seconds at most).
    pub fn wait(&self, counter: &str, by: i64) {
        let until = self.long(counter) + by;
        let give_up = Instant::now() + Duration::from_secs(5);
        while self.long(counter) < until && Instant::now() < give_up {
            std::thread::sleep(Duration::from_micros(200));
        }
    }
}
