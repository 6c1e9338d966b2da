//! The worker where there are no threads (a web page): each job is done where it is handed
//! over, and its answer kept until it is taken.

use std::collections::VecDeque;
use std::sync::Arc;

use web_time::Instant;

use super::{Cutter, Job, LatestCut, Outcome};
use crate::cutting::CutError;
use crate::cutting::response::ExactResponse;
use crate::fem::FemModel;

pub(super) struct Backend {
    /// Taken out only while a job is done (a heal replaces it).
    cutter: Option<Cutter<Arc<FemModel>>>,
    latest: Arc<LatestCut>,
    answers: VecDeque<Outcome>,
    step_seconds: Vec<f64>,
}

impl Backend {
    pub(super) fn start(
        model: Arc<FemModel>,
        response: ExactResponse,
        _name: &str,
        latest: Arc<LatestCut>,
    ) -> Result<Self, CutError> {
        Ok(Self {
            cutter: Some(Cutter::new(model, response)),
            latest,
            answers: VecDeque::new(),
            step_seconds: Vec::new(),
        })
    }

    /// Does the job now.
    pub(super) fn send(&mut self, job: Job) {
        let Some(cutter) = self.cutter.take() else {
            return;
        };
        let started = Instant::now();
        let (cutter, outcome) = cutter.work(job, &self.latest);
        self.cutter = Some(cutter);
        if let Some(outcome) = outcome {
            self.step_seconds.push(started.elapsed().as_secs_f64());
            self.answers.push_back(outcome);
        }
    }

    pub(super) fn answered(&mut self) -> Option<Outcome> {
        self.answers.pop_front()
    }

    pub(super) fn next_answer(&mut self) -> Option<Outcome> {
        self.answers.pop_front()
    }

    pub(super) fn pending(&self) -> u64 {
        self.answers.len() as u64
    }

    pub(super) fn step_seconds(&self) -> Vec<f64> {
        self.step_seconds.clone()
    }
}
