//! How fast the window draws: every frame's wall-clock duration, kept for the report printed
//! when the window closes (the frame-rate figure of a run, on whatever GPU draws it).

use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use serde::Serialize;

/// Frames this early are start-up (shader compilation, first uploads), not the steady rate.
const WARM_UP_FRAMES: usize = 10;

/// Frame durations (s), shared with the code that opened the window.
#[derive(Resource, Clone, Default)]
pub struct FrameLog(pub Arc<Mutex<Vec<f32>>>);

/// The steady frame rate of a window run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameReport {
    /// Frames drawn after the warm-up.
    pub frames: usize,
    pub frame_ms_p50: f64,
    pub frame_ms_p95: f64,
    pub frame_ms_p99: f64,
    /// Frames per second at the median frame time.
    pub fps_p50: f64,
}

impl FrameLog {
    /// The report over the frames after the warm-up; `None` if there were none.
    pub fn report(&self) -> Option<FrameReport> {
        let mut times: Vec<f32> = self
            .0
            .lock()
            .ok()?
            .iter()
            .skip(WARM_UP_FRAMES)
            .copied()
            .collect();
        if times.is_empty() {
            return None;
        }
        times.sort_by(f32::total_cmp);
        let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize] as f64 * 1e3;
        let p50 = at(0.5);
        Some(FrameReport {
            frames: times.len(),
            frame_ms_p50: p50,
            frame_ms_p95: at(0.95),
            frame_ms_p99: at(0.99),
            fps_p50: 1e3 / p50.max(1e-9),
        })
    }
}

/// Every frame's time, kept in the run's log.
pub(super) struct FramesPlugin(pub FrameLog);

impl Plugin for FramesPlugin {
    fn build(&self, app: &mut App) {
        let log = self.0.clone();
        app.insert_resource(log)
            .add_systems(Update, record.in_set(super::FrameSet::Input));
    }
}

/// Real time, not virtual: virtual time caps a slow frame's step.
fn record(time: Res<Time<Real>>, log: Res<FrameLog>) {
    if let Ok(mut times) = log.0.lock() {
        times.push(time.delta_secs());
    }
}
