//! Training exercises: the scenario file educators write (`format`, `units`), reading it with
//! errors that point at the line and field (`load`), its tasks as they run, fed by the haptic
//! loop one tick at a time (`exercise`), the mistakes they note (`mistakes`), put into words
//! only when scored, the tool's motion metrics (`motion`), the cut against
//! an incision's line (`incision`), the incisions of a radial keratotomy (`keratotomy`), and
//! the rubric's
//! score (`score`). No Bevy here: the app layer runs an [`Exercise`] inside the haptic schedule.

mod exercise;
mod format;
mod incision;
mod keratotomy;
mod load;
mod mistakes;
mod motion;
mod score;
mod units;

pub use exercise::{
    COVERED_TO_FINISH, Exercise, NoduleSite, Progress, RegionSite, Sample, Sites, TaskMetrics,
};
pub use format::{
    Contact, Device, Difficulty, Instrument, LaparoscopeEntry, Nodule, OrganEntry, Port, Rubric,
    Scenario, ScopeKey, Spot, Task, TaskKind, Tool, default_law, metres,
};
pub use incision::{BladeSample, IncisionMetrics, IncisionTracker};
pub use keratotomy::{
    Keratometer, KeratotomyMetrics, KeratotomyPlan, KeratotomyTracker, MIN_INCISION_M,
    RadialIncision,
};
pub use load::{ScenarioError, load, parse};
pub use mistakes::{MISTAKES_LISTED, Mistake, Mistakes};
pub use motion::{IDLE_M_PER_S, MOVING_M_PER_S, MotionMetrics, MotionTracker, STRIDE};
pub use score::{CutMade, Scorecard, TaskScore, score};
pub use units::{
    DepthFraction, Dioptres, EdgeLength, FieldOfView, IncisionCount, Millimetres, ModeCount,
    Newtons, Pascals, PoissonRatio, Ratio, Scale, ScopeAngle, Seconds, Stiffening, Toughness,
};
