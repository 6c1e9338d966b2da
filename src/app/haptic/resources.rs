//! The haptic world's resources, shared by every hand: the clock, the organs' coupling and
//! the laparoscope.

use std::sync::Arc;

use bevy::prelude::*;
use nalgebra::Vector3;

use crate::contact::Coupling;
use crate::devices::{Laparoscope, ScopeHandle, ScopePose, ScopeScript};
use crate::dissection::TiedOrgans;

/// The tick being run, set by the runner before each run of the schedule.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct TickClock {
    pub tick: u64,
    pub time_s: f64,
    /// Ticks in a row that missed their deadline.
    pub overruns_in_a_row: u32,
}

/// The organs' contact and attachments, with their state from tick to tick.
#[derive(Resource, Clone)]
pub struct OrganCoupling(pub Coupling);

/// The beds binding organs to others, with their ties' state from tick to tick; run by the
/// contact stage with the coupling.
#[derive(Resource, Clone)]
pub struct OrganBeds(pub Vec<TiedOrgans>);

/// A scene's laparoscope: its optic, its pose (shared with the window, which steers it), and
/// the point the trainee is to keep in view, if any.
#[derive(Clone, Debug)]
pub struct SceneScope {
    pub scope: Laparoscope,
    pub pose: Arc<ScopeHandle>,
    pub keep_in_view_m: Option<Vector3<f64>>,
    /// The camera moved by the scenario, if the trainee does not steer it.
    pub script: Option<ScopeScript>,
}

/// The laparoscope inside the haptic world, with the pose it was last read at.
#[derive(Resource, Debug)]
pub struct Scope {
    pub rig: SceneScope,
    pub pose: ScopePose,
}

impl Scope {
    pub fn new(rig: SceneScope) -> Self {
        let pose = rig.pose.get();
        Self { rig, pose }
    }

    /// Moves a scripted camera to where it is `elapsed_s` into the exercise (and tells the
    /// window), or reads the pose the trainee steered it to (keeping the last one while the
    /// window holds it); then says whether the tip (if known) and the point to keep in view
    /// are in view.
    pub fn in_view(
        &mut self,
        tip_m: Option<&Vector3<f64>>,
        elapsed_s: f64,
    ) -> (Option<bool>, Option<bool>) {
        match &self.rig.script {
            Some(script) => {
                if let Some(pose) = script.pose_at(&self.rig.scope, elapsed_s) {
                    self.pose = pose;
                    self.rig.pose.try_set(pose);
                }
            }
            None => {
                if let Some(pose) = self.rig.pose.try_get() {
                    self.pose = pose;
                }
            }
        }
        let sees = |point: &Vector3<f64>| self.sees(point);
        (tip_m.map(sees), self.rig.keep_in_view_m.as_ref().map(sees))
    }

    /// Whether `point` is in the view where the camera was last read.
    pub fn sees(&self, point: &Vector3<f64>) -> bool {
        self.rig.scope.sees(&self.pose, point)
    }
}
