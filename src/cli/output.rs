//! How the binaries end a command: a report as JSON or as its table, or an error named after
//! the command, with the exit status to match.

use std::process::ExitCode;

/// A benchmark's report as JSON or as its table, or its error.
pub fn print_report<R, E>(command: &str, result: Result<R, E>, json: bool) -> ExitCode
where
    R: serde::Serialize + std::fmt::Display,
    E: std::fmt::Display,
{
    match result {
        Ok(report) if json => print_json(&report),
        Ok(report) => {
            print!("{report}");
            ExitCode::SUCCESS
        }
        Err(e) => fail(command, &e.to_string()),
    }
}

pub fn print_json(value: &impl serde::Serialize) -> ExitCode {
    println!(
        "{}",
        serde_json::to_string_pretty(value).expect("plain data serializes")
    );
    ExitCode::SUCCESS
}

/// Prints `command: message` to stderr; the command failed.
pub fn fail(command: &str, message: &str) -> ExitCode {
    eprintln!("{command}: {message}");
    ExitCode::FAILURE
}
