//! The scenario's tasks inside the haptic tick: every tick, what the trainee does (tip, force
//! sent, organ touched, button) is fed to the running [`Exercise`], so that scoring sees all
//! 1,000 samples a second, in the window as headless.
//!
//! The window starts the exercise when the trainee has read the briefing, and takes it back
//! when it has ended, to score it and show the debrief; both go through an [`ExerciseLink`],
//! which the haptic thread touches without ever waiting or allocating.

use std::mem::take;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use bevy::ecs::query::QueryData;
use bevy::prelude::*;

use super::biliary::Biliary;
use super::cautery::{HookWork, OrganBurns, released_share, ties_torn};
use super::components::{HandTouches, OrganBody, OrganDeformation, OrganIndex, OrganMotion};
use super::cutting::OrganCut;
use super::hand::{DeviceForce, HandIndex, MAX_HANDS, Tool};
use super::resources::{OrganBeds, Scope, TickClock};
use super::snapshot::SnapshotPublisher;
use crate::scenario::{
    BiliarySample, BladeSample, Exercise, HandSample, HookTarget, Progress, RegionSite, Sample,
};

/// What scoring reads of an organ entity.
#[derive(QueryData)]
pub struct ScoredOrgan {
    index: &'static OrganIndex,
    touch: &'static HandTouches,
    body: &'static OrganBody,
    deformation: &'static OrganDeformation,
    motion: Option<&'static OrganMotion>,
    cut: Option<&'static OrganCut>,
}

/// Between the haptic thread and whoever started the exercise: whether it has begun, the
/// exercise once it has ended, and a fresh one for another attempt.
#[derive(Default)]
pub struct ExerciseLink {
    started: AtomicBool,
    ended: Mutex<Option<Exercise>>,
    /// The next attempt's exercise, until the haptic thread takes it.
    next: Mutex<Option<Exercise>>,
    /// The attempts ended before the one under way (the other side's; the haptic thread
    /// never touches it).
    earlier: Mutex<Vec<Exercise>>,
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

    /// Sets up another attempt with `fresh`, to be scored once started again; the ended
    /// attempt is kept with the earlier ones. Refused (false, nothing changed) until the
    /// haptic thread has handed the ended attempt over.
    pub fn retry(&self, fresh: Exercise) -> bool {
        let Some(ended) = self.take_ended() else {
            return false;
        };
        if let Ok(mut earlier) = self.earlier.lock() {
            earlier.push(ended);
        }
        self.started.store(false, Ordering::Release);
        self.offer(fresh);
        true
    }

    /// The exercise the haptic thread takes when started (replacing one offered before and
    /// not yet taken, such as the exercise of a scenario edited on the briefing).
    pub fn offer(&self, exercise: Exercise) {
        if let Ok(mut next) = self.next.lock() {
            *next = Some(exercise);
        }
    }

    /// The attempts ended before the last, in order (once: after that, none).
    pub fn take_earlier(&self) -> Vec<Exercise> {
        self.earlier
            .lock()
            .map(|mut e| take(&mut *e))
            .unwrap_or_default()
    }

    /// The next attempt's exercise into `exercise`, if there is one, without waiting.
    fn take_next(&self, exercise: &mut Option<Exercise>) {
        if let Ok(mut next) = self.next.try_lock()
            && next.is_some()
        {
            *exercise = next.take();
        }
    }
}

/// The exercise under way, when the run is of a scenario: taken from the link when it is
/// started (so that, until then, the other side may replace it and drop the old one: the
/// haptic thread drops no exercise), handed back to it when it has ended.
#[derive(Resource)]
pub struct ExerciseRun {
    pub exercise: Option<Exercise>,
    pub link: Arc<ExerciseLink>,
    /// The attempt taken last has ended and been handed over.
    ended: bool,
    tasks: usize,
    /// Attempts taken so far (the one under way counted).
    attempts: u32,
}

impl ExerciseRun {
    /// A run of the exercises `link` is offered.
    pub fn new(link: Arc<ExerciseLink>) -> Self {
        Self {
            exercise: None,
            link,
            ended: false,
            tasks: 0,
            attempts: 0,
        }
    }

    /// Attempts taken so far, the one under way counted: a retry makes it two.
    pub fn attempts(&self) -> u32 {
        self.attempts
    }

    /// Takes the offered exercise, if there is one (none is offered between an attempt's end
    /// and the next retry).
    fn take_next(&mut self) {
        self.link.take_next(&mut self.exercise);
        if let Some(exercise) = &self.exercise {
            self.tasks = exercise.progress().tasks;
            self.ended = false;
            self.attempts += 1;
        }
    }

