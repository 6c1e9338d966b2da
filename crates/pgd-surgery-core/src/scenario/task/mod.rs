//! A task type in one place. A task implements [`TaskType`]: its own RON fields (a serde
//! struct) and their checks, its description, and the [`TaskRun`] that measures it tick by
//! tick, whose [`TaskResult`] says how it scores and what the debrief and report say of it.
//! The fields every task has — the organ, the force limit, the time limit — are read into
//! one [`TaskShared`] beside it. A type is registered once (`scenario::tasks::register`);
//! the scenario reader then knows its name. The built-in types are in `scenario::tasks`, one
//! module each, with the registry and the reader.

mod check;
mod countertraction;
mod metrics;
mod mistakes;
mod watch;

use std::any::Any;
use std::fmt::{self, Debug};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

pub use check::{BandEnd, SceneFacts, TaskCheck};
pub use countertraction::{
    Countertraction, CountertractionMetrics, CountertractionWatch, LET_GO_S, Lapse,
};
pub use metrics::{TaskMetrics, results_of};
pub use mistakes::{MISTAKES_LISTED, Mistake, Mistakes};
pub use watch::{HYSTERESIS, Hold, LimitWatch};

use super::keratotomy::Keratometer;
use super::motion::MotionTracker;
use super::sample::{NoduleSite, Sample};
use super::units::{Newtons, Seconds};

/// The fields every task has, written among its own: `organ`, `max_force_n`, `time_limit_s`
/// (and, optional, `hand`, `countertraction`, `phase`, `instruments`).
#[derive(Clone, Debug, PartialEq)]
pub struct TaskShared {
    /// The organ the task works on; none for a task among them all (navigation), whose type
    /// says so ([`TaskType::ON_AN_ORGAN`]).
    pub organ: Option<String>,
    /// The force above which pressing or pulling is an error (the band's top in force control).
    pub max_force_n: Newtons,
    pub time_limit_s: Seconds,
    /// The hand that does the task in a bimanual exercise (the right by default): what every
    /// task measures (force, contact, motion) is that hand's.
    pub hand: Hand,
    /// In a bimanual exercise, an organ the other hand keeps held within a force band
    /// throughout the task (traction and counter-traction).
    pub countertraction: Option<Countertraction>,
    /// The phase of the operation the task belongs to ("Calot's triangle"): the debrief gives
    /// each phase's times; a phase's tasks follow one another.
    pub phase: Option<String>,
    /// The instruments of the task's hand it is done with, by kind (`["hook"]`, `["clip
    /// applier", "scissors"]`): tissue touched with another one of the hand's is a mistake.
    /// Empty: any of them.
    pub instruments: Vec<String>,
}

/// A trainee's hand, as a bimanual exercise's tasks name it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum Hand {
    #[default]
    Right,
    Left,
}

impl Hand {
    /// The other hand.
    pub fn other(self) -> Hand {
        match self {
            Hand::Right => Hand::Left,
            Hand::Left => Hand::Right,
        }
    }

    /// The hand in words ("right", "left").
    pub fn name(self) -> &'static str {
        match self {
            Hand::Right => "right",
            Hand::Left => "left",
        }
    }
}

/// The region a task watches move (retraction, grasp): its organ, the point nearest which it
/// lies (mm) and the direction it is to move in. The haptic loop measures how far it moved.
pub struct Watched<'a> {
    pub organ: &'a str,
    pub at_mm: (f64, f64, f64),
    pub towards: (f64, f64, f64),
}

/// What a task is given when its run is made, before the exercise starts.
#[derive(Clone, Debug, Default)]
pub struct RunSetup {
    /// The task's organ among the scenario's organs.
    pub organ: Option<usize>,
    /// Where the nodules in the task's organ lie.
    pub nodules: Vec<NoduleSite>,
    /// The cut organ's model, for a task that predicts what its cut does (keratotomy).
    pub keratometer: Option<Keratometer>,
    /// The scene's organs' names, in order (the sample's organ bits'), for the report.
    pub organ_names: Vec<String>,
}

/// One tick as a task's run sees it: the sample, the time since the last, the metrics every
/// task has (its own are its run's), the mistakes noted so far and the tool's motion.
pub struct Tick<'a> {
    pub sample: &'a Sample,
    pub dt: f64,
    pub metrics: &'a mut TaskMetrics,
    pub mistakes: &'a mut Mistakes,
    pub motion: &'a MotionTracker,
}

