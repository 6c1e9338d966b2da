//! `trainer history`: the attempts kept so far, as a table and a learning-curve plot, or as
//! CSV for an educator; and keeping each new attempt at the end of its debrief.

use std::path::Path;
use std::process::ExitCode;

use crate::history::{
    AttemptRecord, HistoryError, HistoryFilter, Kept, Store, keep_attempt, now_unix_s,
    read_attempts,
};
use crate::report::{CurvePoint, learning_curve};
use crate::scenario::Scorecard;

/// Where attempts are kept, whose they are, and the station they are made on.
#[derive(Clone, Debug)]
pub struct HistoryTarget {
    pub store: Store,
    pub trainee: String,
    pub station: String,
}

/// Keeps a scored attempt in the history; says where it went. Fails only when the attempt
/// could be kept neither in the database nor beside it.
pub fn keep_scored(
    target: &HistoryTarget,
    card: &Scorecard,
    scenario: &Path,
    report: Option<&Path>,
) -> ExitCode {
    let record = AttemptRecord::of(card, scenario, &target.trainee, report, now_unix_s())
        .at_station(&target.station);
    let (trainee, store) = (&target.trainee, target.store.shown());
    match keep_attempt(&target.store, &record) {
        Ok(Kept::Local { id }) => {
            eprintln!("history: attempt {id} of {trainee} kept in {store}");
            ExitCode::SUCCESS
        }
        Ok(Kept::Shared { sent }) => {
            let queued = match sent {
                1 => String::new(),
                n => format!(", with {} attempts queued before", n - 1),
            };
            eprintln!("history: the attempt of {trainee} kept in {store}{queued}");
            ExitCode::SUCCESS
        }
        Ok(Kept::Queued { reason, pending }) => {
            eprintln!(
                "history: {store} cannot be reached ({reason}); the attempt of {trainee} is kept \
                 in {} and will be sent with the next one ({pending} waiting)",
                target.store.local().display()
            );
            ExitCode::SUCCESS
        }
        Err(e @ HistoryError::SetAside { .. }) => {
            eprintln!("trainer: {e}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("trainer: {e}");
            ExitCode::FAILURE
        }
    }
}

/// What `trainer history` is asked.
pub struct HistoryRequest<'a> {
    pub store: &'a Store,
    pub filter: HistoryFilter,
    /// CSV on standard output instead of the table and the plot.
    pub csv: bool,
    pub plot: &'a Path,
}

/// Lists the attempts the request selects.
pub fn show_history(request: &HistoryRequest) -> ExitCode {
    if let Store::Local(database) = request.store
        && !database.exists()
    {
        eprintln!(
            "trainer: no history at {} yet: attempts are kept there as they are scored",
            database.display()
        );
        return ExitCode::FAILURE;
    }
    let attempts = match read_attempts(request.store, &request.filter) {
        Ok((attempts, warning)) => {
            if let Some(warning) = warning {
                eprintln!("trainer: warning: {warning}");
            }
            attempts
        }
        Err(e) => {
            eprintln!("trainer: {e}");
            return ExitCode::FAILURE;
        }
    };
    let shown = match request.csv {
        true => write_csv(&attempts),
        false => print_table(&attempts, request.plot),
    };
    match shown {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("trainer: {e}");
            ExitCode::FAILURE
        }
    }
}

fn write_csv(attempts: &[AttemptRecord]) -> Result<(), String> {
    let mut out = csv::Writer::from_writer(std::io::stdout());
    out.write_record([
        "id",
        "trainee",
        "scenario",
        "title",
        "when",
        "score",
        "passed",
        "time_s",
        "path_mm",
        "peak_force_n",
        "errors",
        "report",
        "proficient",
    ])
    .map_err(|e| e.to_string())?;
    for a in attempts {
        out.write_record([
            a.id.to_string(),
            a.trainee.clone(),
            a.scenario.clone(),
            a.title.clone(),
            a.when(),
            format!("{:.1}", a.score),
            a.passed.to_string(),
            format!("{:.2}", a.time_s),
            format!("{:.1}", a.path_mm),
            format!("{:.3}", a.peak_force_n),
            a.errors.to_string(),
            a.report.clone(),
            a.proficient.map_or_else(String::new, |p| p.to_string()),
        ])
        .map_err(|e| e.to_string())?;
    }
    out.flush().map_err(|e| e.to_string())
}

/// "passed" or "failed", and "proficient" where the attempt met its scenario's benchmark.
fn result(a: &AttemptRecord) -> &'static str {
    match (a.passed, a.proficient) {
        (true, Some(true)) => "proficient",
        (true, _) => "passed",
        (false, _) => "failed",
    }
}

fn print_table(attempts: &[AttemptRecord], plot: &Path) -> Result<(), String> {
    println!(
        "{:>4}  {:<20}  {:<12}  {:<32}  {:>5}  {:<10}  {:>7}  {:>8}  {:>6}  errors",
        "id", "when", "trainee", "scenario", "score", "result", "time s", "path mm", "peak N"
    );
    for a in attempts {
        println!(
            "{:>4}  {:<20}  {:<12}  {:<32}  {:>5.0}  {:<10}  {:>7.1}  {:>8.0}  {:>6.2}  {}",
            a.id,
            a.when(),
            a.trainee,
            a.title,
            a.score,
            result(a),
            a.time_s,
            a.path_mm,
            a.peak_force_n,
            a.errors
        );
    }
    if attempts.is_empty() {
        println!("(no attempt matches)");
        return Ok(());
    }
    if let Some(folder) = plot.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    }
    let points: Vec<CurvePoint> = attempts
        .iter()
        .map(|a| CurvePoint {
            scenario: &a.title,
            score: a.score,
            time_s: a.time_s,
        })
        .collect();
    learning_curve(plot, &points)?;
    eprintln!("learning curve: {}", plot.display());
    Ok(())
}
