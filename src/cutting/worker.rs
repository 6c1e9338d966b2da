//! The cut state off the haptic thread. Growing the cut over the exact uncut response costs
//! sparse solves (milliseconds to a fraction of a second a segment, `docs/cutting.md`), far
//! over a tick: a worker thread owns the organ's cut state, takes the scalpel's steps in
//! order, and publishes a [`CutView`] after each one that cut. The tick reads the latest view
//! without waiting ([`CutWorker::poll`]); a run on a simulated clock waits for each step
//! ([`CutWorker::settle`]), so that it stays deterministic.

use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread;
use std::time::Instant;

use super::CutError;
use super::enrichment::Front;
use super::response::ExactResponse;
use super::scalpel::CutStep;
use super::state::CutState;
use super::view::CutView;
use crate::fem::FemModel;

/// What the haptic side hands the worker: a step to apply, or a view it no longer reads, to
/// be freed here rather than on the haptic thread (a view holds megabytes).
enum Job {
    Step(CutStep),
    /// Undo every incision (a new attempt at the exercise starts on uncut tissue).
    Heal,
    Retire(Arc<CutView>),
}

/// What the worker answers each step with.
enum Outcome {
    /// The cut grew, or was healed: the state as it now stands.
    Changed(Arc<CutView>),
    /// Nothing to publish (an incision set on the surface has cut nothing yet).
    Unchanged,
    /// The cut state refused the step and stands as it was.
    Refused(CutError),
}

/// The latest view where a reader off the haptic thread (the window) takes it: the worker
/// replaces it after each step that cut, and whoever lets go of an old view last frees it,
/// never the haptic thread, which does not touch this.
#[derive(Debug, Default)]
pub struct LatestCut(Mutex<Arc<CutView>>);

impl LatestCut {
    pub fn get(&self) -> Arc<CutView> {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// Puts `view` in the slot; the view it replaces is let go after the lock is.
    fn set(&self, view: Arc<CutView>) {
        let mut slot = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        let old = std::mem::replace(&mut *slot, view);
        drop(slot);
        drop(old);
    }
}

/// An organ's cut state on a thread of its own, its front snapped to the nearest element
/// faces ([`Front::Nearest`]): on the trainer's meshes, whose elements are as large as an
/// incision is deep, a front snapped inward would leave the cut all but unfelt.
pub struct CutWorker {
    jobs: Sender<Job>,
    /// Behind a mutex only so that the worker's handle may be shared between threads (as an
    /// ECS component is): its owner reaches it through `get_mut`, never locking.
    outcomes: Mutex<Receiver<Outcome>>,
    submitted: u64,
    answered: u64,
    view: Arc<CutView>,
    refused: Vec<CutError>,
    /// How long each job (a step, or a heal) took the worker (s), in order: written by the worker, so that the
    /// haptic side never grows it.
    step_seconds: Arc<Mutex<Vec<f64>>>,
}

impl CutWorker {
    /// Factorizes `model`'s rest stiffness (here, on the caller's thread) and starts the
    /// worker that cuts it; `name` names the thread, and each view is also put in `latest`
    /// for the window.
    pub fn spawn(
        model: Arc<FemModel>,
        name: &str,
        latest: Arc<LatestCut>,
    ) -> Result<Self, CutError> {
        let response = ExactResponse::new(&model).map_err(|e| CutError::Solve(e.to_string()))?;
        let empty = CutState::new(&model, &response).view();
        let (jobs, job_queue) = channel();
        let (answers, outcomes) = channel();
        let step_seconds = Arc::new(Mutex::new(Vec::new()));
        let timings = step_seconds.clone();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(worker_threads())
            .thread_name(|k| format!("cut worker {k}"))
            .build()
            .map_err(|e| CutError::Solve(format!("no threads for the cut state: {e}")))?;
        thread::Builder::new()
            .name(format!("cut {name}"))
            .spawn(move || {
                let replies = Replies {
                    answers,
                    timings: &timings,
                    latest: &latest,
                };
                pool.install(|| serve(&model, response, job_queue, replies))
            })
            .map_err(|e| CutError::Solve(format!("no thread for the cut state: {e}")))?;
        Ok(Self {
            jobs,
            outcomes: Mutex::new(outcomes),
            submitted: 0,
            answered: 0,
            view: Arc::new(empty),
            refused: Vec::new(),
            step_seconds,
        })
    }

    /// Hands the worker a step; never waits.
    pub fn submit(&mut self, step: CutStep) {
        if self.jobs.send(Job::Step(step)).is_ok() {
            self.submitted += 1;
        }
    }

