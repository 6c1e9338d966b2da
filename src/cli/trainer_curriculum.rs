//! `trainer curriculum`: where a trainee stands in a programme's curriculum, from the attempts
//! kept in the history; and `trainer validate`'s verdict on a curriculum file.

use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

use crate::app::window::MenuCurriculum;
use crate::history::{AttemptRecord, HistoryFilter, Store, read_attempts};
use crate::scenario::curriculum::{
    CountedAttempt, Curriculum, ExerciseStanding, ModuleStanding, ModuleState, load_curriculum,
    standing,
};

/// Whether `file` is a curriculum (by its name, `….curriculum.ron`) rather than a scenario.
pub fn is_curriculum(file: &Path) -> bool {
    file.to_string_lossy().ends_with(".curriculum.ron")
}

/// Checks a curriculum file and every scenario it names; prints the verdict, `true` if good.
pub fn validate_curriculum(file: &Path) -> bool {
    match load_curriculum(file) {
        Ok(curriculum) => {
            let exercises: usize = curriculum.modules.iter().map(|m| m.exercises.len()).sum();
            println!(
                "{}: ok ({}, {} modules, {exercises} exercises)",
                file.display(),
                curriculum.title,
                curriculum.modules.len()
            );
            true
        }
        Err(e) => {
            eprintln!("{e}");
            false
        }
    }
}

/// Prints where `trainee` stands in the curriculum `file`, from the history in `store`.
pub fn show_standing(file: &Path, store: &Store, trainee: &str) -> ExitCode {
    let curriculum = match load_curriculum(file) {
        Ok(curriculum) => curriculum,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let attempts = match attempts_of(store, trainee) {
        Ok(attempts) => attempts,
        Err(e) => return super::fail("trainer curriculum", &e),
    };
    let stands = standing(&curriculum, &counted(&attempts));
    print!(
        "{}",
        standing_text(&curriculum, &stands, trainee, &store.shown())
    );
    ExitCode::SUCCESS
}

/// The curriculum `file` for the window's menu, where `trainee` stands read afresh from the
/// history in `store` each time the menu opens (a history that cannot be read counts no
/// attempt).
pub fn menu_curriculum(
    file: &Path,
    store: &Store,
    trainee: &str,
) -> Result<MenuCurriculum, String> {
    let curriculum = load_curriculum(file).map_err(|e| e.to_string())?;
    let (store, trainee): (Store, String) = (store.clone(), trainee.to_owned());
    let read = curriculum.clone();
    Ok(MenuCurriculum {
        curriculum,
        standing: Arc::new(move || {
            let attempts = attempts_of(&store, &trainee).unwrap_or_default();
            standing(&read, &counted(&attempts))
        }),
    })
}

/// `trainee`'s attempts kept in the history in `store`, in the order made (none, and no
/// database made, where a local one does not exist yet).
fn attempts_of(store: &Store, trainee: &str) -> Result<Vec<AttemptRecord>, String> {
    if let Store::Local(database) = store
        && !database.exists()
    {
        return Ok(Vec::new());
    }
    let filter = HistoryFilter {
        trainee: Some(trainee.to_owned()),
        scenario: None,
    };
    let (attempts, warning) = read_attempts(store, &filter).map_err(|e| e.to_string())?;
    if let Some(warning) = warning {
        eprintln!("trainer: warning: {warning}");
    }
    Ok(attempts)
}

/// The attempts as the curriculum counts them.
pub(super) fn counted<'a>(
    attempts: impl IntoIterator<Item = &'a AttemptRecord>,
) -> Vec<CountedAttempt<'a>> {
    (attempts.into_iter())
        .map(|a| CountedAttempt {
            scenario: &a.scenario,
            score: a.score,
            passed: a.passed,
            proficient: a.proficient,
        })
        .collect()
}

/// The standing as `trainer curriculum` prints it.
fn standing_text(
    curriculum: &Curriculum,
    modules: &[ModuleStanding],
    trainee: &str,
    store: &str,
) -> String {
    let mut text = format!("{}: where {trainee} stands ({store})\n", curriculum.title);
    for (k, (module, entry)) in modules.iter().zip(&curriculum.modules).enumerate() {
        let state = match module.state {
            ModuleState::Done => "done".to_owned(),
            ModuleState::Open => "open".to_owned(),
            ModuleState::Locked => format!("locked (opens after {})", entry.opens_after.join(", ")),
        };
        text += &format!("{}. {}: {state}\n", k + 1, module.name);
        for exercise in &module.exercises {
            text += &format!("     {}\n", exercise_line(exercise));
        }
    }
    text
}

/// One exercise: had or how far, the rule, the attempts and the best score.
fn exercise_line(exercise: &ExerciseStanding) -> String {
    let (done, of) = exercise.progress;
    let status = match exercise.had() {
        true => "had".to_owned(),
        false => format!("{done} of {of}"),
    };
    let attempts = match (exercise.attempts, exercise.best_score) {
        (0, _) | (_, None) => "no attempt yet".to_owned(),
        (1, Some(best)) => format!("1 attempt, best {best:.0}"),
        (n, Some(best)) => format!("{n} attempts, best {best:.0}"),
    };
    format!(
        "{}: {status} ({}; {attempts})",
        exercise.name,
        exercise.rule.describe()
    )
}
