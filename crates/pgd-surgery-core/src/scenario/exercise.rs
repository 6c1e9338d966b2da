//! A scenario's tasks as they run: fed one [`Sample`] per haptic tick, each task measures what
//! its kind is scored on and ends when done or out of time; then the next starts.

use std::mem::take;

use nalgebra::Vector3;
use serde::Serialize;

use super::format::{OrganEntry, Scenario, Spot, Task, TaskKind, metres};
use super::incision::{BladeSample, IncisionMetrics, IncisionTracker};
use super::keratotomy::{Keratometer, KeratotomyMetrics, KeratotomyPlan, KeratotomyTracker};
use super::mistakes::{Mistake, Mistakes, task_organ};
use super::motion::{MotionMetrics, MotionTracker};
use crate::pgd::SurfacePoint;

/// What the haptic loop knows of one tick, for scoring.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    pub tip_m: Option<Vector3<f64>>,
    /// The force sent to the device (N).
    pub force_n: f64,
    /// The organs the tool touches: bit `k` for the scenario's `organs[k]`.
    pub touching: u64,
    /// Whether the device's first button is held (the mark in palpation).
    pub button: bool,
    /// The instrument in hand, in the scenario's order (0 with one).
    pub instrument: usize,
    /// Retraction: how far (m) the watched region ([`Exercise::watched_region`]) has moved
    /// along its direction; 0 when nothing is watched.
    pub region_moved_m: f64,
    /// Retraction: the force (N) on the organs other than the watched region's, from the tool
    /// and from the organs they touch.
    pub surrounding_force_n: f64,
    /// The organs the grasper's jaws hold: bit `k` for the scenario's `organs[k]`.
    pub grasping: u64,
    /// Whether the grasper tore tissue this tick (a tear before the task began, in an
    /// earlier attempt, does not count against it).
    pub tore: bool,
    /// The scalpel's cut under way, if it is cutting.
    pub blade: Option<BladeSample>,
    /// Under a laparoscope: whether the tool's tip is in the camera's view...
    pub tip_in_view: Option<bool>,
    /// ...and whether the point the scenario has the trainee keep in view is.
    pub target_in_view: Option<bool>,
    /// How far (m) the tool pressed beyond the depth the tissue model covers (the deepest
    /// load step of the organ's nonlinear vademecum), on the organ it presses deepest so;
    /// zero within range.
    pub beyond_range_m: f64,
}

impl Sample {
    pub fn touches(&self, organ: usize) -> bool {
        organ < 64 && self.touching & (1 << organ) != 0
    }

    pub fn grasps(&self, organ: usize) -> bool {
        organ < 64 && self.grasping & (1 << organ) != 0
    }
}

/// Where a nodule of the scenario lies: its centre, and the outward normal of the organ's
/// surface nearest to it, along which a mark right above it lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoduleSite {
    pub centre_m: Vector3<f64>,
    pub outward: Vector3<f64>,
}

impl NoduleSite {
    /// How far (m) `point_m` is from the nodule across the surface: its distance from the
    /// line through the centre along the outward normal, so that depth does not count.
    pub fn lateral_distance_m(&self, point_m: &Vector3<f64>) -> f64 {
        let offset = point_m - self.centre_m;
        (offset - self.outward * offset.dot(&self.outward)).norm()
    }
}

/// Where a retraction task's region lies: the surface point of its organ (the scene's
/// `organ`-th) nearest the scenario's point, and the unit direction it is to move in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionSite {
    pub organ: usize,
    pub at: SurfacePoint,
    pub towards: Vector3<f64>,
}

/// Where the scenario's points lie on the scene's organs, found when the exercise is set up.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sites {
    /// One per nodule of the scenario, in order.
    pub nodules: Vec<NoduleSite>,
    /// One per task, in order: the region a retraction task watches.
    pub regions: Vec<Option<RegionSite>>,
    /// One per task, in order: the cut cornea's model a keratotomy task predicts its
    /// correction with.
    pub keratometers: Vec<Option<Keratometer>>,
}

/// Where an exercise stands, for the trainee's display.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Progress {
    /// The task under way (0-based); `tasks` once all have ended.
    pub task: usize,
    pub tasks: usize,
    pub task_elapsed_s: f64,
}

