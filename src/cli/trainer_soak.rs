//! `trainer soak`: an hour of scripted use on the simulated clock, its progress on the error
//! stream, its report as a table or JSON, and its memory curve as a plot.

use std::path::Path;
use std::process::ExitCode;

use crate::app::soak::{SoakPlan, SoakReport, soak};
use crate::report::{LineChart, Series, line_chart};

use super::{fail, print_json};

/// Runs the soak and prints its report, plotting its memory curve at `plot`; fails when a
/// force was not finite or an attempt was scored but not kept.
pub fn run_soak(plan: &SoakPlan, json: bool, plot: Option<&Path>) -> ExitCode {
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
    if let Some(path) = plot
        && let Err(e) = plot_memory(&report, path)
    {
        return fail("trainer soak --plot", &e);
    }
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

/// The resident memory every simulated minute (MiB against minutes).
fn plot_memory(report: &SoakReport, path: &Path) -> Result<(), String> {
    let points = (report.memory.iter())
        .map(|s| (s.simulated_s / 60.0, s.bytes as f64 / (1024.0 * 1024.0)))
        .collect();
    line_chart(
        path,
        &LineChart {
            title: format!(
                "trainer soak: resident memory, {} attempts",
                report.attempts_scored
            ),
            x_label: "simulated minutes",
            y_label: "resident memory (MiB)",
            series: vec![Series {
                name: "resident memory".into(),
                points,
            }],
        },
    )
}