impl Tick<'_> {
    /// Notes a mistake of the task's own, numbered `code` (the type's
    /// [`TaskType::describe_mistake`] words it), with an amount to say.
    pub fn mistake(&mut self, code: u16, amount: f64) {
        self.mistakes.note(Mistake::Own {
            time_s: self.sample.time_s,
            code,
            amount,
        });
    }
}

/// How far a task has come, for the trainee's display ("held 1.2 of 3.0 s").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaskProgress {
    pub what: &'static str,
    pub done: f64,
    pub of: f64,
    pub unit: &'static str,
}

impl fmt::Display for TaskProgress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let digits = usize::from(self.unit == "s");
        let unit = match self.unit {
            "" => String::new(),
            unit => format!(" {unit}"),
        };
        write!(
            f,
            "{} {:.digits$} of {:.digits$}{unit}",
            self.what, self.done, self.of
        )
    }
}

/// A kind of task: its RON fields are the implementing struct's (beside [`TaskShared`]'s).
pub trait TaskType: Clone + Debug + PartialEq + DeserializeOwned + Send + Sync + 'static {
    /// Its name in a scenario file: `tasks: [NAME(…)]`.
    const NAME: &'static str;
    /// What the trainee and the report call it ("force control").
    const LABEL: &'static str;
    /// Whether it works on one organ, named by its `organ` field (required then, refused
    /// otherwise).
    const ON_AN_ORGAN: bool = true;
    /// What an error of force does to the tissue, in the debrief's words.
    const FORCE_VERB: &'static str = "pressed";
    type Run: TaskRun;

    /// What the task asks, in words, for the trainee.
    fn description(&self, shared: &TaskShared) -> String;

    /// What is wrong with the task's fields in its scenario, noted on `check`; the organ's
    /// presence in the scene is checked for every type.
    fn check(&self, check: &mut TaskCheck<'_>) {
        let _ = check;
    }

    /// The region the task watches move, if any.
    fn watched<'a>(&'a self, shared: &'a TaskShared) -> Option<Watched<'a>> {
        let _ = shared;
        None
    }

    /// The task's run, made before the exercise starts (the haptic thread allocates nothing).
    fn run(&self, shared: &TaskShared, setup: RunSetup) -> Self::Run;

    /// A mistake the run noted with [`Tick::mistake`], in words (without its time).
    fn describe_mistake(&self, shared: &TaskShared, code: u16, amount: f64) -> String {
        let _ = (shared, amount);
        format!("mistake {code}")
    }
}

/// A task as it runs: fed one [`Tick`] at a time on the haptic thread, where it must not
/// allocate; it sets `metrics.completed` when done.
pub trait TaskRun: Clone + Send + Sync + 'static {
    type Result: TaskResult;

    fn step(&mut self, tick: &mut Tick<'_>);

    /// Whether the task is over before its time although not completed (a mark made in the
    /// wrong place, a complication).
    fn over(&self) -> bool {
        false
    }

    /// How far the task has come, for the trainee's display.
    fn progress(&self) -> Option<TaskProgress> {
        None
    }

    /// What the task measured of its own, when the attempt is scored (off the haptic thread).
    fn result(&self) -> Self::Result;
}

/// What a task measured of its own, and how that scores and reads. It is written into the
/// report's JSON beside the metrics every task has.
pub trait TaskResult: Clone + Debug + PartialEq + Serialize + Send + Sync + 'static {
    /// The accuracy term of the score (0–1), for a task with a mark to be accurate about.
    fn accuracy(&self) -> Option<f64> {
        None
    }

    /// The time in contact not spent as the task wants (s): above the limit unless it says
    /// otherwise.
    fn off_target_s(&self, metrics: &TaskMetrics) -> f64 {
        metrics.time_over_limit_s
    }

    /// The force term of the score when the tool never touched (touching is most tasks' point).
    fn untouched_force_share(&self) -> f64 {
        0.0
    }

    /// What is said after "not finished": how far it got, such as " (held 1.0 s of 3.0 s)";
    /// `None` when an unfinished task is not to be called so (a mark made in the wrong place
    /// says so itself).
    fn unfinished(&self) -> Option<String> {
        Some(String::new())
    }

    /// What went wrong, in words, for the debrief (each line is prefixed with the task's label).
    fn feedback(&self) -> Vec<String> {
        Vec::new()
    }

    /// The task's own lines in the report's text.
    fn summary(&self) -> Vec<String> {
        Vec::new()
    }

    /// A complication: the attempt fails whatever its score.
    fn complication(&self) -> Option<String> {
        None
    }

    /// A lower force bound, drawn in the report's plot beside the limit.
    fn lower_force_n(&self) -> Option<f64> {
        None
    }
}