impl Progress {
    pub fn finished(&self) -> bool {
        self.task >= self.tasks
    }
}

/// The scenario's nodules and where each lies.
#[derive(Clone, Copy)]
struct Nodules<'a> {
    scenario: &'a Scenario,
    sites: &'a [NoduleSite],
}

impl<'a> Nodules<'a> {
    /// Where the nodules in `organ` lie.
    fn of(self, organ: &'a str) -> impl Iterator<Item = NoduleSite> + 'a {
        self.scenario
            .nodules
            .iter()
            .zip(self.sites)
            .filter(move |(nodule, _)| nodule.organ == organ)
            .map(|(_, site)| *site)
    }
}

/// Force recorded for the plot every this many ticks (100 Hz at 1 kHz).
const PLOT_EVERY: u64 = 10;
/// The share of an incision's line that must be cut for the task to be done.
pub const COVERED_TO_FINISH: f64 = 0.9;
/// Above a limit until the force falls below this share of it: one press is one error.
const HYSTERESIS: f64 = 0.9;

/// What a task measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TaskMetrics {
    pub kind: TaskKind,
    pub description: String,
    pub started_s: f64,
    pub time_limit_s: f64,
    pub completed: bool,
    /// Time spent on the task (to completion, or the whole limit).
    pub time_s: f64,
    pub contact_s: f64,
    pub peak_force_n: f64,
    /// Mean force while in contact.
    pub mean_force_n: f64,
    /// The force limit the task sets (the band's top for force control).
    pub force_limit_n: f64,
    /// Force control: the band's bottom.
    pub band_min_n: Option<f64>,
    pub time_over_limit_s: f64,
    /// Force control: time in contact with the organ within the band.
    pub within_band_s: f64,
    /// Force control and retraction: how long the task asks to hold, and the longest hold
    /// without a break.
    pub hold_s: Option<f64>,
    pub longest_hold_s: f64,
    /// Safe navigation: targets reached, of how many.
    pub targets_reached: usize,
    pub targets: usize,
    /// Safe navigation: the tip's path against the straight lines between targets (1 = straight).
    pub path_ratio: Option<f64>,
    /// Palpation: how far across the surface the mark was from the nodule (mm), if made...
    pub localization_error_mm: Option<f64>,
    /// ...and how near counts as found (mm).
    pub found_within_mm: Option<f64>,
    /// Retraction: the farthest the region moved along its direction (mm), of how far...
    pub moved_mm: Option<f64>,
    pub move_target_mm: Option<f64>,
    /// ...and the load on the organs around: its limit, its peak and the time above it.
    pub surrounding_limit_n: Option<f64>,
    pub surrounding_peak_n: f64,
    pub surrounding_over_limit_s: f64,
    /// Each error, with the time it was made (the first [`super::MISTAKES_LISTED`])...
    pub errors: Vec<String>,
    /// ...and how many more were made, counted but not listed.
    #[serde(skip_serializing_if = "is_zero")]
    pub more_errors: usize,
    /// The tool tip's motion over the task: path, economy, movements, idle time, jerk.
    pub motion: MotionMetrics,
    /// Incision: the cut against the marked line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub incision: Option<IncisionMetrics>,
    /// Laparoscopy: the time the point to keep in view was out of the camera's view (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_out_of_view_s: Option<f64>,
    /// Radial keratotomy: the incisions against the plan, and the correction they give.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub keratotomy: Option<KeratotomyMetrics>,
    /// How long the tool pressed beyond the depth the tissue model covers (s), and how far
    /// at most (mm): there the tissue stops stiffening and the force is extrapolated.
    pub beyond_range_s: f64,
    pub max_beyond_range_mm: f64,
    /// A complication (a perforated eye): the attempt fails whatever its score.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub complication: Option<String>,
}

fn is_zero(count: &usize) -> bool {
    *count == 0
}

impl TaskMetrics {
    /// Every error made, listed or not.
    pub fn error_count(&self) -> usize {
        self.errors.len() + self.more_errors
    }
}

