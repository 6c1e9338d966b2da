//! What a bimanual task measures of both hands: each hand's motion (the right- and left-hand
//! path lengths educators judge apart), the time both hands work on tissue together, and how
//! far a hand drifts while it holds nothing and the other works. Fixed-size state: the
//! real-time thread allocates nothing.

use nalgebra::Vector3;
use serde::Serialize;

use super::motion::{MotionMetrics, MotionTracker};
use super::sample::{HandSample, Sample};

/// Both hands over a task.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BimanualMetrics {
    pub right: MotionMetrics,
    pub left: MotionMetrics,
    /// Time with at least one hand on tissue, touching or holding it (s)...
    pub working_s: f64,
    /// ...and with both at once (s).
    pub both_working_s: f64,
    /// How far each hand's tip moved (mm, right then left) while it was off the tissue and
    /// the other hand worked: the idle hand's drift.
    pub idle_drift_mm: [f64; 2],
}

impl BimanualMetrics {
    /// The share of the time on tissue both hands worked together (1 with no time on tissue).
    pub fn together(&self) -> f64 {
        match self.working_s > 0.0 {
            true => self.both_working_s / self.working_s,
            false => 1.0,
        }
    }
}

/// The running measurement.
#[derive(Clone, Debug, Default)]
pub struct BimanualTracker {
    hands: [MotionTracker; 2],
    metrics: BimanualMetrics,
    last_tip: [Option<Vector3<f64>>; 2],
}

impl BimanualTracker {
    /// Takes one tick of `sample`, whose left hand is `left`.
    pub fn step(&mut self, sample: &Sample, left: &HandSample, dt: f64) {
        let hands = [sample.right(), *left];
        let working = hands.map(|h| h.working());
        if working.iter().any(|&w| w) {
            self.metrics.working_s += dt;
        }
        if working.iter().all(|&w| w) {
            self.metrics.both_working_s += dt;
        }
        for (k, hand) in hands.iter().enumerate() {
            let tracker = &mut self.hands[k];
            tracker.in_hand(hand.instrument);
            tracker.step(hand.tip_m, dt);
            if let Some(in_view) = hand.tip_in_view {
                tracker.view(in_view, dt);
            }
            let moved = hand
                .tip_m
                .zip(self.last_tip[k])
                .map(|(a, b)| (a - b).norm());
            if !working[k] && working[1 - k] {
                self.metrics.idle_drift_mm[k] += moved.unwrap_or(0.0) * 1e3;
            }
            self.last_tip[k] = hand.tip_m.or(self.last_tip[k]);
        }
    }

    pub fn metrics(&self) -> BimanualMetrics {
        BimanualMetrics {
            right: self.hands[0].metrics(),
            left: self.hands[1].metrics(),
            ..self.metrics.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two seconds at 1 kHz: the right hand slides 30 mm along x at 15 mm/s on the tissue
    /// the whole time; the left holds the tissue still for the first second, then lets go and
    /// drifts 10 mm along y in the second. Path lengths to 1 µm, the time together to a tick,
    /// the left's drift 10 mm and the right's none (it never stopped working).
    #[test]
    fn both_hands_paths_their_work_together_and_the_idle_drift() {
        let mut tracker = BimanualTracker::default();
        let dt = 1e-3;
        for tick in 0..=2000 {
            let t = tick as f64 * dt;
            let sample = Sample {
                time_s: t,
                tip_m: Some(Vector3::new(0.015 * t, 0.0, 0.0)),
                touching: 1,
                ..Sample::default()
            };
            let left = HandSample {
                tip_m: Some(Vector3::new(-0.05, 0.010 * (t - 1.0).max(0.0), 0.0)),
                grasping: u64::from(t < 1.0),
                ..HandSample::default()
            };
            tracker.step(&sample, &left, if tick == 0 { 0.0 } else { dt });
        }
        let m = tracker.metrics();
        assert!(
            (m.right.path_length_mm - 30.0).abs() < 1e-3,
            "{:?}",
            m.right
        );
        assert!((m.left.path_length_mm - 10.0).abs() < 1e-3, "{:?}", m.left);
        assert!((m.working_s - 2.0).abs() < 1.5e-3, "{m:?}");
        assert!((m.both_working_s - 1.0).abs() < 1.5e-3, "{m:?}");
        assert!((m.together() - 0.5).abs() < 1e-3);
        assert!((m.idle_drift_mm[1] - 10.0).abs() < 1e-3, "{m:?}");
        assert_eq!(m.idle_drift_mm[0], 0.0);
    }
}
