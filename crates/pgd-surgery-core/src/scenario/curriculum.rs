//! A training programme's curriculum, `curricula/<name>.curriculum.ron`: modules of
//! exercises in order, each exercise a scenario file with the proficiency rule that says when
//! a trainee has it, and each module opened by the modules it names as done. Read and checked
//! like a scenario (file, line, column, field, hint); where a trainee stands is computed from
//! their attempts ([`standing`]). `docs/programme.md` is the reference page for this file.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::problem::{Problem, ScenarioError};
use super::units::{AttemptCount, Score};

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Curriculum", deny_unknown_fields)]
pub struct Curriculum {
    pub title: String,
    /// In the order they are taught.
    pub modules: Vec<Module>,
}

/// A module: its exercises, and the modules that must be done before it opens.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Module", deny_unknown_fields)]
pub struct Module {
    pub name: String,
    /// Modules listed before this one whose exercises must all be had first; none: open
    /// from the start.
    #[serde(default)]
    pub opens_after: Vec<String>,
    pub exercises: Vec<ExerciseEntry>,
}

/// A scenario of the curriculum and when a trainee has it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Exercise", deny_unknown_fields)]
pub struct ExerciseEntry {
    /// The scenario file, written relative to the curriculum's folder (read as such: the path
    /// here is resolved).
    pub scenario: PathBuf,
    pub proficiency: Proficiency,
}

/// When a trainee has an exercise. Only passed attempts count: an attempt failed by a
/// complication (a perforation, a tear) never does, whatever its score.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
pub enum Proficiency {
    /// The benchmark score met on `in_a_row` consecutive attempts.
    Benchmark {
        score: Score,
        in_a_row: AttemptCount,
    },
    /// `count` attempts, not necessarily in a row, at `min_score` or above.
    Attempts {
        count: AttemptCount,
        min_score: Score,
    },
    /// The scenario's own `benchmark` (every measure it sets) met on `in_a_row`
    /// consecutive attempts: proficiency as LAP Mentor's curricula define it.
    Proficient { in_a_row: AttemptCount },
}

