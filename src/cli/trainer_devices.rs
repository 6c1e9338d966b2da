//! `trainer devices`: every device backend, whether it can be used here, and why not.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::app::missing_display;
use crate::devices::{DeviceError, ForceDimension, Haply, OpenHaptics};

/// One backend: how the command line names it, whether it is usable here, and what to know.
struct Backend {
    spec: &'static str,
    usable: bool,
    note: String,
}

/// A backend over a vendor library: usable when the library loads, else why not.
fn vendor(spec: &'static str, devices: &str, found: Result<PathBuf, DeviceError>) -> Backend {
    match found {
        Ok(path) => Backend {
            spec,
            usable: true,
            note: format!(
                "{devices}: library {} (the device is opened when the trainer starts)",
                path.display()
            ),
        },
        Err(e) => Backend {
            spec,
            usable: false,
            note: e.to_string(),
        },
    }
}

/// The Haply backend: usable when a Haply Inverse Service answers at its address (the
/// variable `PGD_HAPLY_URL`'s, else the default), else why not.
fn haply() -> Backend {
    match Haply::probe(None) {
        Ok((url, version)) => Backend {
            spec: "haply[:URL][@ID]",
            usable: true,
            note: format!(
                "Haply Inverse3: the Haply Inverse Service {version} answers at {url} (the \
                 device is opened when the trainer starts)"
            ),
        },
        Err(e) => Backend {
            spec: "haply[:URL][@ID]",
            usable: false,
            note: e.to_string(),
        },
    }
}

/// Prints the table of backends; succeeds whatever is found.
pub fn list_devices() -> ExitCode {
    let backends = [
        Backend {
            spec: "scripted:FILE",
            usable: true,
            note: "replays a trajectory CSV (time_s,x_m,y_m,z_m,buttons): tests, demos, --headless"
                .into(),
        },
        match missing_display() {
            None => Backend {
                spec: "virtual",
                usable: true,
                note: "the mouse in the trainer window (the default there)".into(),
            },
            Some(why) => Backend {
                spec: "virtual",
                usable: false,
                note: format!("needs the window: {why}"),
            },
        },
        vendor(
            "openhaptics[:NAME]",
            "Geomagic Touch, Touch X, Phantom",
            OpenHaptics::find_library(),
        ),
        vendor(
            "forcedimension",
            "Force Dimension omega, sigma, delta",
            ForceDimension::find_library(),
        ),
        haply(),
    ];
    println!("{:<20} {:<8} notes", "device", "usable");
    for b in &backends {
        let usable = if b.usable { "yes" } else { "no" };
        println!("{:<20} {usable:<8} {}", b.spec, b.note);
    }
    ExitCode::SUCCESS
}