    /// Has the worker undo every incision, after the steps already handed over; never waits.
    /// The view that follows is of the uncut organ.
    pub fn heal(&mut self) {
        if self.jobs.send(Job::Heal).is_ok() {
            self.submitted += 1;
        }
    }

    /// The latest view, taking whatever the worker has answered; never waits.
    pub fn poll(&mut self) -> &Arc<CutView> {
        while let Ok(outcome) = self.receiver().try_recv() {
            self.take(outcome);
        }
        &self.view
    }

    /// The view once every step handed over is answered: waits for the worker.
    pub fn settle(&mut self) -> &Arc<CutView> {
        while self.answered < self.submitted {
            match self.receiver().recv() {
                Ok(outcome) => self.take(outcome),
                Err(_) => break,
            }
        }
        &self.view
    }

    /// The latest view taken (by [`Self::poll`] or [`Self::settle`]).
    pub fn view(&self) -> &Arc<CutView> {
        &self.view
    }

    /// Steps handed over and not yet answered.
    pub fn pending(&self) -> u64 {
        self.submitted - self.answered
    }

    /// The steps the cut state refused, in order.
    pub fn refused(&self) -> &[CutError] {
        &self.refused
    }

    /// How long each step done so far took the worker (s), in order (a copy: not for the
    /// haptic thread).
    pub fn step_seconds(&self) -> Vec<f64> {
        self.step_seconds
            .lock()
            .map_or_else(|e| e.into_inner().clone(), |s| s.clone())
    }

    fn receiver(&mut self) -> &Receiver<Outcome> {
        match self.outcomes.get_mut() {
            Ok(receiver) => receiver,
            Err(poisoned) => poisoned.into_inner(),
        }
    }

    fn take(&mut self, outcome: Outcome) {
        self.answered += 1;
        match outcome {
            Outcome::Changed(view) => {
                let old = std::mem::replace(&mut self.view, view);
                // Dropped by the worker if it is still there; here only if it has gone.
                let _ = self.jobs.send(Job::Retire(old));
            }
            Outcome::Unchanged => {}
            Outcome::Refused(error) => self.refused.push(error),
        }
    }
}

/// Threads for the cut state's parallel work: one core fewer than the machine has (at least
/// one), so that the haptic thread always finds a core.
fn worker_threads() -> usize {
    let cores = thread::available_parallelism().map_or(1, |n| n.get());
    cores.saturating_sub(1).max(1)
}

/// Where the worker's answers go: to the haptic side, each step's time, and the latest view
/// for the window.
struct Replies<'a> {
    answers: Sender<Outcome>,
    timings: &'a Mutex<Vec<f64>>,
    latest: &'a LatestCut,
}

/// The worker's loop: each step applied in order and answered, until the haptic side drops
/// its end.
fn serve(model: &FemModel, response: ExactResponse, jobs: Receiver<Job>, replies: Replies) {
    let mut state = CutState::new(model, response).with_front(Front::Nearest);
    let mut incision = None;
    for job in jobs {
        let started = Instant::now();
        let step = match job {
            Job::Step(step) => step,
            Job::Heal => {
                state = state.heal();
                incision = None;
                let view = Arc::new(state.view());
                replies.latest.set(view.clone());
                if !replies.answer(Outcome::Changed(view), started) {
                    return;
                }
                continue;
            }
            Job::Retire(view) => {
                drop(view);
                continue;
            }
        };
        let applied = match (step, incision) {
            (CutStep::Start { at, blade, depth_m }, _) => {
                incision = Some(state.start(at, blade, depth_m));
                Ok(false)
            }
            (CutStep::Advance { to }, Some(cut)) => state.advance(cut, to).map(|()| true),
            (CutStep::Deepen { depth_m }, Some(cut)) => state.deepen(cut, depth_m).map(|()| true),
            (_, None) => Err(CutError::Degenerate("a step before any incision".into())),
        };
        let outcome = match applied {
            Ok(true) => {
                let view = Arc::new(state.view());
                replies.latest.set(view.clone());
                Outcome::Changed(view)
            }
            Ok(false) => Outcome::Unchanged,
            Err(error) => Outcome::Refused(error),
        };
        if !replies.answer(outcome, started) {
            return;
        }
    }
}

impl Replies<'_> {
    /// Records the job's time and answers it; false once the haptic side has gone.
    fn answer(&self, outcome: Outcome, started: Instant) -> bool {
        if let Ok(mut timings) = self.timings.lock() {
            timings.push(started.elapsed().as_secs_f64());
        }
        self.answers.send(outcome).is_ok()
    }
}
