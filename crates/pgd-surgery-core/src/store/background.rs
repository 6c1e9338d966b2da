//! Vademecums built on a thread of their own, at the lowest priority, while the trainer runs
//! on others: the window opens at once on a first run, on the organs' linear vademecums, and
//! an organ's tissue turns nonlinear in the first scene loaded after its nonlinear vademecum
//! is saved (the window loads its scene again at the next briefing). One build at a time, in
//! the order asked, each file once per run.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::{Condvar, Mutex, OnceLock};
use std::time::Instant;

use super::OnStale;
use super::vademecums::{VademecumSpec, ensure_with};
use crate::pgd::Progress;

/// What the background builder is doing, for the window to show.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BackgroundStatus {
    /// The organ being built, with its law's name, the build's stage and its share done.
    pub building: Option<Building>,
    /// The organs waiting, in order.
    pub queued: Vec<String>,
    /// The organs whose build failed, with why.
    pub failed: Vec<(String, String)>,
    /// The files built (or found good) so far, in order: a scene running an organ's linear
    /// tissue meanwhile is loaded again once its file is among them.
    pub built: Vec<PathBuf>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Building {
    pub organ: String,
    pub law: &'static str,
    pub stage: String,
    pub done: u64,
    pub total: u64,
}

impl Building {
    /// `spec`'s build, not yet begun.
    fn of(spec: &VademecumSpec) -> Self {
        Self {
            organ: spec.name.clone(),
            law: spec.law.name(),
            stage: "starting".into(),
            done: 0,
            total: 0,
        }
    }
}

impl BackgroundStatus {
    /// Nothing building or waiting.
    pub fn is_idle(&self) -> bool {
        self.building.is_none() && self.queued.is_empty()
    }
}

/// Queues `spec`'s vademecum to be built (or loaded, if it is already good) in the
/// background, unless this run has already queued its file.
pub fn build_in_background(spec: VademecumSpec) {
    let builder = builder();
    let mut state = builder
        .state
        .lock()
        .expect("the builder never panics holding it");
    if state.asked.contains(&spec.file) {
        return;
    }
    state.asked.push(spec.file.clone());
    state.status.queued.push(spec.name.clone());
    state.queue.push_back(spec);
    builder.wake.notify_one();
}

/// What the background builder is doing now.
pub fn background_status() -> BackgroundStatus {
    builder()
        .state
        .lock()
        .expect("the builder never panics holding it")
        .status
        .clone()
}

#[derive(Default)]
struct State {
    queue: VecDeque<VademecumSpec>,
    /// Every file queued in this run, built or not.
    asked: Vec<PathBuf>,
    status: BackgroundStatus,
}

struct Builder {
    state: Mutex<State>,
    wake: Condvar,
}

/// The one builder, its thread started on first use.
fn builder() -> &'static Builder {
    static BUILDER: OnceLock<Builder> = OnceLock::new();
    static STARTED: OnceLock<()> = OnceLock::new();
    let builder = BUILDER.get_or_init(|| Builder {
        state: Mutex::new(State::default()),
        wake: Condvar::new(),
    });
    STARTED.get_or_init(|| {
        std::thread::Builder::new()
            .name("vademecum builder".into())
            .spawn(move || work(builder))
            .expect("a thread can be spawned");
    });
    builder
}

/// Builds what is queued, one at a time, on a thread pool of its own whose threads yield to
/// every other thread of the machine (the haptic loop, the renderer).
fn work(builder: &'static Builder) {
    lowest_priority();
    let pool = rayon::ThreadPoolBuilder::new()
        .thread_name(|k| format!("vademecum builder {k}"))
        .start_handler(|_| lowest_priority())
        .build();
    let pool = match pool {
        Ok(pool) => pool,
        Err(e) => return fail_all(builder, &format!("no thread pool: {e}")),
    };
    loop {
        let spec = next(builder);
        let progress = Shared(builder);
        let started = Instant::now();
        let built = pool.install(|| ensure_with(&spec, OnStale::Rebuild, &progress));
        let mut state = builder
            .state
            .lock()
            .expect("the builder never panics holding it");
        state.status.building = None;
        match built {
            Ok(_) => {
                eprintln!(
                    "{}: its {} vademecum is built ({:.0} s, in the background): the next \
                     briefing uses it",
                    spec.name,
                    spec.law.name(),
                    started.elapsed().as_secs_f64()
                );
                state.status.built.push(spec.file.clone());
            }
            Err(why) => {
                eprintln!("{}: the background build failed: {why}", spec.name);
                state.status.failed.push((spec.name.clone(), why));
            }
        }
    }
}

/// Waits for the next spec queued and marks it as being built.
fn next(builder: &Builder) -> VademecumSpec {
    let mut state = builder
        .state
        .lock()
        .expect("the builder never panics holding it");
    loop {
        if let Some(spec) = state.queue.pop_front() {
            state.status.queued.remove(0);
            state.status.building = Some(Building::of(&spec));
            return spec;
        }
        state = builder
            .wake
            .wait(state)
            .expect("the builder never panics holding it");
    }
}

fn fail_all(builder: &Builder, why: &str) {
    let mut state = builder
        .state
        .lock()
        .expect("the builder never panics holding it");
    let names: Vec<String> = state.queue.drain(..).map(|spec| spec.name).collect();
    state.status.queued.clear();
    for name in names {
        state.status.failed.push((name, why.to_owned()));
    }
}

/// The calling thread at the lowest priority of the normal policy (nice 19): best effort, a
/// build that cannot lower itself still builds.
fn lowest_priority() {
    let _ = thread_priority::set_current_thread_priority(thread_priority::ThreadPriority::Min);
}

/// A build's progress, written into the build under way, where [`background_status`] reads
/// it.
struct Shared(&'static Builder);

impl Shared {
    fn update(&self, change: impl FnOnce(&mut Building)) {
        let mut state = self
            .0
            .state
            .lock()
            .expect("the builder never panics holding it");
        if let Some(building) = state.status.building.as_mut() {
            change(building);
        }
    }
}

impl Progress for Shared {
    fn start(&self, stage: &str, total: u64) {
        self.update(|b| {
            b.stage = stage.to_owned();
            (b.done, b.total) = (0, total);
        });
    }

    fn advance(&self, amount: u64) {
        self.update(|b| b.done += amount);
    }

    fn message(&self, _: &str) {}
}
