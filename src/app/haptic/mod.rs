//! The haptic side of the trainer as Bevy ECS: a `World` of organ entities and a `Schedule`
//! of ordered systems, one run per 1 kHz tick, on a thread of its own ([`HapticThread`]) or on
//! a simulated clock ([`HapticLoop::run_simulated`], for `--headless`, tests and benchmarks).
//! The render side only ever reads the latest [`HapticSnapshot`].

mod biliary;
mod cautery;
mod components;
mod cutting;
mod frame_paced;
mod hand;
mod report;
mod resources;
mod runner;
mod scoring;
mod snapshot;
mod swap;
mod systems;
#[cfg(not(target_arch = "wasm32"))]
mod thread;

use bevy::ecs::schedule::{ScheduleLabel, SingleThreadedExecutor};
use bevy::prelude::*;
use snapshot::SnapshotPublisher;

pub use biliary::{Biliary, SceneBiliary, view_record};
pub use cautery::{HookWork, OrganBurns};
pub use components::{
    HandTouches, OrganBody, OrganDeformation, OrganIndex, OrganMotion, ToolTouch, organ_with_law,
};
pub use cutting::{OrganCut, SettleCuts};
pub use frame_paced::FramePaced;
pub use hand::{
    Device, DeviceForce, FaultLog, ForceTrace, GraspForce, HandIndex, MAX_HANDS, Safety,
    TRAINEE_HANDS, Tool,
};
pub use report::{FaultSummary, ForceSummary, HeadlessReport, RangeSummary, TickTimes};
pub use resources::{OrganBeds, OrganCoupling, SceneScope, Scope, TickClock};
pub use runner::{
    CutOrgan, HapticLoop, HapticScene, SceneAssistant, SceneCutting, SceneDynamics, SceneError,
    SceneHand,
};
pub use scoring::{ExerciseLink, ExerciseRun};
pub use snapshot::{
    BedView, BiliaryView, BurnsView, ClipView, HandSnapshot, HapticSnapshot, LeakView, LoopTiming,
    OrganSnapshot, TieView, TubeView,
};
pub use swap::SceneSwap;
#[cfg(not(target_arch = "wasm32"))]
pub use thread::{HapticThread, RealTimeReport, Scheduling};

/// The schedule run once per haptic tick.
#[derive(ScheduleLabel, Clone, Debug, PartialEq, Eq, Hash)]
pub struct HapticTick;

/// The stages of a tick, in order.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
pub enum HapticSet {
    ReadDevice,
    ToolContact,
    EvaluateModes,
    /// Organ against organ, attachments, the hook's energy and the biliary tree.
    OrganContact,
    ComputeForce,
    Safety,
    WriteDevice,
    /// The scenario's tasks take the tick's sample.
    Score,
    Publish,
}

/// The tick's systems, chained through [`HapticSet`], on one thread: a tick is a few tens of
/// microseconds of work, which a multi-threaded executor would only slow down. The optional
/// stages (organ contact, scoring, the trace, publishing) run under a condition on the
/// resource they serve.
pub fn haptic_schedule() -> Schedule {
    let mut schedule = Schedule::new(HapticTick);
    schedule.set_executor(SingleThreadedExecutor::new());
    schedule.configure_sets(
        (
            HapticSet::ReadDevice,
            HapticSet::ToolContact,
            HapticSet::EvaluateModes,
            HapticSet::OrganContact,
            HapticSet::ComputeForce,
            HapticSet::Safety,
            HapticSet::WriteDevice,
            HapticSet::Score,
            HapticSet::Publish,
        )
            .chain(),
    );
    schedule.add_systems((
        (
            systems::read_device,
            systems::change_instrument,
            systems::place_instrument,
        )
            .chain()
            .in_set(HapticSet::ReadDevice),
        (systems::tool_contact, systems::grasp, cutting::cut)
            .chain()
            .in_set(HapticSet::ToolContact),
        systems::evaluate_modes.in_set(HapticSet::EvaluateModes),
        (
            systems::organ_contact.run_if(resource_exists::<OrganCoupling>),
            cautery::cauterize.run_if(resource_exists::<cautery::OrganBurns>),
            biliary::tick_biliary.run_if(resource_exists::<Biliary>),
        )
            .chain()
            .in_set(HapticSet::OrganContact),
        systems::compute_force.in_set(HapticSet::ComputeForce),
        systems::apply_safety.in_set(HapticSet::Safety),
        systems::write_device.in_set(HapticSet::WriteDevice),
        (
            scoring::score_tick,
            scoring::heal_on_retry,
            scoring::heal_beds_on_retry,
        )
            .chain()
            .run_if(resource_exists::<ExerciseRun>)
            .in_set(HapticSet::Score),
        (
            systems::trace_force.run_if(any_with_component::<ForceTrace>),
            (
                scoring::publish_progress,
                systems::publish_biliary.run_if(resource_exists::<Biliary>),
                systems::publish_snapshot,
            )
                .chain()
                .run_if(resource_exists::<SnapshotPublisher>),
        )
            .in_set(HapticSet::Publish),
    ));
    schedule
}