/// A task read from a scenario: the shared fields and its type's own.
pub struct Task {
    pub shared: TaskShared,
    kind: Box<dyn AnyTask>,
}

impl Task {
    pub fn new<T: TaskType>(shared: TaskShared, task: T) -> Self {
        Self::from_parts(shared, Box::new(task))
    }

    pub(in crate::scenario) fn from_parts(shared: TaskShared, kind: Box<dyn AnyTask>) -> Self {
        Self { shared, kind }
    }

    /// The task's own fields if it is a `T`.
    pub fn get<T: TaskType>(&self) -> Option<&T> {
        self.kind.as_any().downcast_ref()
    }

    /// Its name in the scenario file.
    pub fn name(&self) -> &'static str {
        self.kind.name()
    }

    pub fn label(&self) -> &'static str {
        self.kind.label()
    }

    /// The organ the task works on (none for navigation, which works among them all).
    pub fn organ(&self) -> Option<&str> {
        self.shared.organ.as_deref()
    }

    pub fn max_force_n(&self) -> f64 {
        self.shared.max_force_n.0
    }

    pub fn time_limit_s(&self) -> f64 {
        self.shared.time_limit_s.0
    }

    /// The hand that does the task.
    pub fn hand(&self) -> Hand {
        self.shared.hand
    }

    /// What the task asks, in words, for the trainee.
    pub fn description(&self) -> String {
        self.kind.description(&self.shared)
    }

    /// The region the task watches move, if any.
    pub fn watched(&self) -> Option<Watched<'_>> {
        self.kind.watched(&self.shared)
    }

    pub fn force_verb(&self) -> &'static str {
        self.kind.force_verb()
    }

    pub(super) fn check(&self, check: &mut TaskCheck<'_>) {
        self.kind.check(check);
    }

    pub(super) fn run(&self, setup: RunSetup) -> Box<dyn AnyRun> {
        self.kind.run(&self.shared, setup)
    }

    pub(super) fn describe_mistake(&self, code: u16, amount: f64) -> String {
        self.kind.describe_mistake(&self.shared, code, amount)
    }
}

impl Clone for Task {
    fn clone(&self) -> Self {
        Self {
            shared: self.shared.clone(),
            kind: self.kind.clone_box(),
        }
    }
}

impl PartialEq for Task {
    fn eq(&self, other: &Self) -> bool {
        self.shared == other.shared && self.kind.eq_any(other.kind.as_any())
    }
}

impl Debug for Task {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct(self.name())
            .field("shared", &self.shared)
            .field("fields", &self.kind)
            .finish()
    }
}

/// What a task measured of its own, of whichever type: serialized flat into the task's
/// metrics, read back as its type with [`TaskOutcome::get`].
pub struct TaskOutcome(Box<dyn AnyResult>);

impl TaskOutcome {
    pub fn new<R: TaskResult>(result: R) -> Self {
        Self(Box::new(result))
    }

    /// The result if it is an `R`.
    pub fn get<R: TaskResult>(&self) -> Option<&R> {
        self.0.as_any().downcast_ref()
    }

    pub fn accuracy(&self) -> Option<f64> {
        self.0.accuracy()
    }

    pub fn off_target_s(&self, metrics: &TaskMetrics) -> f64 {
        self.0.off_target_s(metrics)
    }

    pub fn untouched_force_share(&self) -> f64 {
        self.0.untouched_force_share()
    }

    pub fn unfinished(&self) -> Option<String> {
        self.0.unfinished()
    }

    pub fn feedback(&self) -> Vec<String> {
        self.0.feedback()
    }

    pub fn summary(&self) -> Vec<String> {
        self.0.summary()
    }

    pub fn complication(&self) -> Option<String> {
        self.0.complication()
    }

    pub fn lower_force_n(&self) -> Option<f64> {
        self.0.lower_force_n()
    }
}

impl Clone for TaskOutcome {
    fn clone(&self) -> Self {
        Self(self.0.clone_box())
    }
}

impl PartialEq for TaskOutcome {
    fn eq(&self, other: &Self) -> bool {
        self.0.eq_any(other.0.as_any())
    }
}

impl Debug for TaskOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl Serialize for TaskOutcome {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        erased_serde::serialize(self.0.as_serialize(), serializer)
    }
}

