//! Cut along a line marked on an organ's surface, to a depth, with the scalpel.

use parry3d::query::PointQuery;
use serde::{Deserialize, Serialize};

use crate::mesh::Surface;
use crate::scenario::incision::{IncisionMetrics, IncisionTracker};
use crate::scenario::scene::{OrganEntry, metres};
use crate::scenario::task::{
    RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
};
use crate::scenario::units::Millimetres;

/// `Incision(organ, from_mm, to_mm, depth_mm, tolerance_mm, max_force_n, time_limit_s)`: done
/// when the cut covers nine tenths of the line within `tolerance_mm` of it and the blade is
/// lifted; scored on the deviation from the line, the depth against `depth_mm`, the strokes
/// it took, the force and the time.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Incision {
    pub from_mm: (f64, f64, f64),
    pub to_mm: (f64, f64, f64),
    pub depth_mm: Millimetres,
    pub tolerance_mm: Millimetres,
}

/// The share of an incision's line that must be cut for the task to be done.
pub const COVERED_TO_FINISH: f64 = 0.9;
/// The mistake of straying off the line (the limit, mm, the amount).
const OFF_THE_LINE: u16 = 0;
/// The deepest incision a task may ask for (mm).
const MAX_INCISION_DEPTH_MM: f64 = 30.0;
/// How far (mm) a line's end may lie from the organ's surface as the check meshes it (the
/// coarse organ, whose surface is within a few millimetres of the full one's).
const LINE_ON_SURFACE_MM: f64 = 5.0;

impl TaskType for Incision {
    const NAME: &'static str = "Incision";
    const LABEL: &'static str = "incision";
    type Run = IncisionRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "cut the marked line on the {}, {:.0} mm long and {:.0} mm deep, under {} N",
            shared.organ.as_deref().unwrap_or_default(),
            (metres(self.to_mm) - metres(self.from_mm)).norm() * 1e3,
            self.depth_mm.0,
            shared.max_force_n
        )
    }

    /// A scalpel, an organ a scalpel can part, a line of some length on its surface and a
    /// depth the organs' thickness allows.
    fn check(&self, check: &mut TaskCheck<'_>) {
        check_blade(check);
        let anchors = |name| ["tasks", "Incision", name];
        let length_mm = (metres(self.to_mm) - metres(self.from_mm)).norm() * 1e3;
        if length_mm < 5.0 {
            check.problem_at(
                "to_mm",
                &anchors("to_mm"),
                format!("the line is {length_mm:.1} mm long: too short to cut and score"),
                "mark a line at least 5 mm long, from_mm to to_mm in the scene's frame",
            );
        }
        if let Some(entry) = check.organ()
            && let Some((end, distance_mm)) =
                farthest_off_surface(entry, [self.from_mm, self.to_mm])
        {
            let name = ["from_mm", "to_mm"][end];
            let organ = &entry.name;
            check.problem_at(
                name,
                &anchors(name),
                format!("the line's end is {distance_mm:.0} mm off the {organ}'s surface"),
                format!(
                    "mark the line on the {organ}'s surface (within {LINE_ON_SURFACE_MM} mm); \
                     `pgd mesh {organ} --out FILE.vtu` writes its mesh to look at"
                ),
            );
        }
        let depth_mm = self.depth_mm.0;
        if depth_mm > MAX_INCISION_DEPTH_MM {
            check.problem_at(
                "depth_mm",
                &anchors("depth_mm"),
                format!("{depth_mm} mm is deeper than a scalpel's incision goes here"),
                format!("at most {MAX_INCISION_DEPTH_MM} mm"),
            );
        }
        check.within_device();
    }

    fn run(&self, _: &TaskShared, setup: RunSetup) -> IncisionRun {
        IncisionRun {
            organ: setup.organ,
            tracker: IncisionTracker::new(
                setup.organ,
                metres(self.from_mm),
                metres(self.to_mm),
                self.tolerance_mm.metres(),
                self.depth_mm.metres(),
            ),
        }
    }

    fn describe_mistake(&self, shared: &TaskShared, code: u16, limit_mm: f64) -> String {
        debug_assert_eq!(code, OFF_THE_LINE);
        format!(
            "cut the {} more than {limit_mm:.0} mm off the line",
            shared.organ.as_deref().unwrap_or("organ")
        )
    }
}

/// A cutting task needs a scalpel and an organ whose toughness under a blade is known.
pub(super) fn check_blade(check: &mut TaskCheck<'_>) {
    let task = check.name();
    let anchors = ["tasks", task, "organ"];
    if !check.scene.blade {
        check.problem_at(
            "organ",
            &anchors,
            format!("an {task} task needs a scalpel to cut with"),
            "set tool: Scalpel(tip_radius_mm: 6.0)",
        );
    }
    if let Some(entry) = check.organ()
        && entry.toughness_j_per_m2().is_none()
    {
        let organ = &entry.name;
        check.problem_at(
            "organ",
            &anchors,
            format!("the {organ}'s toughness under a blade is not known: it cannot be cut"),
            format!(
                "give it one: Organ(name: \"{organ}\", toughness_j_per_m2: 190.0) (the liver's is known)"
            ),
        );
    }
}

