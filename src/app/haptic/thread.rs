//! The haptic loop on a thread of its own, paced by absolute deadlines: render frames can
//! neither bunch its ticks nor delay them.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde::Serialize;

use super::report::TickTimes;
use super::resources::TickClock;
use super::runner::HapticLoop;
use super::snapshot::{LoopTiming, TIMING_EVERY_TICKS};
use super::swap::SceneSwap;
use crate::devices::{Histogram, Metronome, TICK_S, TimerMode};

/// How well the thread kept time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RealTimeReport {
    pub timer: TimerMode,
    /// The haptic thread's scheduling: real-time, or why it could not be.
    pub scheduling: String,
    pub ticks: u64,
    /// Deadlines passed by more than a period, skipped rather than run late in a burst.
    pub skipped: u64,
    /// How late each tick started after its deadline.
    pub lateness: TickTimes,
    /// How far each interval between tick starts was from 1 ms.
    pub period_error: TickTimes,
    pub compute: TickTimes,
}

/// How the haptic thread asks the OS to schedule it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Scheduling {
    /// Like any other thread: the baseline.
    Normal,
    /// Real-time (FIFO), above every normal thread, when the OS grants it.
    RealTime,
}

pub struct HapticThread {
    stop: Arc<AtomicBool>,
    swap: SceneSwap,
    handle: JoinHandle<(RealTimeReport, HapticLoop)>,
}

impl HapticThread {
    /// Starts ticking `haptic` every millisecond of real time.
    pub fn spawn(
        haptic: HapticLoop,
        timer: TimerMode,
        scheduling: Scheduling,
    ) -> std::io::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let swap = SceneSwap::default();
        let (flag, swapped) = (stop.clone(), swap.clone());
        let handle = std::thread::Builder::new()
            .name("haptic 1 kHz".into())
            .spawn(move || run(haptic, timer, scheduling, &flag, &swapped))?;
        Ok(Self { stop, swap, handle })
    }

    /// Where to offer the thread another scene.
    pub fn swap(&self) -> SceneSwap {
        self.swap.clone()
    }

    /// Stops the loop after its current tick; says how it kept time, and hands the loop back
    /// (its world holds what the run measured).
    pub fn stop(self) -> (RealTimeReport, HapticLoop) {
        self.stop.store(true, Ordering::Relaxed);
        self.handle
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    }
}

fn run(
    mut haptic: HapticLoop,
    timer: TimerMode,
    scheduling: Scheduling,
    stop: &AtomicBool,
    swap: &SceneSwap,
) -> (RealTimeReport, HapticLoop) {
    let scheduling = match scheduling {
        Scheduling::Normal => "normal".to_owned(),
        Scheduling::RealTime => match raise_priority() {
            Ok(()) => "real-time (FIFO)".to_owned(),
            Err(e) => {
                bevy::log::warn!(
                    "haptic thread: could not get real-time scheduling ({e}); ticks may be \
                     late when the machine is busy"
                );
                format!("normal (real-time refused: {e})")
            }
        },
    };
    let period = Duration::from_secs_f64(TICK_S);
    let mut metronome = Metronome::new(period, timer);
    let (mut lateness, mut period_error, mut compute) = (
        Histogram::default(),
        Histogram::default(),
        Histogram::default(),
    );
    let (mut ticks, mut skipped, mut in_a_row) = (0, 0, 0);
    let mut last_start: Option<Instant> = None;
    while !stop.load(Ordering::Relaxed) {
        let beat = metronome.wait();
        let started = Instant::now();
        if let Some(last) = last_start {
            period_error.record((started - last).abs_diff(period));
        }
        last_start = Some(started);
        lateness.record(beat.lateness);
        skipped += beat.skipped;
        swap.take(&mut haptic);
        let time = haptic.tick(TickClock {
            tick: beat.tick,
            time_s: beat.tick as f64 * TICK_S,
            overruns_in_a_row: in_a_row,
        });
        compute.record(time);
        if beat.tick.is_multiple_of(TIMING_EVERY_TICKS) {
            haptic.world_mut().insert_resource(LoopTiming {
                compute_p99_us: TickTimes::of(&compute).p99_us,
                lateness_p99_us: TickTimes::of(&lateness).p99_us,
                skipped,
            });
        }
        in_a_row = if beat.skipped > 0 || time > period {
            in_a_row + 1
        } else {
            0
        };
        ticks += 1;
    }
    let report = RealTimeReport {
        timer,
        scheduling,
        ticks,
        skipped,
        lateness: TickTimes::of(&lateness),
        period_error: TickTimes::of(&period_error),
        compute: TickTimes::of(&compute),
    };
    (report, haptic)
}

/// Real-time (FIFO) scheduling above every normal thread, the renderer's included, so that a
/// busy machine delays ticks rather than the haptic thread's turn; needs the right to (root or
/// `CAP_SYS_NICE`, or an rtprio limit), and the loop runs without it if refused.
#[cfg(unix)]
fn raise_priority() -> Result<(), String> {
    use thread_priority::unix::{
        RealtimeThreadSchedulePolicy, ThreadSchedulePolicy, set_thread_priority_and_policy,
        thread_native_id,
    };
    use thread_priority::{ThreadPriority, ThreadPriorityValue};
    let priority = ThreadPriorityValue::try_from(70u8).map_err(|e| e.to_string())?;
    set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Crossplatform(priority),
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    )
    .map_err(|e| format!("{e:?}"))
}

#[cfg(not(unix))]
fn raise_priority() -> Result<(), String> {
    thread_priority::set_current_thread_priority(thread_priority::ThreadPriority::Max)
        .map_err(|e| format!("{e:?}"))
}