/// One task's running state.
#[derive(Clone)]
struct Running {
    metrics: TaskMetrics,
    /// The mistakes made, put into words when the attempt is scored.
    mistakes: Mistakes,
    /// Radial keratotomy: when the cut went through the whole thickness (a complication).
    perforated_s: Option<f64>,
    force_sum: f64,
    /// Force control and palpation: the organ's index in the scenario's organs.
    organ: Option<usize>,
    /// Force control and retraction: since when what the task asks has held (the force in
    /// the band on the organ, the region moved far enough).
    held_since: Option<f64>,
    over_limit: LimitWatch,
    /// Retraction: the load on the organs around.
    over_surrounding: LimitWatch,
    /// Safe navigation: the forbidden zone the tip is in, if any.
    inside_zone: Option<usize>,
    /// Palpation: whether the button was held on the last tick.
    button_held: bool,
    /// Grasp: whether the tissue has been damaged.
    damaged: bool,
    motion: MotionTracker,
    /// Incision: the cut against the line.
    incision: Option<IncisionTracker>,
    /// Radial keratotomy: the strokes as incisions.
    keratotomy: Option<KeratotomyTracker>,
}

/// The tasks of a scenario, run one after another.
#[derive(Clone)]
pub struct Exercise {
    scenario: Scenario,
    sites: Sites,
    /// Each task's description, made up front and moved into its metrics when it starts, so
    /// that the real-time thread formats nothing then; and the room for its mistakes.
    descriptions: Vec<String>,
    mistakes: Vec<Mistakes>,
    current: usize,
    running: Option<Running>,
    /// The tasks ended, room for all made up front: their metrics are completed (motion, cut,
    /// words) when the attempt is scored.
    done: Vec<Running>,
    first_time_s: Option<f64>,
    last_time_s: Option<f64>,
    ticks: u64,
    /// (time s, force N) at 100 Hz while a task runs, for the report's plot; sized for every
    /// task's time limit up front, so the real-time thread does not reallocate it.
    pub force_trace: Vec<(f64, f64)>,
}

impl Exercise {
    /// The exercise of `scenario`, whose nodules and regions lie at `sites`.
    pub fn new(scenario: Scenario, sites: Sites) -> Self {
        let total_s: f64 = scenario.tasks.iter().map(Task::time_limit_s).sum();
        let samples = (total_s / (PLOT_EVERY as f64 * crate::devices::TICK_S)).ceil() as usize;
        Self {
            descriptions: scenario.tasks.iter().map(Task::description).collect(),
            mistakes: scenario
                .tasks
                .iter()
                .map(|_| Mistakes::reserved())
                .collect(),
            done: Vec::with_capacity(scenario.tasks.len()),
            scenario,
            sites,
            current: 0,
            running: None,
            first_time_s: None,
            last_time_s: None,
            ticks: 0,
            force_trace: Vec::with_capacity(samples + 1),
        }
    }

    /// Where the exercise stands: the task under way and how long it has run.
    pub fn progress(&self) -> Progress {
        Progress {
            task: self.current,
            tasks: self.scenario.tasks.len(),
            task_elapsed_s: match (&self.running, self.last_time_s) {
                (Some(running), Some(now)) => now - running.metrics.started_s,
                _ => 0.0,
            },
        }
    }

    /// Seconds from the exercise's first tick to `time_s` (0 before it has begun).
    pub fn elapsed_s(&self, time_s: f64) -> f64 {
        self.first_time_s
            .map_or(0.0, |first| (time_s - first).max(0.0))
    }

    /// The region the task under way watches (retraction), for the sample to measure.
    pub fn watched_region(&self) -> Option<&RegionSite> {
        self.sites.regions.get(self.current)?.as_ref()
    }

    /// Whether every task has ended.
    pub fn finished(&self) -> bool {
        self.current >= self.scenario.tasks.len()
    }