    /// The attempt under way or ended last, wherever it is: here, handed over, or (started
    /// but not yet ticked) still offered.
    pub fn into_exercise(mut self) -> Option<Exercise> {
        if self.exercise.is_none() && self.link.started() {
            self.take_next();
        }
        self.exercise.or_else(|| self.link.take_ended())
    }

    /// Where the exercise stands; `None` before it has started.
    pub fn progress(&self) -> Option<Progress> {
        if !self.link.started() {
            return None;
        }
        match &self.exercise {
            Some(exercise) => Some(exercise.progress()),
            None => self.ended.then_some(Progress {
                task: self.tasks,
                tasks: self.tasks,
                task_elapsed_s: 0.0,
                step: None,
            }),
        }
    }
}

pub fn score_tick(
    clock: Res<TickClock>,
    hands: Query<(&HandIndex, &Tool, &DeviceForce, &HookWork)>,
    organs: Query<ScoredOrgan>,
    beds: Option<Res<OrganBeds>>,
    mut run: ResMut<ExerciseRun>,
    mut scope: Option<ResMut<Scope>>,
    biliary: Option<Res<Biliary>>,
) {
    if !run.link.started() {
        return;
    }
    if run.exercise.is_none() {
        run.take_next();
    }
    let Some(exercise) = run.exercise.as_mut() else {
        return;
    };
    let mut samples = [None; MAX_HANDS];
    for (hand, tool, force, _) in &hands {
        samples[hand.0] = Some(hand_sample(hand.0, tool, force, &organs));
    }
    let hook = (hands.iter())
        .map(|(_, _, _, work)| work.0)
        .find(|work| work.on != HookTarget::Off)
        .unwrap_or_default();
    let Some(right) = samples[0] else {
        return;
    };
    let tore = organs.iter().any(|o| o.motion.is_some_and(|m| m.tore));
    let blade = organs.iter().find_map(|o| blade_sample(o.index, o.cut?));
    let (region_moved_m, surrounding_force_n) = exercise
        .watched_region()
        .map_or((0.0, 0.0), |region| watch(region, &organs));
    let beyond_range_m = (organs.iter().flat_map(|o| &o.touch.0))
        .filter_map(|touch| touch.contact.map(|c| c.beyond_range_m))
        .fold(0.0, f64::max);
    let elapsed_s = exercise.elapsed_s(clock.time_s);
    let (tip_in_view, target_in_view) = scope.as_mut().map_or((None, None), |scope| {
        scope.in_view(right.tip_m.as_ref(), elapsed_s)
    });
    let left = samples[1].map(|mut left| {
        left.tip_in_view = scope.as_ref().zip(left.tip_m).map(|(s, tip)| s.sees(&tip));
        left
    });
    exercise.step(&Sample {
        time_s: clock.time_s,
        tip_m: right.tip_m,
        force_n: right.force_n,
        touching: right.touching,
        button: right.button,
        instrument: right.instrument,
        region_moved_m,
        surrounding_force_n,
        grasping: right.grasping,
        tore,
        blade,
        tip_in_view,
        target_in_view,
        beyond_range_m,
        left,
        hook,
        released_share: released_share(beds.as_deref()),
        ties_torn: ties_torn(beds.as_deref()),
        biliary: biliary
            .as_ref()
            .map_or_else(BiliarySample::default, |b| b.sample),
    });
    if let (Some(biliary), Some(record)) = (&biliary, exercise.critical_view_mut()) {
        biliary.keep_judging(record, clock.time_s, beds.as_deref());
    }
    if exercise.finished() {
        let run = &mut *run;
        run.link.hand_over(&mut run.exercise);
        run.ended = run.exercise.is_none();
    }
}

/// Hand `slot`'s tool, force, and the organs it touches and holds (bit `k` for organ `k`);
/// whether its tip is in view is the scope's to say.
fn hand_sample(
    slot: usize,
    tool: &Tool,
    force: &DeviceForce,
    organs: &Query<ScoredOrgan>,
) -> HandSample {
    let bits = |of: &dyn Fn(&ScoredOrganItem) -> bool| {
        (organs.iter())
            .filter(|o| o.index.0 < 64 && of(o))
            .fold(0, |bits, o| bits | 1 << o.index.0)
    };
    let holds = |o: &ScoredOrganItem| {
        o.motion
            .is_some_and(|m| m.organ.holding() && m.hand == slot)
    };
    HandSample {
        tip_m: tool.sample.map(|s| s.tip_m),
        force_n: force.sent_n.norm(),
        touching: bits(&|o| o.touch.0[slot].contact.is_some()),
        grasping: bits(&holds),
        button: tool.sample.is_some_and(|s| s.buttons & 1 != 0),
        instrument: tool.rack.in_hand().0,
        tip_in_view: None,
    }
}

