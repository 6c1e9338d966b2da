//! A scenario's tasks as they run: fed one [`Sample`] per haptic tick, each task measures what
//! its kind is scored on and ends when done or out of time; then the next starts.

use super::bimanual::BimanualTracker;
use super::format::Scenario;
use super::keratotomy::Keratometer;
use super::motion::MotionTracker;
use super::sample::{NoduleSite, RegionSite, Sample};
use super::task::{
    AnyRun, CountertractionWatch, Hand, LimitWatch, Mistake, Mistakes, RunSetup, Task, TaskMetrics,
    TaskProgress, Tick,
};
use crate::biliary::ViewRecord;

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
    /// Room for what the critical view of safety is judged on, in a scene with a biliary
    /// tree: kept while the exercise runs, for the debrief's pictures.
    pub critical_view: Option<ViewRecord>,
}

/// Where an exercise stands, for the trainee's display.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Progress {
    /// The task under way (0-based); `tasks` once all have ended.
    pub task: usize,
    pub tasks: usize,
    pub task_elapsed_s: f64,
    /// How far the task under way has come, if its type says.
    pub step: Option<TaskProgress>,
}

impl Progress {
    pub fn finished(&self) -> bool {
        self.task >= self.tasks
    }
}

/// Force recorded for the plot every this many ticks (100 Hz at 1 kHz).
const PLOT_EVERY: u64 = 10;

/// One task's running state: what every task measures, and its type's run.
#[derive(Clone)]
struct Running {
    metrics: TaskMetrics,
    /// The mistakes made, put into words when the attempt is scored.
    mistakes: Mistakes,
    force_sum: f64,
    over_limit: LimitWatch,
    motion: MotionTracker,
    /// Both hands, in a bimanual exercise.
    hands: Option<BimanualTracker>,
    /// The hand that does the task.
    hand: Hand,
    /// The other hand's hold, when the task asks for counter-traction.
    countertraction: Option<CountertractionWatch>,
    /// The task's instruments among its hand's: the kind of each of the hand's instruments
    /// it is not done with (none where any will do).
    other_instruments: Vec<Option<&'static str>>,
    /// Whether the hand was on tissue with one of those last tick (none before the first).
    on_with_other: Option<bool>,
    run: Box<dyn AnyRun>,
}

/// The tasks of a scenario, run one after another.
#[derive(Clone)]
pub struct Exercise {
    scenario: Scenario,
    sites: Sites,
    /// Each task's run, made up front with its description and the room for its mistakes,
    /// and taken when the task starts, so that the real-time thread allocates nothing then.
    prepared: Vec<Option<Running>>,
    current: usize,
    running: Option<Running>,
    /// The tasks ended, room for all made up front: their metrics are completed (motion, the
    /// type's own, words) when the attempt is scored.
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
        let prepared = (scenario.tasks.iter().enumerate())
            .map(|(k, task)| {
                let setup = setup(&scenario, &sites, k);
                Some(Running::prepare(task, setup, &scenario))
            })
            .collect();
        Self {
            prepared,
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
            step: self.running.as_ref().and_then(|r| r.run.progress()),
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
        let running = self.start(sample.time_s);
        running.step(sample, dt);
        let elapsed = sample.time_s - running.metrics.started_s;
        if running.over() || elapsed >= running.metrics.time_limit_s {
            self.end_task(sample.time_s);
        }
    }

