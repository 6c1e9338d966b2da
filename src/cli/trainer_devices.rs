//! `trainer devices`: every device backend, whether it can be used here, and why not.

use std::process::ExitCode;

use crate::app::missing_display;
use crate::devices::OpenHaptics;

/// One backend: how the command line names it, whether it is usable here, and what to know.
struct Backend {
    spec: &'static str,
    usable: bool,
    note: String,
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
        match OpenHaptics::find_library() {
            Ok(path) => Backend {
                spec: "openhaptics[:NAME]",
                usable: true,
                note: format!(
                    "Geomagic Touch, Touch X, Phantom: HD library {} (the device is opened when the trainer starts)",
                    path.display()
                ),
            },
            Err(e) => Backend {
                spec: "openhaptics[:NAME]",
                usable: false,
                note: e.to_string(),
            },
        },
        Backend {
            spec: "forcedimension",
            usable: false,
            note: "Force Dimension omega, sigma, delta: not supported yet".into(),
        },
        Backend {
            spec: "haply[:PORT]",
            usable: false,
            note: "Haply Inverse3: not supported yet".into(),
        },
    ];
    println!("{:<20} {:<8} notes", "device", "usable");
    for b in &backends {
        let usable = if b.usable { "yes" } else { "no" };
        println!("{:<20} {usable:<8} {}", b.spec, b.note);
    }
    ExitCode::SUCCESS
}