/// How far the region has moved along its direction (m), and the force on every other organ
/// (N): the tools' on it, and what the organs it touches or hangs from put on it.
fn watch(region: &RegionSite, organs: &Query<ScoredOrgan>) -> (f64, f64) {
    let mut moved_m = 0.0;
    let mut surrounding_n = 0.0;
    for organ in organs {
        let deformation = &organ.deformation.0;
        if organ.index.0 == region.organ {
            moved_m = deformation
                .displacement(&organ.body.vademecum, &region.at)
                .dot(&region.towards);
        } else {
            let tools: f64 = deformation.loads.iter().map(|l| l.force_n.norm()).sum();
            surrounding_n += tools + deformation.coupling_force_n.norm();
        }
    }
    (moved_m, surrounding_n)
}

/// The scalpel's cut under way on the organ, if it is cutting: its front, its depth and its
/// stroke.
fn blade_sample(index: &OrganIndex, cut: &OrganCut) -> Option<BladeSample> {
    if !cut.scalpel.cutting() {
        return None;
    }
    let strokes = cut.scalpel.strokes();
    let stroke = strokes.last()?;
    Some(BladeSample {
        organ: index.0,
        front_m: stroke.end_m.into(),
        depth_m: stroke.max_depth_m,
        stroke: strokes.len() as u32,
    })
}

/// Where the exercise stands (none without one), into the snapshot about to be published.
pub fn publish_progress(run: Option<Res<ExerciseRun>>, mut publisher: ResMut<SnapshotPublisher>) {
    publisher.0.input_buffer_mut().exercise = run.and_then(|run| run.progress());
}

/// A new attempt at the exercise starts on uncut tissue: once the run has taken its next
/// attempt, each cut organ's worker undoes its incisions and its scalpel forgets its strokes.
pub fn heal_on_retry(run: Res<ExerciseRun>, mut organs: Query<&mut OrganCut>) {
    let attempts = run.attempts();
    for mut cut in &mut organs {
        if cut.attempt == attempts {
            continue;
        }
        if cut.attempt > 0 {
            cut.scalpel.heal();
            cut.worker.heal();
        }
        cut.attempt = attempts;
    }
}

