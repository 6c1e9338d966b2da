//! The cut state off the haptic tick. Growing the cut over the exact uncut response costs
//! sparse solves (milliseconds to a fraction of a second a segment, `docs/cutting.md`), far
//! over a tick: a worker owns the organ's cut state, takes the scalpel's steps in order, and
//! publishes a [`CutView`] after each one that cut. The tick reads the latest view without
//! waiting ([`CutWorker::poll`]); a run on a simulated clock waits for each step
//! ([`CutWorker::settle`]), so that it stays deterministic.
//!
//! Where there are threads the worker is a thread of its own ([`threaded`]); in a web page,
//! which has none, each step is applied where it is handed over ([`inline`]), and the frame
//! that hands it over takes the step's time.

#[cfg(target_arch = "wasm32")]
mod inline;
#[cfg(not(target_arch = "wasm32"))]
mod threaded;

use std::borrow::Borrow;
use std::sync::{Arc, Mutex, PoisonError};

use nalgebra::Vector3;

#[cfg(target_arch = "wasm32")]
use inline::Backend;
#[cfg(not(target_arch = "wasm32"))]
use threaded::Backend;

use super::CutError;
use super::enrichment::Front;
use super::response::ExactResponse;
use super::scalpel::CutStep;
use super::state::CutState;
use super::view::{CutScratch, CutView, PatchCut};
use crate::fem::FemModel;

/// What the haptic side hands the worker: a step to apply, or a view it no longer reads with
/// its scratch, to be freed by the worker rather than on the haptic thread (a view holds
/// megabytes).
enum Job {
    Step(CutStep),
    /// Undo every incision (a new attempt at the exercise starts on uncut tissue).
    Heal,
    Retire(Arc<CutView>, CutScratch),
}

/// What the worker answers a step or a heal with.
enum Outcome {
    /// The cut grew, or was healed: the state as it now stands, and its scratch.
    Changed(Arc<CutView>, CutScratch),
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

/// The organ's cut state as the worker keeps it, its front snapped to the nearest element
/// faces ([`Front::Nearest`]): on the trainer's meshes, whose elements are as large as an
/// incision is deep, a front snapped inward would leave the cut all but unfelt. `M` is how
/// it holds the organ's model (borrowed on a thread that owns it, owned otherwise).
struct Cutter<M: Borrow<FemModel>> {
    state: CutState<M, ExactResponse>,
    /// The incision under way.
    incision: Option<usize>,
}

impl<M: Borrow<FemModel>> Cutter<M> {
    fn new(model: M, response: ExactResponse) -> Self {
        Self {
            state: CutState::new(model, response).with_front(Front::Nearest),
            incision: None,
        }
    }

    /// Does `job`, publishing each changed view in `latest` too; what to answer, if anything.
    fn work(self, job: Job, latest: &LatestCut) -> (Self, Option<Outcome>) {
        let mut cutter = self;
        let applied = match job {
            Job::Step(step) => cutter.step(step),
            Job::Heal => {
                cutter = Self {
                    state: cutter.state.heal(),
                    incision: None,
                };
                Ok(true)
            }
            Job::Retire(view, scratch) => {
                drop((view, scratch));
                return (cutter, None);
            }
        };
        let outcome = match applied {
            Ok(true) => {
                let view = Arc::new(cutter.state.view());
                latest.set(view.clone());
                let scratch = CutScratch::with_room(view.unknowns);
                Outcome::Changed(view, scratch)
            }
            Ok(false) => Outcome::Unchanged,
            Err(error) => Outcome::Refused(error),
        };
        (cutter, Some(outcome))
    }