    /// Takes one tick's sample.
    pub fn step(&mut self, sample: &Sample) {
        let dt = self
            .last_time_s
            .map_or(0.0, |last| (sample.time_s - last).max(0.0));
        self.last_time_s = Some(sample.time_s);
        self.first_time_s.get_or_insert(sample.time_s);
        if self.finished() {
            return;
        }
        if self.ticks.is_multiple_of(PLOT_EVERY) {
            self.force_trace.push((sample.time_s, sample.force_n));
        }
        self.ticks += 1;
        let task = &self.scenario.tasks[self.current];
        let running = self.running.get_or_insert_with(|| {
            let description = take(&mut self.descriptions[self.current]);
            let mistakes = take(&mut self.mistakes[self.current]);
            Running::start(
                task,
                description,
                mistakes,
                &self.scenario.organs,
                sample.time_s,
            )
        });
        let nodules = Nodules {
            scenario: &self.scenario,
            sites: &self.sites.nodules,
        };
        running.step(task, sample, dt, nodules);
        let elapsed = sample.time_s - running.metrics.started_s;
        if running.over() || elapsed >= task.time_limit_s() {
            self.end_task(sample.time_s);
        }
    }

    /// Ends the task under way at `time_s` (allocating nothing: the ended task's metrics are
    /// completed when the attempt is scored).
    fn end_task(&mut self, time_s: f64) {
        if let Some(mut running) = self.running.take() {
            running.metrics.time_s = time_s - running.metrics.started_s;
            self.done.push(running);
        }
        self.current += 1;
    }

    /// Ends the exercise (unfinished tasks are not completed) and returns every task's metrics.
    pub fn finish(mut self) -> (Scenario, Vec<TaskMetrics>, Vec<(f64, f64)>) {
        let now = self.last_time_s.unwrap_or(0.0);
        while !self.finished() {
            let task = &self.scenario.tasks[self.current];
            self.running.get_or_insert_with(|| {
                let description = take(&mut self.descriptions[self.current]);
                let mistakes = take(&mut self.mistakes[self.current]);
                Running::start(task, description, mistakes, &self.scenario.organs, now)
            });
            self.end_task(now);
        }
        let tasks = self.scenario.tasks.iter();
        let mut done: Vec<TaskMetrics> = (self.done.into_iter().zip(tasks))
            .map(|(running, task)| running.into_metrics(task))
            .collect();
        predict_corrections(&mut done, &self.sites.keratometers);
        (self.scenario, done, self.force_trace)
    }
}

/// Each keratotomy's predicted correction: a full solve of the cut cornea, which is why it is
/// made when the attempt is scored, and not on the haptic thread.
fn predict_corrections(done: &mut [TaskMetrics], keratometers: &[Option<Keratometer>]) {
    for (metrics, keratometer) in done.iter_mut().zip(keratometers) {
        if let (Some(keratotomy), Some(keratometer)) = (&mut metrics.keratotomy, keratometer) {
            keratotomy.predicted_correction_d = keratometer.correction_d(keratotomy);
        }
    }
}