/// A new attempt starts on whole tissue: once the run has taken its next attempt, the beds
/// are healed, the burns gone and the biliary tree as it was at rest.
pub fn heal_beds_on_retry(
    run: Res<ExerciseRun>,
    mut healed_for: Local<u32>,
    mut beds: Option<ResMut<OrganBeds>>,
    mut burns: Option<ResMut<OrganBurns>>,
    mut biliary: Option<ResMut<Biliary>>,
) {
    let attempts = run.attempts();
    if *healed_for == attempts {
        return;
    }
    if *healed_for > 0 {
        beds.iter_mut()
            .flat_map(|b| b.0.iter_mut())
            .for_each(|bed| bed.heal());
        if let Some(burns) = burns.as_mut() {
            burns.0.clear();
        }
        if let Some(biliary) = biliary.as_mut() {
            biliary.heal();
        }
    }
    *healed_for = attempts;
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use bevy::ecs::system::RunSystemOnce;

    use super::*;
    use crate::scenario::{Sites, parse};

    /// An exercise whose one task ends after 5 ms.
    fn exercise() -> Exercise {
        let text = r#"Scenario(title: "t", briefing: "b", organs: ["liver"],
            tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                                 hold_s: 0.001, time_limit_s: 0.005)])"#;
        let scenario = parse(Path::new("t.scenario.ron"), text).unwrap();
        Exercise::new(scenario, Sites::default())
    }

    /// A haptic world with no organs, scoring what `link` offers.
    fn world(link: &Arc<ExerciseLink>) -> World {
        let mut world = World::new();
        world.insert_resource(TickClock::default());
        world.spawn((
            HandIndex(0),
            Tool::default(),
            DeviceForce::default(),
            HookWork::default(),
        ));
        world.insert_resource(ExerciseRun::new(link.clone()));
        world
    }

    /// Ticks the world's scoring `ticks` times, 1 ms apart, from `tick`.
    fn score(world: &mut World, from: u64, ticks: u64) {
        for tick in from..from + ticks {
            world.resource_mut::<TickClock>().time_s = tick as f64 * 1e-3;
            world.run_system_once(score_tick).unwrap();
        }
    }

    fn progress(world: &World) -> Option<Progress> {
        world.resource::<ExerciseRun>().progress()
    }

    /// Nothing is scored before the start; the attempt runs and is handed over; another
    /// attempt waits for that hand-over (so that the two are never mixed up), is not scored
    /// until started again, then runs from its first task; the first is kept for its report.
    #[test]
    fn attempts_take_turns_between_the_window_and_the_haptic_thread() {
        let link = Arc::new(ExerciseLink::default());
        let mut world = world(&link);
        link.offer(exercise());
        score(&mut world, 0, 3);
        assert_eq!(progress(&world), None, "scored before the start");
        assert!(!link.retry(exercise()), "nothing has ended yet");

        link.start();
        score(&mut world, 3, 2);
        assert_eq!(progress(&world).map(|p| p.task), Some(0));
        score(&mut world, 5, 10);
        assert!(progress(&world).is_some_and(|p| p.finished()));
        assert!(link.ended_copy().is_some(), "handed over");

        assert!(link.retry(exercise()));
        score(&mut world, 15, 3);
        assert_eq!(progress(&world), None, "scored before the second start");
        link.start();
        score(&mut world, 18, 1);
        assert_eq!(progress(&world).map(|p| p.task), Some(0));
        score(&mut world, 19, 10);
        assert!(progress(&world).is_some_and(|p| p.finished()));
        assert_eq!(link.take_earlier().len(), 1);
        assert!(link.take_ended().is_some());
    }

    /// The steps of a stroke 6 mm deep along 16 mm of a 1 cm thick block's top.
    fn stroke() -> [crate::cutting::CutStep; 2] {
        use crate::cutting::CutStep;
        use nalgebra::{Point3, Vector3};
        let top = |x_mm: f64| Point3::new(x_mm, 20.0, 10.0) * 1e-3;
        [
            CutStep::Start {
                at: top(12.0),
                blade: -Vector3::z(),
                depth_m: 6e-3,
            },
            CutStep::Advance { to: top(28.0) },
        ]
    }

    /// A block of liver tissue 4 × 4 × 1 cm clamped underneath, cut by [`stroke`] on its
    /// worker: settled, the cut has enriched unknowns.
    fn cut_block() -> OrganCut {
        use crate::cutting::{Blade, CutWorker, LIVER_TOUGHNESS_J_PER_M2, Scalpel};
        use crate::fem::{Dirichlet, FemModel, Law, Material};
        let mesh = crate::mesh::box_mesh([0.04, 0.04, 0.01], [8, 8, 2]).unwrap();
        let mut dirichlet = Dirichlet::new(mesh.node_count());
        dirichlet.clamp(mesh.node_set("z0").unwrap()).unwrap();
        let model = FemModel::new(mesh, Material::liver(Law::Linear), dirichlet).unwrap();
        let mut worker = CutWorker::spawn(Arc::new(model), "block", Default::default()).unwrap();
        stroke().into_iter().for_each(|step| worker.submit(step));
        assert!(worker.settle().unknowns > 0, "the stroke cut nothing");
        let scalpel = Scalpel::new(Blade::default(), LIVER_TOUGHNESS_J_PER_M2);
        OrganCut::new(scalpel, worker, 0, 1)
    }

    /// The first attempt keeps the tissue as it is; once a retry is started, the cut organs
    /// are whole again (no enriched unknown left) and cut as before by the same stroke.
    #[test]
    fn a_retry_heals_the_cut_organs() {
        let link = Arc::new(ExerciseLink::default());
        let mut world = world(&link);
        let organ = world.spawn(cut_block()).id();
        let tick = |world: &mut World, from: u64, ticks: u64| {
            for t in from..from + ticks {
                world.resource_mut::<TickClock>().time_s = t as f64 * 1e-3;
                world.run_system_once(score_tick).unwrap();
                world.run_system_once(heal_on_retry).unwrap();
            }
        };
        let unknowns = |world: &mut World| {
            let mut cut = world.get_mut::<OrganCut>(organ).unwrap();
            cut.worker.settle().unknowns
        };
        let cut_before = unknowns(&mut world);
        link.offer(exercise());
        link.start();
        tick(&mut world, 0, 15);
        assert_eq!(world.resource::<ExerciseRun>().attempts(), 1);
        assert_eq!(
            unknowns(&mut world),
            cut_before,
            "healed on the first attempt"
        );

        assert!(link.retry(exercise()));
        link.start();
        tick(&mut world, 15, 2);
        assert_eq!(world.resource::<ExerciseRun>().attempts(), 2);
        assert_eq!(unknowns(&mut world), 0, "still cut after the retry");
        assert!(
            world
                .get::<OrganCut>(organ)
                .unwrap()
                .scalpel
                .strokes()
                .is_empty()
        );
        let mut cut = world.get_mut::<OrganCut>(organ).unwrap();
        stroke()
            .into_iter()
            .for_each(|step| cut.worker.submit(step));
        assert_eq!(
            unknowns(&mut world),
            cut_before,
            "the same stroke cuts otherwise"
        );
    }
}
