//! The worker as a thread of its own, with a pool for the cut state's parallel work. Jobs and
//! answers cross through bounded channels, whose slots are made when the worker starts: the
//! haptic side hands a job over and takes an answer without allocating or waiting.

use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread;

use web_time::Instant;

use super::{Cutter, Job, LatestCut, Outcome};
use crate::cutting::CutError;
use crate::cutting::response::ExactResponse;
use crate::fem::FemModel;

/// Jobs waiting for the worker at most: with a step every 30 ms or more, a worker this far
/// behind has been stalled for seconds.
const JOBS_QUEUED: usize = 256;

/// Answers waiting for the haptic side at most (it takes them every tick; the worker waits
/// for room past that).
const ANSWERS_QUEUED: usize = 64;

pub(super) struct Backend {
    jobs: SyncSender<Job>,
    /// Behind a mutex only so that the worker's handle may be shared between threads (as an
    /// ECS component is): its owner reaches it through `get_mut`, never locking.
    answers: Mutex<Receiver<Outcome>>,
    submitted: u64,
    answered: u64,
    /// Written by the worker, so that the haptic side never grows it.
    step_seconds: Arc<Mutex<Vec<f64>>>,
}

impl Backend {
    /// Starts the thread, named after `name`, that cuts `model`.
    pub(super) fn start(
        model: Arc<FemModel>,
        response: ExactResponse,
        name: &str,
        latest: Arc<LatestCut>,
    ) -> Result<Self, CutError> {
        let (jobs, job_queue) = sync_channel(JOBS_QUEUED);
        let (answers, answered) = sync_channel(ANSWERS_QUEUED);
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
            answers: Mutex::new(answered),
            submitted: 0,
            answered: 0,
            step_seconds,
        })
    }

    /// Hands a job to the thread; never waits. With the queue full (a worker stalled for
    /// seconds) the job is dropped: a step's cut goes on from the next step taken, and a
    /// view to retire is freed here.
    pub(super) fn send(&mut self, job: Job) {
        let answered = !matches!(job, Job::Retire(..));
        match self.jobs.try_send(job) {
            Ok(()) if answered => self.submitted += 1,
            Ok(()) | Err(TrySendError::Disconnected(_) | TrySendError::Full(_)) => {}
        }
    }

    /// An answer the thread has given, if any; never waits.
    pub(super) fn answered(&mut self) -> Option<Outcome> {
        let outcome = self.receiver().try_recv().ok()?;
        self.answered += 1;
        Some(outcome)
    }

    /// The next answer, waiting for it; none once every job handed over is answered.
    pub(super) fn next_answer(&mut self) -> Option<Outcome> {
        if self.answered == self.submitted {
            return None;
        }
        let outcome = self.receiver().recv().ok()?;
        self.answered += 1;
        Some(outcome)
    }

    pub(super) fn pending(&self) -> u64 {
        self.submitted - self.answered
    }

    pub(super) fn step_seconds(&self) -> Vec<f64> {
        self.step_seconds
            .lock()
            .map_or_else(|e| e.into_inner().clone(), |s| s.clone())
    }

    fn receiver(&mut self) -> &Receiver<Outcome> {
        match self.answers.get_mut() {
            Ok(receiver) => receiver,
            Err(poisoned) => poisoned.into_inner(),
        }
    }
}

/// Threads for the cut state's parallel work: one core fewer than the machine has (at least
/// one), so that the haptic thread always finds a core.
fn worker_threads() -> usize {
    let cores = thread::available_parallelism().map_or(1, |n| n.get());
    cores.saturating_sub(1).max(1)
}

/// Where the worker's answers go: to the haptic side, each job's time, and the latest view
/// for the window.
struct Replies<'a> {
    answers: SyncSender<Outcome>,
    timings: &'a Mutex<Vec<f64>>,
    latest: &'a LatestCut,
}

/// The worker's loop: each job done in order and answered, until the haptic side drops its
/// end.
fn serve(model: &FemModel, response: ExactResponse, jobs: Receiver<Job>, replies: Replies) {
    let mut cutter = Cutter::new(model, response);
    for job in jobs {
        let started = Instant::now();
        let outcome;
        (cutter, outcome) = cutter.work(job, replies.latest);
        let Some(outcome) = outcome else {
            continue;
        };
        if let Ok(mut timings) = replies.timings.lock() {
            timings.push(started.elapsed().as_secs_f64());
        }
        if replies.answers.send(outcome).is_err() {
            return;
        }
    }
}
