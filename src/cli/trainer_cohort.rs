//! `trainer history --cohort`: a programme's view of its trainees (all, or a group), each
//! one's standing in a curriculum as a table, and the cohort's learning curves (one PNG, one
//! CSV).

use std::path::Path;
use std::process::ExitCode;

use super::trainer_curriculum::counted;
use crate::history::{AttemptRecord, HistoryFilter, Store, read_attempts};
use crate::report::{CurvePoint, learning_curve};
use crate::scenario::curriculum::{Curriculum, ModuleState, load_curriculum, standing};

/// What `trainer history --cohort` is asked.
pub struct CohortRequest<'a> {
    pub store: &'a Store,
    pub curriculum: &'a Path,
    /// Where the cohort's learning curves go (the CSV beside it, `.csv`).
    pub plot: &'a Path,
    /// Only these trainees; all when empty.
    pub group: &'a [String],
}

/// Prints each trainee's standing and writes the cohort's learning curves.
pub fn show_cohort(request: &CohortRequest) -> ExitCode {
    let curriculum = match load_curriculum(request.curriculum) {
        Ok(curriculum) => curriculum,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let all = HistoryFilter::default();
    let mut attempts = match read_attempts(request.store, &all) {
        Ok((attempts, warning)) => {
            if let Some(warning) = warning {
                eprintln!("trainer history: warning: {warning}");
            }
            attempts
        }
        Err(e) => return super::fail("trainer history", &e.to_string()),
    };
    if !request.group.is_empty() {
        attempts.retain(|a| request.group.contains(&a.trainee));
    }
    print!("{}", cohort_table(&curriculum, &attempts));
    match write_curves(&attempts, request.plot) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => super::fail("trainer history", &e),
    }
}

/// The trainees in the order of their first attempt.
fn trainees(attempts: &[AttemptRecord]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for a in attempts {
        if !names.contains(&a.trainee.as_str()) {
            names.push(&a.trainee);
        }
    }
    names
}

/// One row a trainee: each module's state, the exercises had, the attempts, the last report.
fn cohort_table(curriculum: &Curriculum, attempts: &[AttemptRecord]) -> String {
    let exercises: usize = curriculum.modules.iter().map(|m| m.exercises.len()).sum();
    let count = trainees(attempts).len();
    let plural = if count == 1 { "" } else { "s" };
    let mut text = format!("{}: {count} trainee{plural}\n", curriculum.title);
    let modules: Vec<String> = (1..=curriculum.modules.len())
        .map(|k| format!("module {k}"))
        .collect();
    text += &format!(
        "{:<14}  {}  {:>6}  {:>8}  last report\n",
        "trainee",
        modules
            .iter()
            .map(|m| format!("{m:<10}"))
            .collect::<String>(),
        "had",
        "attempts"
    );
    for trainee in trainees(attempts) {
        let theirs: Vec<&AttemptRecord> =
            attempts.iter().filter(|a| a.trainee == trainee).collect();
        let stands = standing(curriculum, &counted(theirs.iter().copied()));
        let states: String = (stands.iter())
            .map(|m| match m.state {
                ModuleState::Done => "done",
                ModuleState::Open => "open",
                ModuleState::Locked => "locked",
            })
            .map(|state| format!("{state:<10}"))
            .collect();
        let had = stands
            .iter()
            .flat_map(|m| &m.exercises)
            .filter(|e| e.had())
            .count();
        let last = theirs.last().map_or("", |a| a.report.as_str());
        text += &format!(
            "{trainee:<14}  {states}  {:>6}  {:>8}  {last}\n",
            format!("{had}/{exercises}"),
            theirs.len()
        );
    }
    text
}

/// Each trainee's scores and times over their attempts, one series each: the plot at `plot`
/// and its numbers as CSV beside it.
fn write_curves(attempts: &[AttemptRecord], plot: &Path) -> Result<(), String> {
    if attempts.is_empty() {
        println!("(no attempt yet)");
        return Ok(());
    }
    if let Some(folder) = plot.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    }
    let points: Vec<CurvePoint> = (attempts.iter())
        .map(|a| CurvePoint {
            scenario: &a.trainee,
            score: a.score,
            time_s: a.time_s,
        })
        .collect();
    learning_curve(plot, &points)?;
    let csv_path = plot.with_extension("csv");
    let mut out = csv::Writer::from_path(&csv_path).map_err(|e| e.to_string())?;
    let header = [
        "trainee", "attempt", "scenario", "when", "score", "passed", "time_s", "report",
    ];
    out.write_record(header).map_err(|e| e.to_string())?;
    for trainee in trainees(attempts) {
        let theirs = attempts.iter().filter(|a| a.trainee == trainee);
        for (k, a) in theirs.enumerate() {
            out.write_record([
                trainee.to_owned(),
                (k + 1).to_string(),
                a.scenario.clone(),
                a.when(),
                format!("{:.1}", a.score),
                a.passed.to_string(),
                format!("{:.2}", a.time_s),
                a.report.clone(),
            ])
            .map_err(|e| e.to_string())?;
        }
    }
    out.flush().map_err(|e| e.to_string())?;
    eprintln!(
        "the cohort's learning curves: {} and {}",
        plot.display(),
        csv_path.display()
    );
    Ok(())
}