    /// The task under way, started at `time_s` if it has not begun.
    fn start(&mut self, time_s: f64) -> &mut Running {
        let prepared = &mut self.prepared[self.current];
        self.running.get_or_insert_with(|| {
            let mut running = prepared.take().expect("each task's run is made up front");
            running.metrics.started_s = time_s;
            running
        })
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

    /// Where what the critical view is judged on is kept while a task runs (`None` before
    /// the exercise starts, after it ends, or in a scene without a biliary tree).
    pub fn critical_view_mut(&mut self) -> Option<&mut ViewRecord> {
        let running = self.first_time_s.is_some() && !self.finished();
        self.sites.critical_view.as_mut().filter(|_| running)
    }

    /// Ends the exercise (unfinished tasks are not completed) and returns every task's metrics.
    pub fn finish(mut self) -> Finished {
        let now = self.last_time_s.unwrap_or(0.0);
        while !self.finished() {
            self.start(now);
            self.end_task(now);
        }
        let tasks = self.scenario.tasks.iter();
        let done: Vec<TaskMetrics> = (self.done.into_iter().zip(tasks))
            .map(|(running, task)| running.into_metrics(task))
            .collect();
        Finished {
            scenario: self.scenario,
            tasks: done,
            force_trace: self.force_trace,
            critical_view: self.sites.critical_view.filter(|r| r.time_s.is_some()),
        }
    }
}

/// An ended exercise: its scenario, every task's metrics, the force against time and what
/// the critical view was judged on last, if it ever was.
pub struct Finished {
    pub scenario: Scenario,
    pub tasks: Vec<TaskMetrics>,
    /// (time s, force N) at 100 Hz.
    pub force_trace: Vec<(f64, f64)>,
    pub critical_view: Option<ViewRecord>,
}

/// What the `k`th task's run is given: its organ's place in the scene, the nodules in it and
/// the cut organ's model.
fn setup(scenario: &Scenario, sites: &Sites, k: usize) -> RunSetup {
    let organ = scenario.tasks[k].organ();
    RunSetup {
        organ: organ.and_then(|name| scenario.organs.iter().position(|o| o.name == name)),
        nodules: (scenario.nodules.iter().zip(&sites.nodules))
            .filter(|(nodule, _)| Some(nodule.organ.as_str()) == organ)
            .map(|(_, site)| *site)
            .collect(),
        keratometer: sites.keratometers.get(k).cloned().flatten(),
        organ_names: scenario.organs.iter().map(|o| o.name.clone()).collect(),
    }
}

/// For each instrument of `task`'s hand, its kind if the task's `instruments` leave it out
/// (all none when the task names none).
fn other_instruments(scenario: &Scenario, task: &Task) -> Vec<Option<&'static str>> {
    let hand = match task.hand() {
        Hand::Right => 0,
        Hand::Left => 1,
    };
    let named = &task.shared.instruments;
    let hands = scenario.hands();
    let instruments = hands.get(hand).map_or(&[][..], |h| &h[..]);
    (instruments.iter())
        .map(|(tool, _)| tool.kind())
        .map(|kind| (!named.is_empty() && !named.iter().any(|n| n == kind)).then_some(kind))
        .collect()
}

/// The watch of `task`'s counter-traction, if it asks for one (on an organ of the scenario's:
/// the scenario's check makes sure).
fn countertraction(scenario: &Scenario, task: &Task) -> Option<CountertractionWatch> {
    let countertraction = task.shared.countertraction.as_ref()?;
    let organ = (scenario.organs.iter()).position(|o| o.name == countertraction.organ)?;
    Some(CountertractionWatch::new(countertraction, organ))
}

impl Running {
    /// The run of `task`, one of `scenario`'s, before it starts.
    fn prepare(task: &Task, setup: RunSetup, scenario: &Scenario) -> Self {
        Self {
            metrics: TaskMetrics {
                kind: task.label(),
                description: task.description(),
                time_limit_s: task.time_limit_s(),
                force_limit_n: task.max_force_n(),
                ..TaskMetrics::default()
            },
            mistakes: Mistakes::reserved(),
            force_sum: 0.0,
            over_limit: LimitWatch::default(),
            motion: MotionTracker::default(),
            hands: scenario.bimanual().then(BimanualTracker::default),
            hand: task.hand(),
            countertraction: countertraction(scenario, task),
            other_instruments: other_instruments(scenario, task),
            on_with_other: None,
            run: task.run(setup),
        }
    }

    /// The ended task's metrics, completed: its motion, its type's own, its mistakes in words.
    fn into_metrics(self, task: &Task) -> TaskMetrics {
        let mut m = self.metrics;
        m.motion = self.motion.metrics();
        m.hands = self.hands.as_ref().map(BimanualTracker::metrics);
        m.countertraction = (self.countertraction.as_ref()).map(CountertractionWatch::metrics);
        m.mean_force_n = match m.contact_s > 0.0 {
            true => self.force_sum / m.contact_s,
            false => 0.0,
        };
        (m.errors, m.more_errors) = self.mistakes.describe(task);
        let outcome = self.run.result();
        m.complication = outcome.complication();
        m.outcome = Some(outcome);
        m
    }

