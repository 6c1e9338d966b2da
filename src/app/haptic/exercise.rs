//! The scenario's tasks inside the haptic tick: every tick, what the trainee does (tip, force
//! sent, organ touched) is fed to the running [`Exercise`], so that scoring sees all 1,000
//! samples a second, in the window as headless.

use bevy::prelude::*;

use super::components::{OrganIndex, ToolTouch};
use super::resources::{DeviceForce, TickClock, Tool};
use crate::scenario::{Exercise, Sample};

/// The exercise under way, when the session runs a scenario.
#[derive(Resource)]
pub struct ExerciseRun(pub Exercise);

pub fn score_tick(
    clock: Res<TickClock>,
    tool: Res<Tool>,
    force: Res<DeviceForce>,
    organs: Query<(&OrganIndex, &ToolTouch)>,
    exercise: Option<ResMut<ExerciseRun>>,
) {
    let Some(mut exercise) = exercise else {
        return;
    };
    let touching = organs
        .iter()
        .filter(|(index, touch)| touch.contact.is_some() && index.0 < 64)
        .fold(0, |bits, (index, _)| bits | 1 << index.0);
    exercise.0.step(&Sample {
        time_s: clock.time_s,
        tip_m: tool.sample.map(|s| s.tip_m),
        force_n: force.sent_n.norm(),
        touching,
        button: tool.sample.is_some_and(|s| s.buttons & 1 != 0),
    });
}