impl Running {
    /// The task starting at `time_s`, told to the trainee as `description`, noting its
    /// mistakes in `mistakes`.
    fn start(
        task: &Task,
        description: String,
        mistakes: Mistakes,
        organs: &[OrganEntry],
        time_s: f64,
    ) -> Self {
        let (force_limit_n, targets, band_min_n) = match task {
            Task::ForceControl {
                min_force_n,
                max_force_n,
                ..
            } => (max_force_n.0, 0, Some(min_force_n.0)),
            Task::SafeNavigation {
                targets,
                max_force_n,
                ..
            } => (max_force_n.0, targets.len(), None),
            Task::Palpation { max_force_n, .. }
            | Task::Retraction { max_force_n, .. }
            | Task::Grasp { max_force_n, .. }
            | Task::Incision { max_force_n, .. }
            | Task::RadialKeratotomy { max_force_n, .. } => (max_force_n.0, 0, None),
        };
        let hold_s = match task {
            Task::ForceControl { hold_s, .. }
            | Task::Retraction { hold_s, .. }
            | Task::Grasp { hold_s, .. } => Some(hold_s.0),
            Task::SafeNavigation { .. }
            | Task::Palpation { .. }
            | Task::Incision { .. }
            | Task::RadialKeratotomy { .. } => None,
        };
        let (move_target_mm, surrounding_limit_n) = match task {
            Task::Retraction {
                move_mm,
                max_surrounding_force_n,
                ..
            } => (Some(move_mm.0), Some(max_surrounding_force_n.0)),
            Task::Grasp { move_mm, .. } => (Some(move_mm.0), None),
            _ => (None, None),
        };
        let organ = match task {
            Task::ForceControl { organ, .. }
            | Task::Palpation { organ, .. }
            | Task::Grasp { organ, .. }
            | Task::Incision { organ, .. }
            | Task::RadialKeratotomy { organ, .. } => organs.iter().position(|o| &o.name == organ),
            // Retraction watches its organ through its region site.
            Task::SafeNavigation { .. } | Task::Retraction { .. } => None,
        };
        let incision = match task {
            Task::Incision {
                from_mm,
                to_mm,
                depth_mm,
                tolerance_mm,
                ..
            } => Some(IncisionTracker::new(
                organ,
                (metres(*from_mm), metres(*to_mm)),
                tolerance_mm.metres(),
                depth_mm.metres(),
            )),
            _ => None,
        };
        let keratotomy = match task {
            Task::RadialKeratotomy {
                incisions,
                optical_zone_mm,
                depth_fraction,
                target_correction_d,
                correction_tolerance_d,
                ..
            } => Some(KeratotomyTracker::new(
                organ,
                KeratotomyPlan {
                    incisions: incisions.0,
                    optical_zone_m: optical_zone_mm.metres(),
                    depth_fraction: depth_fraction.0,
                    target_correction_d: target_correction_d.0,
                    correction_tolerance_d: correction_tolerance_d.0,
                },
            )),
            _ => None,
        };
        Self {
            metrics: TaskMetrics {
                kind: task.kind(),
                description,
                started_s: time_s,
                time_limit_s: task.time_limit_s(),
                force_limit_n,
                band_min_n,
                targets,
                found_within_mm: match task {
                    Task::Palpation {
                        found_within_mm, ..
                    } => Some(found_within_mm.0),
                    _ => None,
                },
                move_target_mm,
                surrounding_limit_n,
                hold_s,
                ..TaskMetrics::default()
            },
            mistakes,
            perforated_s: None,
            force_sum: 0.0,
            organ,
            incision,
            keratotomy,
            button_held: false,
            damaged: false,
            held_since: None,
            over_limit: LimitWatch::default(),
            over_surrounding: LimitWatch::default(),
            inside_zone: None,
            motion: MotionTracker::default(),
        }
    }

    /// The ended task's metrics, completed: its motion, its cut, its mistakes in words.
    fn into_metrics(self, task: &Task) -> TaskMetrics {
        let mut m = self.metrics;
        m.motion = self.motion.metrics();
        m.incision = self.incision.as_ref().map(IncisionTracker::metrics);
        m.keratotomy = self.keratotomy.as_ref().map(|k| k.metrics());
        m.mean_force_n = match m.contact_s > 0.0 {
            true => self.force_sum / m.contact_s,
            false => 0.0,
        };
        (m.errors, m.more_errors) = self.mistakes.describe(task);
        m.complication = self.perforated_s.map(|time_s| {
            format!(
                "{time_s:.2} s: cut through the whole thickness of the {}: a perforation",
                task_organ(task)
            )
        });
        m
    }

