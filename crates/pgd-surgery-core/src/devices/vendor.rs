//! What every hardware backend does with its vendor's C library: find it (a variable naming
//! the file, or the loader's search), load it at run time, resolve its functions, each failure
//! one message that names the file and what to install.

use std::path::{Path, PathBuf};

use libloading::Library;

use super::{DeviceError, DeviceLimits};

/// A vendor library the trainer can load.
pub struct VendorLibrary {
    /// The backend's name in messages (`openhaptics`, `forcedimension`).
    pub backend: &'static str,
    /// The file's name for the dynamic loader.
    pub file: &'static str,
    /// The environment variable that names another file.
    pub variable: &'static str,
    /// What to install when it is missing.
    pub install: &'static str,
}

impl VendorLibrary {
    /// The file to load: the variable's, or the plain name through the loader's search.
    pub fn path(&self) -> PathBuf {
        std::env::var_os(self.variable).map_or_else(|| PathBuf::from(self.file), PathBuf::from)
    }

    fn failed(&self, message: String) -> DeviceError {
        DeviceError::Failed {
            device: self.backend.into(),
            message,
        }
    }

    /// Loads the library at `path`.
    pub fn load(&self, path: &Path) -> Result<Library, DeviceError> {
        // SAFETY: loading runs the library's initializers; it is the vendor's SDK (or a fake).
        unsafe { Library::new(path) }.map_err(|e| {
            self.failed(format!(
                "cannot load `{}` ({e}); install {}, or name the library's file in {}",
                path.display(),
                self.install,
                self.variable
            ))
        })
    }

    /// The function `name` of `library`, loaded from `path`.
    ///
    /// # Safety
    /// `T` must be the function's C type as the vendor's header declares it.
    pub unsafe fn function<T: Copy>(
        &self,
        library: &Library,
        path: &Path,
        name: &str,
    ) -> Result<T, DeviceError> {
        // SAFETY: the caller names the symbol's type.
        let symbol = unsafe { library.get::<T>(name.as_bytes()) };
        symbol.map(|s| *s).map_err(|e| {
            self.failed(format!(
                "`{}` lacks {name} ({e}): not the library of {}",
                path.display(),
                self.install
            ))
        })
    }
}

/// The limits a vendor's driver reported, held to the product's ceiling; the warning, when
/// the driver reported more, goes to the error stream as the device opens.
pub fn held_to_ceiling(reported: DeviceLimits, device: &str) -> DeviceLimits {
    let (limits, warning) = reported.within_ceiling(device);
    if let Some(warning) = warning {
        eprintln!("{warning}");
    }
    limits
}
