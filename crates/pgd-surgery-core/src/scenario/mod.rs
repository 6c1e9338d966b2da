//! Training exercises. The scenario file educators write, as types (`format`, `scene`,
//! `units`), read with errors that point at the line and field (`load`, `problem`); its tasks,
//! each of a type that implements the task trait (`task`; the built-in types, their registry
//! and their reader in `tasks`), run one after another fed by the haptic loop one tick at a
//! time (`exercise`, `sample`), with the tool's motion (`motion`), the cut against an
//! incision's line (`incision`) and the incisions of a radial keratotomy (`keratotomy`)
//! measured; the assistant's scripted instrument (`assistant`); and the rubric's score
//! (`score`). A programme's curriculum of scenarios, read
//! the same way, and where a trainee stands in it (`curriculum`). No Bevy here: the app layer runs an
//! [`Exercise`] inside the haptic schedule.

mod assistant;
mod attachment;
mod biliary;
mod bimanual;
pub mod curriculum;
mod exercise;
mod format;
mod global;
mod incision;
mod keratotomy;
mod load;
mod motion;
mod operation;
mod phases;
mod problem;
mod sample;
mod scene;
mod score;
pub mod task;
pub mod tasks;
mod units;

pub use attachment::{AttachmentEntry, DEFAULT_TIE_GAP_MM};
pub use biliary::BiliaryEntry;
pub use bimanual::{BimanualMetrics, BimanualTracker};
pub use exercise::{Exercise, Finished, Progress, Sites};
pub use format::{
    Assistant, Contact, Device, Difficulty, Instrument, LaparoscopeEntry, Port, Rubric, Scenario,
    ScopeKey, TipKey, Tool, default_law,
};
pub use global::{Benchmark, BenchmarkLine, GlobalMeasures};
pub use incision::{BladeSample, IncisionMetrics, IncisionTracker};
pub use keratotomy::{
    Keratometer, KeratotomyMetrics, KeratotomyPlan, KeratotomyTracker, MIN_INCISION_M,
    RadialIncision,
};
pub use load::{load, parse};
pub use motion::{IDLE_M_PER_S, MOVING_M_PER_S, MotionMetrics, MotionTracker, STRIDE};
pub use operation::{
    ErrorScored, Event, OperationRubric, OperationScore, ScoredError, ScoredStep, StepScored,
};
pub use phases::PhaseTime;
pub use problem::ScenarioError;
pub use sample::{
    BiliarySample, HandSample, HookSample, HookTarget, NoduleSite, RegionSite, Sample, ViewSample,
    WallSample,
};
pub use scene::{Nodule, OrganEntry, Spot, metres};
pub use score::{CutMade, Scorecard, TaskScore, score};
pub use task::{
    Countertraction, CountertractionMetrics, CountertractionWatch, Hand, Lapse, MISTAKES_LISTED,
    Mistake, Mistakes, Task, TaskMetrics, TaskShared, TaskType,
};
pub use tasks::{COVERED_TO_FINISH, register, registered_names};
pub use units::{
    AttemptCount, DepthFraction, Dioptres, EdgeLength, FieldOfView, IncisionCount, Millimetres,
    ModeCount, Newtons, Pascals, PoissonRatio, Ratio, Scale, ScopeAngle, Score, Seconds,
    Stiffening, Toughness,
};
