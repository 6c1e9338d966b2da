//! `trainer soak`: an hour of scripted use on the simulated clock, its progress on the error
//! stream and its report as a table or JSON.

use std::process::ExitCode;

use crate::app::soak::{SoakPlan, soak};

use super::{fail, print_json};

/// Runs the soak and prints its report; fails when a force was not finite or an attempt was
/// scored but not kept.
pub fn run_soak(plan: &SoakPlan, json: bool) -> ExitCode {
    let mut next_minute = 60.0;
    let result = soak(plan, |simulated_s, title, score| {
        if simulated_s >= next_minute {
            eprintln!("soak: {simulated_s:>6.0} s simulated; last attempt: {title}, {score:.0}");
            next_minute = (simulated_s / 60.0).floor() * 60.0 + 60.0;
        }
    });
    let report = match result {
        Ok(report) => report,
        Err(e) => return fail("trainer soak", &e),
    };
    match json {
        true => print_json(&report),
        false => {
            print!("{report}");
            ExitCode::SUCCESS
        }
    };
    if report.nan_count > 0 || report.attempts_kept < report.attempts_scored {
        return fail(
            "trainer soak",
            "a force was not finite or an attempt was not kept (see the report)",
        );
    }
    ExitCode::SUCCESS
}
