//! What the trainer prints and writes: `trainer validate`'s verdict on scenario files,
//! `trainer prepare`'s vademecums, and the end of an attempt (its score printed, its report
//! written).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::trainer_history::{HistoryTarget, keep_scored};
use crate::app::attempt::{Outcome, scenario_files, scenario_scene};
use crate::app::launch;
use crate::app::scene::Detail;
use crate::pgd::{self, Statistics, web_form};
use crate::report;
use crate::scenario;
use crate::store::OnStale;

/// Each attempt with its number among its scenario's attempts, when there were several.
pub fn numbered(attempts: launch::Attempts) -> Vec<(PathBuf, Option<usize>, Outcome)> {
    let count = |file: &PathBuf| attempts.iter().filter(|(f, _)| f == file).count();
    let counts: Vec<usize> = attempts.iter().map(|(file, _)| count(file)).collect();
    let mut seen: Vec<PathBuf> = Vec::new();
    attempts
        .into_iter()
        .zip(counts)
        .map(|((file, outcome), count)| {
            seen.push(file.clone());
            let k = seen.iter().filter(|f| **f == file).count();
            (file, (count > 1).then_some(k), outcome)
        })
        .collect()
}

/// `trainer validate`: every file checked (scenarios, and curricula by their name), every
/// problem printed; fails if any file has one.
pub fn validate_scenarios(files: &[PathBuf]) -> ExitCode {
    let mut failed = false;
    for file in files {
        if super::is_curriculum(file) {
            failed |= !super::validate_curriculum(file);
            continue;
        }
        match scenario::load(file) {
            Ok(s) => {
                println!(
                    "{}: ok ({}, {} task{})",
                    file.display(),
                    s.title,
                    s.tasks.len(),
                    if s.tasks.len() == 1 { "" } else { "s" }
                );
                warn_of_missing_glyphs(file, &s);
            }
            Err(e) => {
                eprintln!("{e}");
                failed = true;
            }
        }
    }
    verdict(failed)
}

/// A warning on the error stream when the scenario's words (its title, briefing and tasks)
/// hold characters the trainer's font cannot draw: they would show as boxes.
fn warn_of_missing_glyphs(file: &Path, scenario: &scenario::Scenario) {
    let tasks = scenario.tasks.iter().map(scenario::Task::description);
    let words: Vec<String> = [scenario.title.clone(), scenario.briefing.clone()]
        .into_iter()
        .chain(tasks)
        .collect();
    let missing = crate::report::without_glyph(&words.join("\n"));
    if !missing.is_empty() {
        let listed: Vec<String> = missing.iter().map(|c| format!("{c:?}")).collect();
        eprintln!(
            "warning: {}: the trainer's font (DejaVu Sans) has no glyph for {}: they show as \
             boxes in the window and the web page",
            file.display(),
            listed.join(", ")
        );
    }
}

/// `trainer prepare`: the vademecums and distance fields the scenario files need, built under
/// `dir` where missing or stale, then listed one per line (what a class, or the web page's
/// site, must have), and with `web` their web forms written there (for the page's scenes:
/// linear tissue where a scenario names no law, [`scenario::Scenario::for_the_web`]), with
/// their sizes and how much the felt force changes. Fails if any file does not read or any
/// scene cannot be built.
pub fn prepare_scenarios(
    files: &[PathBuf],
    dir: &Path,
    detail: Detail,
    web: Option<&Path>,
) -> ExitCode {
    let mut failed = false;
    let mut listed: Vec<PathBuf> = Vec::new();
    for file in files {
        let prepared = scenario::load(file)
            .map_err(|e| e.to_string())
            .map(|s| if web.is_some() { s.for_the_web() } else { s })
            .and_then(|s| {
                scenario_scene(&s, dir, detail, OnStale::Rebuild)?;
                scenario_files(&s, dir, detail)
            });
        match prepared {
            Ok(needed) => listed.extend(needed.into_iter().filter(|f| f.is_file())),
            Err(e) => {
                eprintln!("{}: {e}", file.display());
                failed = true;
            }
        }
    }
    listed.sort();
    listed.dedup();
    for file in &listed {
        println!("{}", file.display());
    }
    if let Some(web) = web
        && let Err(e) = write_web_forms(&listed, web)
    {
        eprintln!("{e}");
        failed = true;
    }
    verdict(failed)
}