    fn step(&mut self, task: &Task, sample: &Sample, dt: f64, nodules: Nodules) {
        self.motion.in_hand(sample.instrument);
        self.motion.step(sample.tip_m, dt);
        if let Some(in_view) = sample.tip_in_view {
            self.motion.view(in_view, dt);
        }
        let m = &mut self.metrics;
        if let Some(in_view) = sample.target_in_view {
            *m.target_out_of_view_s.get_or_insert(0.0) += if in_view { 0.0 } else { dt };
        }
        let force = sample.force_n;
        m.peak_force_n = m.peak_force_n.max(force);
        if sample.beyond_range_m > 0.0 {
            m.beyond_range_s += dt;
            m.max_beyond_range_mm = m.max_beyond_range_mm.max(sample.beyond_range_m * 1e3);
        }
        if sample.touching != 0 || sample.grasping != 0 {
            m.contact_s += dt;
            self.force_sum += force * dt;
        }
        if self
            .over_limit
            .crossed(force, m.force_limit_n, dt, &mut m.time_over_limit_s)
        {
            self.mistakes.note(Mistake::OverLimit {
                time_s: sample.time_s,
                limit_n: m.force_limit_n,
            });
        }
        match task {
            Task::ForceControl {
                min_force_n,
                max_force_n,
                hold_s,
                ..
            } => {
                let on_organ = self.organ.is_some_and(|k| sample.touches(k));
                let in_band = on_organ && (min_force_n.0..=max_force_n.0).contains(&force);
                if in_band {
                    self.metrics.within_band_s += dt;
                }
                self.hold(in_band, hold_s.0, sample.time_s);
            }
            Task::SafeNavigation {
                targets, forbidden, ..
            } => self.navigate(targets, forbidden, sample),
            Task::Palpation {
                organ,
                found_within_mm,
                ..
            } => self.palpate(nodules.of(organ), found_within_mm.metres(), sample),
            Task::Retraction {
                move_mm,
                hold_s,
                max_surrounding_force_n,
                ..
            } => {
                self.load_around(max_surrounding_force_n.0, sample, dt);
                let moved_mm = self.region_moved_mm(sample);
                self.hold(moved_mm >= move_mm.0, hold_s.0, sample.time_s);
            }
            Task::Grasp {
                move_mm, hold_s, ..
            } => self.grasp((move_mm.0, hold_s.0), sample),
            Task::Incision { .. } => self.cut(sample),
            Task::RadialKeratotomy { .. } => self.keratotomy(sample),
        }
    }

    /// Radial keratotomy: the task is done when the plan's incisions are made and the blade
    /// is lifted. A cut through the whole thickness is a complication: the task cannot be
    /// done any more and the attempt fails.
    fn keratotomy(&mut self, sample: &Sample) {
        let Some(tracker) = self.keratotomy.as_mut() else {
            return;
        };
        if tracker.step(sample.blade.as_ref()) {
            self.perforated_s.get_or_insert(sample.time_s);
        }
        self.metrics.completed = !tracker.cutting()
            && tracker.made() >= tracker.planned()
            && self.perforated_s.is_none();
    }

    /// Incision: the cut follows the line; the task is done when nine tenths of it are cut
    /// and the blade is lifted. Straying farther than twice the tolerance off the line is an
    /// error (once).
    fn cut(&mut self, sample: &Sample) {
        let Some(tracker) = self.incision.as_mut() else {
            return;
        };
        let strayed_before = tracker.strayed();
        tracker.step(sample.blade.as_ref());
        if !strayed_before && tracker.strayed() {
            self.mistakes.note(Mistake::OffTheLine {
                time_s: sample.time_s,
                limit_mm: tracker.stray_limit_m() * 1e3,
            });
        }
        let lifted = sample.blade.is_none_or(|b| Some(b.organ) != self.organ);
        self.metrics.completed = lifted && tracker.covered_share() >= COVERED_TO_FINISH;
    }

    /// Retraction and grasp: how far the region has moved (mm), kept as the farthest yet.
    fn region_moved_mm(&mut self, sample: &Sample) -> f64 {
        let m = &mut self.metrics;
        let moved_mm = sample.region_moved_m * 1e3;
        m.moved_mm = Some(m.moved_mm.map_or(moved_mm, |most| most.max(moved_mm)));
        moved_mm
    }

    /// Grasp: held in the jaws and drawn far enough for the hold, then let go; a damaged
    /// tissue is an error and the task can no longer be done.
    fn grasp(&mut self, (move_mm, hold_s): (f64, f64), sample: &Sample) {
        let grasped = self.organ.is_some_and(|k| sample.grasps(k));
        if sample.tore && !self.damaged {
            self.damaged = true;
            self.mistakes.note(Mistake::Tore {
                time_s: sample.time_s,
            });
        }
        let moved_mm = self.region_moved_mm(sample);
        if self.metrics.longest_hold_s < hold_s {
            self.hold(grasped && moved_mm >= move_mm, hold_s, sample.time_s);
        }
        let m = &mut self.metrics;
        m.completed = m.longest_hold_s >= hold_s && !grasped && !self.damaged;
    }

