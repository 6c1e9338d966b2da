//! The scenario's tasks inside the haptic tick: every tick, what the trainee does (tip, force
//! sent, organ touched, button) is fed to the running [`Exercise`], so that scoring sees all
//! 1,000 samples a second, in the window as headless.
//!
//! The window starts the exercise when the trainee has read the briefing, and takes it back
//! when it has ended, to score it and show the debrief; both go through an [`ExerciseLink`],
//! which the haptic thread touches without ever waiting or allocating.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use bevy::prelude::*;

use super::components::{OrganBody, OrganDeformation, OrganIndex, ToolTouch};
use super::resources::{DeviceForce, TickClock, Tool};
use super::snapshot::SnapshotPublisher;
use crate::scenario::{Exercise, Progress, RegionSite, Sample};

/// What scoring reads of an organ entity.
type Organ = (
    &'static OrganIndex,
    &'static ToolTouch,
    &'static OrganBody,
    &'static OrganDeformation,
);

/// Between the haptic thread and whoever started the exercise: whether it has begun, and the
/// exercise once it has ended.
#[derive(Default)]
pub struct ExerciseLink {
    started: AtomicBool,
    ended: Mutex<Option<Exercise>>,
}

impl ExerciseLink {
    /// From the next tick on, the exercise is scored.
    pub fn start(&self) {
        self.started.store(true, Ordering::Release);
    }

    pub fn started(&self) -> bool {
        self.started.load(Ordering::Acquire)
    }

    /// A copy of the ended exercise (to score it for a display while it stays here).
    pub fn ended_copy(&self) -> Option<Exercise> {
        self.ended.lock().ok()?.clone()
    }

    /// The ended exercise, once (after that, `None`).
    pub fn take_ended(&self) -> Option<Exercise> {
        self.ended.lock().ok()?.take()
    }

    /// Moves the ended exercise out of `exercise` into the link without waiting; leaves it
    /// where it is if the other side holds the lock this very moment (try again next tick).
    pub(crate) fn hand_over(&self, exercise: &mut Option<Exercise>) {
        if let Ok(mut ended) = self.ended.try_lock() {
            *ended = exercise.take();
        }
    }
}

/// The exercise under way, when the session runs a scenario (`None` once handed over).
#[derive(Resource)]
pub struct ExerciseRun {
    pub exercise: Option<Exercise>,
    pub link: Arc<ExerciseLink>,
    tasks: usize,
}

impl ExerciseRun {
    pub fn new(exercise: Exercise, link: Arc<ExerciseLink>) -> Self {
        Self {
            tasks: exercise.progress().tasks,
            exercise: Some(exercise),
            link,
        }
    }

    /// Where the exercise stands; `None` before it has started.
    pub fn progress(&self) -> Option<Progress> {
        if !self.link.started() {
            return None;
        }
        Some(match &self.exercise {
            Some(exercise) => exercise.progress(),
            None => Progress {
                task: self.tasks,
                tasks: self.tasks,
                task_elapsed_s: 0.0,
            },
        })
    }
}

pub fn score_tick(
    clock: Res<TickClock>,
    tool: Res<Tool>,
    force: Res<DeviceForce>,
    organs: Query<Organ>,
    run: Option<ResMut<ExerciseRun>>,
) {
    let Some(mut run) = run else {
        return;
    };
    if !run.link.started() {
        return;
    }
    let Some(exercise) = run.exercise.as_mut() else {
        return;
    };
    let touching = organs
        .iter()
        .filter(|(index, touch, ..)| touch.contact.is_some() && index.0 < 64)
        .fold(0, |bits, (index, ..)| bits | 1 << index.0);
    let (region_moved_m, surrounding_force_n) = exercise
        .watched_region()
        .map_or((0.0, 0.0), |region| watch(region, &organs));
    exercise.step(&Sample {
        time_s: clock.time_s,
        tip_m: tool.sample.map(|s| s.tip_m),
        force_n: force.sent_n.norm(),
        touching,
        button: tool.sample.is_some_and(|s| s.buttons & 1 != 0),
        region_moved_m,
        surrounding_force_n,
    });
    if exercise.finished() {
        let run = &mut *run;
        run.link.hand_over(&mut run.exercise);
    }
}

/// How far the region has moved along its direction (m), and the force on every other organ
/// (N): the tool's on it, and what the organs it touches or hangs from put on it.
fn watch(region: &RegionSite, organs: &Query<Organ>) -> (f64, f64) {
    let mut moved_m = 0.0;
    let mut surrounding_n = 0.0;
    for (index, _, body, deformation) in organs {
        let deformation = &deformation.0;
        if index.0 == region.organ {
            moved_m = deformation
                .displacement(&body.vademecum, &region.at)
                .dot(&region.towards);
        } else {
            let tool = deformation.loads[OrganDeformation::TOOL].force_n;
            surrounding_n += tool.norm() + deformation.coupling_force_n.norm();
        }
    }
    (moved_m, surrounding_n)
}

/// Where the exercise stands, into the snapshot about to be published.
pub fn publish_progress(
    run: Option<Res<ExerciseRun>>,
    publisher: Option<ResMut<SnapshotPublisher>>,
) {
    if let Some(mut publisher) = publisher {
        publisher.0.input_buffer_mut().exercise = run.and_then(|run| run.progress());
    }
}