fn verdict(failed: bool) -> ExitCode {
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// Each file's web form in `dir` (named `<file name>.web`), and a table of sizes and, for
/// vademecums, the felt force's change (p95 and max over the surface triangles).
fn write_web_forms(files: &[PathBuf], dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    println!("web form                                     file MB  web MB  felt force p95   max");
    let mb = |n: usize| n as f64 / 1e6;
    let (mut total, mut total_web) = (0, 0);
    for file in files {
        let bytes = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
        let is_vademecum = file.extension().is_some_and(|e| e == "vdm");
        let (web, changes) = if is_vademecum {
            let full = pgd::decode(file, &bytes).map_err(|e| e.to_string())?;
            let web = web_form::vademecum(&full);
            let expanded = web_form::expand(file, &web).map_err(|e| e.to_string())?;
            let back = pgd::decode(file, &expanded).map_err(|e| e.to_string())?;
            (web, web_form::felt_force_changes(&full, &back))
        } else {
            (web_form::deflated(&bytes), Vec::new())
        };
        let name = format!(
            "{}.{}",
            file.file_name().unwrap_or_default().to_string_lossy(),
            web_form::EXTENSION
        );
        let out = dir.join(&name);
        std::fs::write(&out, &web).map_err(|e| format!("{}: {e}", out.display()))?;
        let force = match changes.is_empty() {
            true => "(kept exactly)".to_owned(),
            false => {
                let change = Statistics::of(changes.iter().copied());
                format!("{:.4} %   {:.4} %", 100.0 * change.p95, 100.0 * change.max)
            }
        };
        println!(
            "{name:<44} {:>7.2} {:>7.2}  {force}",
            mb(bytes.len()),
            mb(web.len())
        );
        (total, total_web) = (total + bytes.len(), total_web + web.len());
    }
    println!("{:<44} {:>7.2} {:>7.2}", "all", mb(total), mb(total_web));
    Ok(())
}

/// The end of an exercise: its score printed (JSON with `json`), its report written, named
/// after the scenario's file (and the attempt, when the trainee retried), and the attempt kept
/// in the history.
pub fn debrief(
    outcome: Result<Outcome, String>,
    file: &Path,
    attempt: Option<usize>,
    report_dir: &Path,
    json: bool,
    history: &HistoryTarget,
) -> ExitCode {
    let outcome = match outcome {
        Ok(outcome) => outcome,
        Err(e) => {
            eprintln!("trainer: {e}");
            return ExitCode::FAILURE;
        }
    };
    let name = file
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("attempt");
    let stem = name.trim_end_matches(".ron").trim_end_matches(".scenario");
    let stem = match attempt {
        Some(k) => format!("{stem}.attempt-{k}"),
        None => stem.to_owned(),
    };
    let written = report::write_report(report_dir, &stem, &outcome.card, &outcome.force_trace);
    if json {
        match serde_json::to_string_pretty(&outcome.card) {
            Ok(text) => println!("{text}"),
            Err(e) => eprintln!("trainer: could not write the JSON scorecard: {e}"),
        }
    } else {
        print!("{}", report::summary(&outcome.card));
    }
    let (report, code) = match written {
        Ok(files) => {
            let shown: Vec<String> = files.paths().map(|p| p.display().to_string()).collect();
            eprintln!("report: {}", shown.join(", "));
            (Some(files.json), ExitCode::SUCCESS)
        }
        Err(e) => {
            eprintln!("trainer: the report was not written: {e}");
            (None, ExitCode::FAILURE)
        }
    };
    let kept = keep_scored(history, &outcome.card, file, report.as_deref());
    if code == ExitCode::SUCCESS {
        kept
    } else {
        code
    }
}