impl Proficiency {
    /// How far the attempts (at this exercise, in the order made) have come towards the
    /// rule: attempts in a row, or counted, of the ones needed.
    pub fn progress(&self, attempts: &[CountedAttempt<'_>]) -> (usize, usize) {
        match *self {
            Proficiency::Benchmark { score, in_a_row } => {
                let met = |a: &CountedAttempt| a.passed && a.score >= score.0;
                (longest_run(attempts, met).min(in_a_row.0), in_a_row.0)
            }
            Proficiency::Attempts { count, min_score } => {
                let met = (attempts.iter())
                    .filter(|a| a.passed && a.score >= min_score.0)
                    .count();
                (met.min(count.0), count.0)
            }
            Proficiency::Proficient { in_a_row } => {
                let met = |a: &CountedAttempt| a.passed && a.proficient == Some(true);
                (longest_run(attempts, met).min(in_a_row.0), in_a_row.0)
            }
        }
    }

    /// The rule in words ("80 on 2 attempts in a row").
    pub fn describe(&self) -> String {
        match self {
            Proficiency::Benchmark { score, in_a_row } => {
                format!("{:.0} on {} attempts in a row", score.0, in_a_row.0)
            }
            Proficiency::Attempts { count, min_score } => {
                format!("{} attempts at {:.0} or more", count.0, min_score.0)
            }
            Proficiency::Proficient { in_a_row } => {
                format!("its benchmark met on {} attempts in a row", in_a_row.0)
            }
        }
    }
}

/// The most consecutive attempts that `met` says meet a rule.
fn longest_run(attempts: &[CountedAttempt<'_>], met: impl Fn(&CountedAttempt) -> bool) -> usize {
    let mut run = 0;
    let mut longest = 0;
    for attempt in attempts {
        run = if met(attempt) { run + 1 } else { 0 };
        longest = usize::max(longest, run);
    }
    longest
}

/// Reads and checks the curriculum in `file`: its modules, their order, and every scenario
/// it names (which must exist and validate).
pub fn load_curriculum(file: &Path) -> Result<Curriculum, ScenarioError> {
    let text = std::fs::read_to_string(file).map_err(|e| ScenarioError::unreadable(file, e))?;
    let mut curriculum: Curriculum = super::load::read_ron(file, &text)?;
    let folder = file.parent().unwrap_or(Path::new(""));
    for exercise in curriculum.modules.iter_mut().flat_map(|m| &mut m.exercises) {
        exercise.scenario = folder.join(&exercise.scenario);
    }
    match check(&curriculum).into_iter().next() {
        None => Ok(curriculum),
        Some(problem) => Err(problem.locate(file, &text)),
    }
}

/// What is wrong with a curriculum as a whole, in file order.
fn check(curriculum: &Curriculum) -> Vec<Problem> {
    let mut problems = Vec::new();
    if curriculum.modules.is_empty() {
        problems.push(Problem {
            field: "modules".into(),
            anchors: vec!["modules".into()],
            message: "the curriculum has no modules".into(),
            hint: "add Module(name: …, exercises: [Exercise(scenario: …, proficiency: …)])".into(),
        });
    }
    for (k, module) in curriculum.modules.iter().enumerate() {
        let anchors =
            |name: &str| vec!["Module".into(), format!("\"{}\"", module.name), name.into()];
        let earlier = &curriculum.modules[..k];
        if earlier.iter().any(|m| m.name == module.name) {
            problems.push(Problem {
                field: format!("modules[{k}].name"),
                anchors: anchors("name"),
                message: format!("the module `{}` is named twice", module.name),
                hint: "name each module once".into(),
            });
        }
        for (j, needed) in module.opens_after.iter().enumerate() {
            if !earlier.iter().any(|m| &m.name == needed) {
                problems.push(Problem {
                    field: format!("modules[{k}].opens_after[{j}]"),
                    anchors: vec![
                        "Module".into(),
                        format!("\"{}\"", module.name),
                        "opens_after".into(),
                        format!("\"{needed}\""),
                    ],
                    message: format!("`{needed}` is not a module listed before `{}`", module.name),
                    hint: format!(
                        "a module opens after modules listed before it: {}",
                        names(earlier)
                    ),
                });
            }
        }
        if module.exercises.is_empty() {
            problems.push(Problem {
                field: format!("modules[{k}].exercises"),
                anchors: anchors("exercises"),
                message: format!("the module `{}` has no exercises", module.name),
                hint: "add Exercise(scenario: \"…scenario.ron\", proficiency: …)".into(),
            });
        }
        for (j, exercise) in module.exercises.iter().enumerate() {
            problems.extend(check_scenario(k, j, exercise));
        }
    }
    problems
}

/// The module names, for a hint ("none" for none).
fn names(modules: &[Module]) -> String {
    match modules {
        [] => "none".into(),
        _ => (modules.iter().map(|m| format!("`{}`", m.name)))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// A problem if exercise `j` of module `k` names a scenario that does not load, or asks for
/// its benchmark and it has none.
fn check_scenario(k: usize, j: usize, exercise: &ExerciseEntry) -> Option<Problem> {
    let written = exercise
        .scenario
        .file_name()?
        .to_string_lossy()
        .into_owned();
    match super::load::load(&exercise.scenario) {
        Err(error) => Some(Problem {
            field: format!("modules[{k}].exercises[{j}].scenario"),
            anchors: vec!["exercises".into(), written],
            message: format!("the scenario does not load: {error}"),
            hint: "scenario files are written relative to the curriculum's folder; `trainer \
                   validate FILE` checks one"
                .into(),
        }),
        Ok(scenario)
            if scenario.benchmark.is_none()
                && matches!(exercise.proficiency, Proficiency::Proficient { .. }) =>
        {
            Some(Problem {
                field: format!("modules[{k}].exercises[{j}].proficiency"),
                anchors: vec!["exercises".into(), written, "Proficient".into()],
                message: "the rule asks for the scenario's benchmark, and it sets none".into(),
                hint: "give the scenario `benchmark: Benchmark(…)`, or use `Benchmark(score: …, \
                       in_a_row: …)`"
                    .into(),
            })
        }
        Ok(_) => None,
    }
}

/// An attempt as the curriculum counts it: the scenario file it was made at (as given to
/// the trainer), its score, whether it passed and whether it met the scenario's benchmark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CountedAttempt<'a> {
    pub scenario: &'a str,
    pub score: f64,
    pub passed: bool,
    /// Whether it met the scenario's benchmark (none where the scenario sets none).
    pub proficient: Option<bool>,
}

/// Where a module stands for a trainee.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModuleState {
    /// Every exercise had.
    Done,
    /// Open (the modules it opens after are done), not yet done.
    Open,
    /// Waiting on the modules it opens after.
    Locked,
}

/// Where a trainee stands on one exercise.
#[derive(Clone, Debug, PartialEq)]
pub struct ExerciseStanding {
    /// The scenario's file name without `.scenario.ron`.
    pub name: String,
    pub rule: Proficiency,
    pub attempts: usize,
    pub best_score: Option<f64>,
    /// Attempts towards the rule, of those it needs.
    pub progress: (usize, usize),
}

impl ExerciseStanding {
    pub fn had(&self) -> bool {
        self.progress.0 >= self.progress.1
    }
}

/// Where a trainee stands on one module.
#[derive(Clone, Debug, PartialEq)]
pub struct ModuleStanding {
    pub name: String,
    pub state: ModuleState,
    pub exercises: Vec<ExerciseStanding>,
}

/// Where a trainee stands in `curriculum` after `attempts` (theirs, in the order made). An
/// attempt counts for an exercise when it was made at a scenario file of the same name.
pub fn standing(curriculum: &Curriculum, attempts: &[CountedAttempt<'_>]) -> Vec<ModuleStanding> {
    let mut modules: Vec<ModuleStanding> = Vec::with_capacity(curriculum.modules.len());
    for module in &curriculum.modules {
        let exercises: Vec<ExerciseStanding> = (module.exercises.iter())
            .map(|e| exercise_standing(e, attempts))
            .collect();
        let opens = module.opens_after.iter().all(|needed| {
            (modules.iter()).any(|m| &m.name == needed && m.state == ModuleState::Done)
        });
        let state = match (opens, exercises.iter().all(ExerciseStanding::had)) {
            (false, _) => ModuleState::Locked,
            (true, true) => ModuleState::Done,
            (true, false) => ModuleState::Open,
        };
        modules.push(ModuleStanding {
            name: module.name.clone(),
            state,
            exercises,
        });
    }
    modules
}

fn exercise_standing(
    exercise: &ExerciseEntry,
    attempts: &[CountedAttempt<'_>],
) -> ExerciseStanding {
    let name = file_name(&exercise.scenario.to_string_lossy());
    let made: Vec<CountedAttempt> = (attempts.iter())
        .filter(|a| file_name(a.scenario) == name)
        .copied()
        .collect();
    ExerciseStanding {
        name: name.trim_end_matches(".scenario.ron").to_owned(),
        rule: exercise.proficiency,
        attempts: made.len(),
        best_score: made.iter().map(|m| m.score).reduce(f64::max),
        progress: exercise.proficiency.progress(&made),
    }
}

/// The last part of a path, whichever separator it was written with.
fn file_name(path: &str) -> String {
    path.rsplit(['/', '\\']).next().unwrap_or(path).to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn benchmark(score: f64, in_a_row: usize) -> Proficiency {
        Proficiency::Benchmark {
            score: Score(score),
            in_a_row: AttemptCount(in_a_row),
        }
    }

    fn module(name: &str, opens_after: &[&str], scenario: &str, rule: Proficiency) -> Module {
        Module {
            name: name.into(),
            opens_after: opens_after.iter().map(|s| s.to_string()).collect(),
            exercises: vec![ExerciseEntry {
                scenario: PathBuf::from(format!("curricula/../scenarios/{scenario}.scenario.ron")),
                proficiency: rule,
            }],
        }
    }

    fn attempt(scenario: &'static str, score: f64, passed: bool) -> CountedAttempt<'static> {
        CountedAttempt {
            scenario,
            score,
            passed,
            proficient: None,
        }
    }

    /// Two modules, the second opening after the first: locked until the benchmark is met
    /// twice in a row (an attempt between below it breaks the run; a failed one, whatever its
    /// score, too), then open, then done once its own rule is met.
    #[test]
    fn a_module_opens_when_the_one_before_is_done() {
        let curriculum = Curriculum {
            title: "t".into(),
            modules: vec![
                module("basics", &[], "press", benchmark(80.0, 2)),
                module(
                    "tasks",
                    &["basics"],
                    "grasp",
                    Proficiency::Attempts {
                        count: AttemptCount(2),
                        min_score: Score(70.0),
                    },
                ),
            ],
        };
        let states = |attempts: &[CountedAttempt]| -> Vec<ModuleState> {
            standing(&curriculum, attempts)
                .iter()
                .map(|m| m.state)
                .collect()
        };
        use ModuleState::{Done, Locked, Open};
        assert_eq!(states(&[]), [Open, Locked]);
        let broken_run = [
            attempt("scenarios/press.scenario.ron", 85.0, true),
            attempt("scenarios/press.scenario.ron", 75.0, true),
            attempt("/home/a/press.scenario.ron", 95.0, true),
        ];
        assert_eq!(states(&broken_run), [Open, Locked]);
        let failed = [
            attempt("scenarios/press.scenario.ron", 85.0, true),
            attempt("scenarios/press.scenario.ron", 90.0, false),
            attempt("scenarios/press.scenario.ron", 95.0, true),
        ];
        assert_eq!(states(&failed), [Open, Locked], "a failed attempt counts");
        let mut made = broken_run.to_vec();
        made.push(attempt("press.scenario.ron", 81.0, true));
        assert_eq!(states(&made), [Done, Open]);
        made.push(attempt("scenarios/grasp.scenario.ron", 72.0, true));
        made.push(attempt("scenarios/grasp.scenario.ron", 99.0, false));
        let standing = standing(&curriculum, &made);
        assert_eq!(standing[1].state, Open);
        assert_eq!(standing[1].exercises[0].progress, (1, 2));
        assert_eq!(standing[1].exercises[0].best_score, Some(99.0));
        made.push(attempt("scenarios/grasp.scenario.ron", 70.0, true));
        assert_eq!(states(&made), [Done, Done]);
    }

    /// Proficiency by the scenario's benchmark: two proficient attempts in a row; one that
    /// passed but missed the benchmark breaks the run, one that met it but failed (a major
    /// error) never counts.
    #[test]
    fn the_scenarios_benchmark_met_twice_in_a_row_is_proficiency() {
        let rule = Proficiency::Proficient {
            in_a_row: AttemptCount(2),
        };
        let made = |marks: &[(bool, Option<bool>)]| -> Vec<CountedAttempt<'static>> {
            (marks.iter())
                .map(|&(passed, proficient)| CountedAttempt {
                    proficient,
                    ..attempt("op.scenario.ron", 95.0, passed)
                })
                .collect()
        };
        let broken = made(&[(true, Some(true)), (true, Some(false)), (true, Some(true))]);
        assert_eq!(rule.progress(&broken), (1, 2));
        let failed = made(&[(true, Some(true)), (false, Some(true))]);
        assert_eq!(rule.progress(&failed), (1, 2));
        let unmarked = made(&[(true, None), (true, None)]);
        assert_eq!(rule.progress(&unmarked), (0, 2));
        let had = made(&[(true, Some(false)), (true, Some(true)), (true, Some(true))]);
        assert_eq!(rule.progress(&had), (2, 2));
        assert_eq!(rule.describe(), "its benchmark met on 2 attempts in a row");
    }

    /// A module listed before another cannot open after it, and a module with an unknown
    /// name in `opens_after` is refused with the names it could have.
    #[test]
    fn a_module_opens_only_after_modules_before_it() {
        let curriculum = Curriculum {
            title: "t".into(),
            modules: vec![
                module(
                    "basics",
                    &["tasks"],
                    "liver-steady-press",
                    benchmark(80.0, 2),
                ),
                module(
                    "tasks",
                    &["basics"],
                    "gallbladder-grasp-retract",
                    benchmark(80.0, 2),
                ),
            ],
        };
        let problems = check(&curriculum);
        let first = problems.first().expect("refused");
        assert_eq!(first.field, "modules[0].opens_after[0]");
        assert!(
            first
                .message
                .contains("`tasks` is not a module listed before `basics`")
        );
        assert!(first.hint.contains("none"));
    }
}