/// The end of `points_mm` farthest from the organ's surface (0 or 1) and its distance (mm), if
/// more than [`LINE_ON_SURFACE_MM`]; `None` also when the organ's mesh cannot be had (its own
/// check says why).
fn farthest_off_surface(
    entry: &OrganEntry,
    points_mm: [(f64, f64, f64); 2],
) -> Option<(usize, f64)> {
    let mesh = entry.outline_mesh()?;
    let surface = Surface::extract(&mesh);
    let positions: Vec<[f32; 3]> = mesh
        .nodes()
        .iter()
        .map(|p| p.cast::<f32>().into())
        .collect();
    let triangles: Vec<[u32; 3]> = surface
        .triangles
        .iter()
        .map(|t| t.map(|n| n as u32))
        .collect();
    let trimesh = crate::parry_interop::trimesh(&positions, &triangles)?;
    let distance_mm = |p: (f64, f64, f64)| {
        let point = nalgebra::Point3::from(metres(p));
        let query = crate::parry_interop::to_parry(&point);
        let projected = trimesh.project_local_point(query, false).point;
        (crate::parry_interop::from_parry(projected) - point).norm() * 1e3
    };
    let distances = points_mm.map(distance_mm);
    let end = usize::from(distances[1] > distances[0]);
    (distances[end] > LINE_ON_SURFACE_MM).then_some((end, distances[end]))
}

#[derive(Clone, Debug)]
pub struct IncisionRun {
    organ: Option<usize>,
    tracker: IncisionTracker,
}

impl TaskRun for IncisionRun {
    type Result = IncisionResult;

    /// The cut follows the line; the task is done when nine tenths of it are cut and the
    /// blade is lifted. Straying farther than twice the tolerance off the line is an error
    /// (once).
    fn step(&mut self, tick: &mut Tick<'_>) {
        let tracker = &mut self.tracker;
        let strayed_before = tracker.strayed();
        tracker.step(tick.sample.blade.as_ref());
        if !strayed_before && tracker.strayed() {
            tick.mistake(OFF_THE_LINE, tracker.stray_limit_m() * 1e3);
        }
        let lifted = (tick.sample.blade).is_none_or(|b| Some(b.organ) != self.organ);
        tick.metrics.completed = lifted && tracker.covered_share() >= COVERED_TO_FINISH;
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(TaskProgress {
            what: "line cut:",
            done: 100.0 * self.tracker.covered_share(),
            of: 100.0 * COVERED_TO_FINISH,
            unit: "%",
        })
    }

    fn result(&self) -> IncisionResult {
        IncisionResult {
            incision: self.tracker.metrics(),
        }
    }
}

/// An incision's measures: the cut against the marked line.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct IncisionResult {
    pub incision: IncisionMetrics,
}

impl TaskResult for IncisionResult {
    /// The mean of the line's accuracy (1 on it, falling to 0 at twice the tolerance off it
    /// on average) and the depth's (1 at the target, falling to 0 at half or twice as deep);
    /// 0 with nothing cut.
    fn accuracy(&self) -> Option<f64> {
        let cut = &self.incision;
        if cut.covered_mm <= 0.0 {
            return Some(0.0);
        }
        let line = 1.0 - cut.mean_deviation_mm / (2.0 * cut.tolerance_mm);
        let depth = depth_accuracy(cut.mean_depth_mm / cut.target_depth_mm);
        Some(0.5 * (line.clamp(0.0, 1.0) + depth))
    }

    /// What the cut missed: the line, its depth.
    fn feedback(&self) -> Vec<String> {
        let cut = &self.incision;
        let mut lines = Vec::new();
        if cut.covered_mm < COVERED_TO_FINISH * cut.line_length_mm {
            lines.push(format!(
                "cut {:.0} of the line's {:.0} mm (strokes: {})",
                cut.covered_mm, cut.line_length_mm, cut.strokes
            ));
        }
        if cut.mean_deviation_mm > cut.tolerance_mm {
            lines.push(format!(
                "{:.1} mm off the line on average (within {:.0} mm counts)",
                cut.mean_deviation_mm, cut.tolerance_mm
            ));
        }
        let (depth, target) = (cut.mean_depth_mm, cut.target_depth_mm);
        if cut.covered_mm > 0.0 && !(0.75 * target..=1.25 * target).contains(&depth) {
            lines.push(format!(
                "cut {depth:.1} mm deep on average for {target:.0} mm"
            ));
        }
        lines
    }
}

/// 1 at the target depth (`ratio` of it 1), falling to 0 at half or twice as deep.
pub(super) fn depth_accuracy(ratio: f64) -> f64 {
    (1.0 - ratio.ln().abs() / 2f64.ln()).clamp(0.0, 1.0)
}