    /// Completes the task once `holding` has been true for `hold_s` without a break.
    fn hold(&mut self, holding: bool, hold_s: f64, time_s: f64) {
        if holding {
            let since = *self.held_since.get_or_insert(time_s);
            let m = &mut self.metrics;
            m.longest_hold_s = m.longest_hold_s.max(time_s - since);
            m.completed = m.longest_hold_s >= hold_s;
        } else {
            self.held_since = None;
        }
    }

    /// Retraction: the load on the organs around, against its limit.
    fn load_around(&mut self, limit_n: f64, sample: &Sample, dt: f64) {
        let m = &mut self.metrics;
        let force = sample.surrounding_force_n;
        m.surrounding_peak_n = m.surrounding_peak_n.max(force);
        if self
            .over_surrounding
            .crossed(force, limit_n, dt, &mut m.surrounding_over_limit_s)
        {
            self.mistakes.note(Mistake::OverSurrounding {
                time_s: sample.time_s,
                limit_n,
            });
        }
    }

    /// A press of the button while on the organ is the mark: the task ends with it, found if
    /// the mark is near enough a nodule. A press off the organ marks nothing.
    fn palpate(
        &mut self,
        nodules: impl Iterator<Item = NoduleSite>,
        found_within_m: f64,
        sample: &Sample,
    ) {
        let pressed = sample.button && !self.button_held;
        self.button_held = sample.button;
        let on_organ = self.organ.is_some_and(|k| sample.touches(k));
        let (true, true, Some(tip)) = (pressed, on_organ, sample.tip_m) else {
            return;
        };
        let Some(error_m) = nodules
            .map(|site| site.lateral_distance_m(&tip))
            .min_by(f64::total_cmp)
        else {
            return;
        };
        let m = &mut self.metrics;
        m.localization_error_mm = Some(error_m * 1e3);
        m.completed = error_m <= found_within_m;
    }

    /// Whether the task is over before its time: done, (palpation) marked, right or wrong, or
    /// ended by a complication.
    fn over(&self) -> bool {
        let m = &self.metrics;
        m.completed || m.localization_error_mm.is_some() || self.perforated_s.is_some()
    }

    fn navigate(&mut self, targets: &[Spot], forbidden: &[Spot], sample: &Sample) {
        // The motion tracker has taken this tick's tip: its start and path are the task's.
        let (Some(tip), Some(first)) = (sample.tip_m, self.motion.start()) else {
            return;
        };
        let path_m = self.motion.path_length_m();
        let m = &mut self.metrics;
        if let Some(target) = targets.get(m.targets_reached)
            && target.contains(&tip)
        {
            m.targets_reached += 1;
            if m.targets_reached == targets.len() {
                m.completed = true;
                m.path_ratio = Some(path_m / straight_length_m(first, targets).max(1e-6));
            }
        }
        match self.inside_zone {
            Some(k) => {
                let zone = &forbidden[k];
                if (tip - zone.centre_m()).norm() > zone.radius_mm.metres() / HYSTERESIS {
                    self.inside_zone = None;
                }
            }
            None => {
                if let Some(k) = forbidden.iter().position(|z| z.contains(&tip)) {
                    self.inside_zone = Some(k);
                    self.mistakes.note(Mistake::Forbidden {
                        time_s: sample.time_s,
                        zone: k,
                    });
                }
            }
        }
    }
}

/// One force limit as a task watches it: the time spent above it, and a press above it seen
/// once (it ends when the force falls below [`HYSTERESIS`] of the limit).
#[derive(Clone, Copy, Default)]
struct LimitWatch {
    over: bool,
}

impl LimitWatch {
    /// Adds `dt` to `time_over` while `force` is above `limit`; true on the tick it goes over.
    fn crossed(&mut self, force: f64, limit: f64, dt: f64, time_over: &mut f64) -> bool {
        if force > limit {
            *time_over += dt;
            let crossed = !self.over;
            self.over = true;
            crossed
        } else {
            if force < HYSTERESIS * limit {
                self.over = false;
            }
            false
        }
    }
}

/// The straight path from `start` through the targets, in order (m).
fn straight_length_m(start: Vector3<f64>, targets: &[Spot]) -> f64 {
    let mut length = 0.0;
    let mut from = start;
    for target in targets {
        length += (target.centre_m() - from).norm();
        from = target.centre_m();
    }
    length
}
