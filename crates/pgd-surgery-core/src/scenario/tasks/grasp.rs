//! Take hold of the organ with the grasper, draw it and let go, without tearing it.

use serde::{Deserialize, Serialize};

use super::region::{RegionMove, RegionResult, check_towards, watched};
use crate::scenario::task::{
    RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick, Watched,
};
use crate::scenario::units::{Millimetres, Seconds};

/// `Grasp(organ, region, at_mm, towards, move_mm, hold_s, max_force_n, time_limit_s)`: close
/// the jaws on the organ's `region` (the surface nearest `at_mm`), draw it at least
/// `move_mm` along `towards`, keep it there for `hold_s`, then open the jaws. Damaging the
/// tissue (pulling it harder or further than it bears) fails the task.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grasp {
    pub region: String,
    pub at_mm: (f64, f64, f64),
    pub towards: (f64, f64, f64),
    pub move_mm: Millimetres,
    pub hold_s: Seconds,
}

/// The mistake of tearing the organ.
const TORE: u16 = 0;

impl TaskType for Grasp {
    const NAME: &'static str = "Grasp";
    const LABEL: &'static str = "grasp";
    const FORCE_VERB: &'static str = "pulled";
    type Run = GraspRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "grasp {} of the {}, draw it {:.0} mm, hold it {} s and let go, under {} N and \
             without tearing it",
            self.region,
            shared.organ.as_deref().unwrap_or_default(),
            self.move_mm.0,
            self.hold_s.0,
            shared.max_force_n
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        if !check.scene.grasps {
            check.problem(
                "organ",
                "a Grasp task needs a grasper to grasp with",
                "set tool: Grasper(tip_radius_mm: 6.0)",
            );
        }
        check_towards(check, self.towards);
        check.hold_fits(self.hold_s.0);
    }

    fn watched<'a>(&'a self, shared: &'a TaskShared) -> Option<Watched<'a>> {
        watched(shared, self.at_mm, self.towards)
    }

    fn run(&self, _: &TaskShared, setup: RunSetup) -> GraspRun {
        GraspRun {
            organ: setup.organ,
            region: RegionMove::new(self.move_mm.0, self.hold_s.0),
            damaged: false,
        }
    }

    fn describe_mistake(&self, shared: &TaskShared, code: u16, _: f64) -> String {
        debug_assert_eq!(code, TORE);
        format!("tore the {}", shared.organ.as_deref().unwrap_or("organ"))
    }
}

#[derive(Clone, Debug)]
pub struct GraspRun {
    organ: Option<usize>,
    region: RegionMove,
    /// Whether the tissue has been damaged: the task can no longer be done.
    damaged: bool,
}

impl TaskRun for GraspRun {
    type Result = GraspResult;

    /// Held in the jaws and drawn far enough for the hold, then let go.
    fn step(&mut self, tick: &mut Tick<'_>) {
        let sample = tick.sample;
        let grasped = self.organ.is_some_and(|k| sample.grasps(k));
        if sample.tore && !self.damaged {
            self.damaged = true;
            tick.mistake(TORE, 0.0);
        }
        let moved_mm = self.region.moved(sample.region_moved_m);
        let region = &mut self.region;
        if region.hold.longest_s < region.hold_s {
            region.hold(grasped && moved_mm >= region.move_mm, sample.time_s);
        }
        tick.metrics.completed =
            region.hold.longest_s >= region.hold_s && !grasped && !self.damaged;
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(self.region.progress())
    }

    fn result(&self) -> GraspResult {
        GraspResult {
            region: self.region.result(),
        }
    }
}

/// A grasp's measures: the region's move and hold.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GraspResult {
    #[serde(flatten)]
    pub region: RegionResult,
}

impl TaskResult for GraspResult {
    fn unfinished(&self) -> Option<String> {
        Some(self.region.unfinished())
    }
}
