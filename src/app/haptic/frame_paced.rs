//! The haptic loop where there is no thread for it (a web page's main thread): each frame
//! runs the 1 ms ticks that real time has made due since the last, so the physics keeps its
//! fixed step whatever the frame rate. A frame too late for all of them runs a burst of at
//! most [`MAX_BURST`] and drops the rest: the loop's clock counts the ticks run, so a page
//! too slow for real time runs its exercise slower, whole (a hold still lasts its seconds of
//! ticks, a scripted hand still moves along its script), rather than jumping ahead.

use std::time::Duration;

use super::report::TickTimes;
use super::resources::TickClock;
use super::runner::HapticLoop;
use super::snapshot::{LoopTiming, TIMING_EVERY_TICKS};
use super::swap::SceneSwap;
use crate::devices::{Histogram, TICK_S};

/// The most ticks one frame runs: 100 ms of physics, so a stalled page (a background tab, a
/// scene being loaded) does not freeze the next frame with a backlog.
pub const MAX_BURST: u64 = 100;

/// A haptic loop ticked by the frames.
pub struct FramePaced {
    haptic: HapticLoop,
    swap: SceneSwap,
    /// Ticks run (the loop's clock) and ticks dropped: together, the ticks of real time
    /// accounted for.
    ticks: u64,
    skipped: u64,
    compute: Histogram,
}

impl FramePaced {
    /// Paces `haptic`; another scene offered on `swap` is taken at the start of a tick.
    pub fn new(haptic: HapticLoop, swap: SceneSwap) -> Self {
        Self {
            haptic,
            swap,
            ticks: 0,
            skipped: 0,
            compute: Histogram::default(),
        }
    }

    /// Runs the ticks due after `elapsed` of real time since the first frame (skipping those
    /// beyond `MAX_BURST`); returns how many ran.
    pub fn advance(&mut self, elapsed: Duration) -> u64 {
        let due = (elapsed.as_secs_f64() / TICK_S).floor() as u64;
        let behind = due.saturating_sub(self.ticks + self.skipped);
        let run = behind.min(MAX_BURST);
        self.skipped += behind - run;
        for _ in 0..run {
            let tick = self.ticks;
            self.swap.take(&mut self.haptic);
            let time = self.haptic.tick(TickClock {
                tick,
                time_s: tick as f64 * TICK_S,
                overruns_in_a_row: 0,
            });
            self.compute.record(time);
            self.ticks += 1;
            if self.ticks.is_multiple_of(TIMING_EVERY_TICKS) {
                self.publish_timing();
            }
        }
        run
    }

    /// The loop's timing for the HUD; a frame is late by design, so lateness is not kept.
    fn publish_timing(&mut self) {
        self.haptic.world_mut().insert_resource(LoopTiming {
            compute_p99_us: TickTimes::of(&self.compute).p99_us,
            lateness_p99_us: 0.0,
            skipped: self.skipped,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::haptic::{HapticScene, TickClock as Clock};
    use crate::devices::{DeviceSample, Scripted, Trajectory, TrajectoryRow};
    use nalgebra::Vector3;

    /// A loop over no organ, held still by a scripted hand.
    fn paced() -> FramePaced {
        let rows = vec![TrajectoryRow::new(0.0, &DeviceSample::at(Vector3::zeros()))];
        let device = Box::new(Scripted::new("still", Trajectory { rows }));
        let haptic = HapticLoop::new(&HapticScene::without_organs(), device).unwrap();
        FramePaced::new(haptic, SceneSwap::default())
    }

    fn clock(paced: &FramePaced) -> Clock {
        *paced.haptic.world().resource::<Clock>()
    }

    /// Frames at 60 Hz run the 16 or 17 ticks each is due, none skipped, and the loop's clock
    /// reads real time.
    #[test]
    fn each_frame_runs_the_ticks_real_time_has_made_due() {
        let mut paced = paced();
        let mut ran = Vec::new();
        for frame in 1..=6 {
            ran.push(paced.advance(Duration::from_secs_f64(frame as f64 / 60.0)));
        }
        assert_eq!(ran, [16, 17, 17, 16, 17, 17]);
        assert_eq!((paced.ticks, paced.skipped), (100, 0));
        assert_eq!(clock(&paced).tick, 99);
        assert!((clock(&paced).time_s - 0.099).abs() < 1e-12);
    }

    /// A frame 1.5 s late runs a burst of MAX_BURST ticks and drops the rest; the next frame
    /// is back on time, and the loop's clock has lost the dropped ticks, not jumped them.
    #[test]
    fn a_late_frame_runs_a_bounded_burst_and_drops_the_rest() {
        let mut paced = paced();
        assert_eq!(paced.advance(Duration::from_millis(1500)), MAX_BURST);
        assert_eq!((paced.ticks, paced.skipped), (MAX_BURST, 1500 - MAX_BURST));
        assert_eq!(paced.advance(Duration::from_millis(1510)), 10);
        assert_eq!(clock(&paced).tick, MAX_BURST + 9);
        assert!((clock(&paced).time_s - (MAX_BURST + 9) as f64 * TICK_S).abs() < 1e-12);
        assert_eq!(paced.compute.count(), MAX_BURST + 10);
    }
}