/// [`TaskType`] as an object: what [`Task`] holds.
pub(in crate::scenario) trait AnyTask: Debug + Send + Sync {
    fn name(&self) -> &'static str;
    fn label(&self) -> &'static str;
    fn force_verb(&self) -> &'static str;
    fn description(&self, shared: &TaskShared) -> String;
    fn check(&self, check: &mut TaskCheck<'_>);
    fn watched<'a>(&'a self, shared: &'a TaskShared) -> Option<Watched<'a>>;
    fn run(&self, shared: &TaskShared, setup: RunSetup) -> Box<dyn AnyRun>;
    fn describe_mistake(&self, shared: &TaskShared, code: u16, amount: f64) -> String;
    fn clone_box(&self) -> Box<dyn AnyTask>;
    fn eq_any(&self, other: &dyn Any) -> bool;
    fn as_any(&self) -> &dyn Any;
}

impl<T: TaskType> AnyTask for T {
    fn name(&self) -> &'static str {
        T::NAME
    }
    fn label(&self) -> &'static str {
        T::LABEL
    }
    fn force_verb(&self) -> &'static str {
        T::FORCE_VERB
    }
    fn description(&self, shared: &TaskShared) -> String {
        TaskType::description(self, shared)
    }
    fn check(&self, check: &mut TaskCheck<'_>) {
        TaskType::check(self, check);
    }
    fn watched<'a>(&'a self, shared: &'a TaskShared) -> Option<Watched<'a>> {
        TaskType::watched(self, shared)
    }
    fn run(&self, shared: &TaskShared, setup: RunSetup) -> Box<dyn AnyRun> {
        Box::new(TaskType::run(self, shared, setup))
    }
    fn describe_mistake(&self, shared: &TaskShared, code: u16, amount: f64) -> String {
        TaskType::describe_mistake(self, shared, code, amount)
    }
    fn clone_box(&self) -> Box<dyn AnyTask> {
        Box::new(self.clone())
    }
    fn eq_any(&self, other: &dyn Any) -> bool {
        other.downcast_ref::<T>() == Some(self)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// [`TaskRun`] as an object: what the exercise runs.
pub(in crate::scenario) trait AnyRun: Send + Sync {
    fn step(&mut self, tick: &mut Tick<'_>);
    fn over(&self) -> bool;
    fn progress(&self) -> Option<TaskProgress>;
    fn result(&self) -> TaskOutcome;
    fn clone_box(&self) -> Box<dyn AnyRun>;
}

impl<R: TaskRun> AnyRun for R {
    fn step(&mut self, tick: &mut Tick<'_>) {
        TaskRun::step(self, tick);
    }
    fn over(&self) -> bool {
        TaskRun::over(self)
    }
    fn progress(&self) -> Option<TaskProgress> {
        TaskRun::progress(self)
    }
    fn result(&self) -> TaskOutcome {
        TaskOutcome::new(TaskRun::result(self))
    }
    fn clone_box(&self) -> Box<dyn AnyRun> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn AnyRun> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// [`TaskResult`] as an object: what [`TaskOutcome`] holds.
trait AnyResult: Debug + Send + Sync {
    fn accuracy(&self) -> Option<f64>;
    fn off_target_s(&self, metrics: &TaskMetrics) -> f64;
    fn untouched_force_share(&self) -> f64;
    fn unfinished(&self) -> Option<String>;
    fn feedback(&self) -> Vec<String>;
    fn summary(&self) -> Vec<String>;
    fn complication(&self) -> Option<String>;
    fn lower_force_n(&self) -> Option<f64>;
    fn clone_box(&self) -> Box<dyn AnyResult>;
    fn eq_any(&self, other: &dyn Any) -> bool;
    fn as_any(&self) -> &dyn Any;
    fn as_serialize(&self) -> &dyn erased_serde::Serialize;
}

impl<R: TaskResult> AnyResult for R {
    fn accuracy(&self) -> Option<f64> {
        TaskResult::accuracy(self)
    }
    fn off_target_s(&self, metrics: &TaskMetrics) -> f64 {
        TaskResult::off_target_s(self, metrics)
    }
    fn untouched_force_share(&self) -> f64 {
        TaskResult::untouched_force_share(self)
    }
    fn unfinished(&self) -> Option<String> {
        TaskResult::unfinished(self)
    }
    fn feedback(&self) -> Vec<String> {
        TaskResult::feedback(self)
    }
    fn summary(&self) -> Vec<String> {
        TaskResult::summary(self)
    }
    fn complication(&self) -> Option<String> {
        TaskResult::complication(self)
    }
    fn lower_force_n(&self) -> Option<f64> {
        TaskResult::lower_force_n(self)
    }
    fn clone_box(&self) -> Box<dyn AnyResult> {
        Box::new(self.clone())
    }
    fn eq_any(&self, other: &dyn Any) -> bool {
        other.downcast_ref::<R>() == Some(self)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_serialize(&self) -> &dyn erased_serde::Serialize {
        self
    }
}