    /// Applies a scalpel's step: whether the cut grew.
    fn step(&mut self, step: CutStep) -> Result<bool, CutError> {
        let state = &mut self.state;
        match (step, self.incision) {
            (CutStep::Start { at, blade, depth_m }, _) => {
                self.incision = Some(state.start(at, blade, depth_m));
                Ok(false)
            }
            (CutStep::Advance { to }, Some(cut)) => state.advance(cut, to).map(|()| true),
            (CutStep::Deepen { depth_m }, Some(cut)) => state.deepen(cut, depth_m).map(|()| true),
            (_, None) => Err(CutError::Degenerate("a step before any incision".into())),
        }
    }
}

/// How many refusals a worker keeps; past that they are counted.
const REFUSALS_KEPT: usize = 32;

/// An organ's cut state on its worker.
pub struct CutWorker {
    backend: Backend,
    view: Arc<CutView>,
    /// Scratch for the latest view's answers, made with it by the worker.
    scratch: CutScratch,
    /// The first [`REFUSALS_KEPT`] refusals (later ones are not kept: the list never grows
    /// on the haptic thread).
    refused: Vec<CutError>,
}

impl CutWorker {
    /// Factorizes `model`'s rest stiffness (here, on the caller's thread) and starts the
    /// worker that cuts it; `name` names the worker's thread, and each view is also put in
    /// `latest` for the window.
    pub fn spawn(
        model: Arc<FemModel>,
        name: &str,
        latest: Arc<LatestCut>,
    ) -> Result<Self, CutError> {
        let response = ExactResponse::new(&model).map_err(|e| CutError::Solve(e.to_string()))?;
        let empty = CutState::new(model.as_ref(), &response).view();
        Ok(Self {
            backend: Backend::start(model, response, name, latest)?,
            view: Arc::new(empty),
            scratch: CutScratch::default(),
            refused: Vec::with_capacity(REFUSALS_KEPT),
        })
    }

    /// Hands the worker a step.
    pub fn submit(&mut self, step: CutStep) {
        self.backend.send(Job::Step(step));
    }

    /// Has the worker undo every incision, after the steps already handed over. The view
    /// that follows is of the uncut organ.
    pub fn heal(&mut self) {
        self.backend.send(Job::Heal);
    }

    /// The latest view, taking whatever the worker has answered; never waits.
    pub fn poll(&mut self) -> &Arc<CutView> {
        while let Some(outcome) = self.backend.answered() {
            self.take(outcome);
        }
        &self.view
    }

    /// The view once every step handed over is answered: waits for the worker.
    pub fn settle(&mut self) -> &Arc<CutView> {
        while let Some(outcome) = self.backend.next_answer() {
            self.take(outcome);
        }
        &self.view
    }

    /// The latest view taken (by [`Self::poll`] or [`Self::settle`]).
    pub fn view(&self) -> &Arc<CutView> {
        &self.view
    }

    /// Starts summing the organ's loads for [`Self::patch_response`]: none yet.
    pub fn clear_loads(&mut self) {
        self.view.clear_loads(&mut self.scratch);
    }

    /// Adds `force_n` (N) on the patch `patch` (mesh nodes and their shares) to the organ's
    /// loads.
    pub fn add_load(&mut self, patch: &[(usize, f64)], force_n: &Vector3<f64>) {
        self.view.add_load(patch, force_n, &mut self.scratch);
    }

    /// What the cut adds at the patch `patch` in the latest view taken: to its compliance, and
    /// to its displacement under the loads added since [`Self::clear_loads`]. Allocates
    /// nothing.
    pub fn patch_response(&mut self, patch: &[(usize, f64)]) -> PatchCut {
        self.view.patch_response(patch, &mut self.scratch)
    }

    /// Steps handed over and not yet answered.
    pub fn pending(&self) -> u64 {
        self.backend.pending()
    }

    /// The steps the cut state refused, in order (the first [`REFUSALS_KEPT`]).
    pub fn refused(&self) -> &[CutError] {
        &self.refused
    }

    /// How long each job done so far (a step, or a heal) took the worker (s), in order (a
    /// copy: not for the haptic thread).
    pub fn step_seconds(&self) -> Vec<f64> {
        self.backend.step_seconds()
    }

    fn take(&mut self, outcome: Outcome) {
        match outcome {
            Outcome::Changed(view, scratch) => {
                let old = std::mem::replace(&mut self.view, view);
                let old_scratch = std::mem::replace(&mut self.scratch, scratch);
                self.backend.send(Job::Retire(old, old_scratch));
            }
            Outcome::Unchanged => {}
            Outcome::Refused(error) if self.refused.len() < REFUSALS_KEPT => {
                self.refused.push(error);
            }
            Outcome::Refused(_) => {}
        }
    }
}