    /// What every task measures of a tick, then what its type measures.
    fn step(&mut self, sample: &Sample, dt: f64) {
        if let (Some(hands), Some(left)) = (&mut self.hands, &sample.left) {
            hands.step(sample, left, dt);
        }
        self.step_countertraction(sample, dt);
        let own;
        let sample = match self.hand {
            Hand::Right => sample,
            Hand::Left => {
                own = sample.of_left_hand();
                &own
            }
        };
        self.watch_instrument(sample);
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
        let mut tick = Tick {
            sample,
            dt,
            metrics: &mut self.metrics,
            mistakes: &mut self.mistakes,
            motion: &self.motion,
        };
        self.run.step(&mut tick);
    }

    /// Notes each time the hand comes onto tissue with an instrument the task is not done
    /// with (not when the task begins there: the instrument the last task left in hand).
    fn watch_instrument(&mut self, sample: &Sample) {
        let working = sample.touching != 0 || sample.grasping != 0;
        let other = self
            .other_instruments
            .get(sample.instrument)
            .copied()
            .flatten();
        let on_with_other = working && other.is_some();
        if let (Some(false), Some(kind), true) = (self.on_with_other, other, on_with_other) {
            (self.mistakes).note(Mistake::OtherInstrument {
                time_s: sample.time_s,
                kind,
            });
        }
        self.on_with_other = Some(on_with_other);
    }

    /// Watches the other hand's hold, if the task asks for one.
    fn step_countertraction(&mut self, sample: &Sample, dt: f64) {
        let (Some(watch), Some(left)) = (&mut self.countertraction, sample.left) else {
            return;
        };
        let other = match self.hand {
            Hand::Right => left,
            Hand::Left => sample.right(),
        };
        if let Some(lapse) = watch.step(&other, dt) {
            (self.mistakes).note(Mistake::Countertraction {
                time_s: sample.time_s,
                lapse,
            });
        }
    }

    /// Whether the task is over before its time: done, or ended as its type says.
    fn over(&self) -> bool {
        self.metrics.completed || self.run.over()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A press to be made with the hook, the probe also in hand: coming onto the liver with
    /// the probe is a mistake each time (not when the task begins with it there), with the
    /// hook it is none.
    #[test]
    fn tissue_touched_with_another_instrument_than_the_tasks_is_a_mistake() {
        let scenario = crate::scenario::parse(
            std::path::Path::new("t.scenario.ron"),
            r#"Scenario(title: "t", briefing: "b", organs: ["liver"],
                instruments: [
                    Instrument(tool: Probe(tip_radius_mm: 6.0),
                               port: Port(at_mm: (0.0, 120.0, -100.0), shaft_mm: 300.0)),
                    Instrument(tool: Hook(tip_radius_mm: 6.0, power_w: 30.0, mode: Cut),
                               port: Port(at_mm: (0.0, 120.0, -100.0), shaft_mm: 300.0)),
                ],
                tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                                     hold_s: 3.0, time_limit_s: 6.0, instruments: ["hook"])])"#,
        )
        .unwrap();
        let mut exercise = Exercise::new(scenario, Sites::default());
        // (from, to, instrument): on the liver with the probe from the start, then again
        // with it, then with the hook.
        let spells = [(0.0, 0.4, 0), (1.0, 1.5, 0), (2.0, 2.5, 1), (3.0, 3.5, 0)];
        for tick in 0..5000 {
            let time_s = f64::from(tick) * 1e-3;
            let on = spells.iter().find(|&&(a, b, _)| (a..b).contains(&time_s));
            exercise.step(&Sample {
                time_s,
                touching: u64::from(on.is_some()),
                instrument: on.map_or(1, |s| s.2),
                force_n: if on.is_some() { 0.2 } else { 0.0 },
                ..Sample::default()
            });
        }
        let finished = exercise.finish();
        assert_eq!(
            finished.tasks[0].errors,
            [
                "1.00 s: worked on tissue with the probe, not with the task's hook",
                "3.00 s: worked on tissue with the probe, not with the task's hook",
            ]
        );
    }
}
