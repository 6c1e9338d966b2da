//! Built-in scripts: a press-and-slide at each of a list of surface points, and a grasp held
//! at one, for the headless demo, tests and the timing benchmark.

use nalgebra::Vector3;

use super::{Trajectory, TrajectoryRow};
use crate::devices::DeviceSample;

/// Where and how one press goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressTarget {
    /// A point of the surface (m) and its outward unit normal.
    pub point_m: Vector3<f64>,
    pub normal: Vector3<f64>,
}

/// Timing and depth of each press.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressMotion {
    pub tip_radius_m: f64,
    /// How far below the surface the tip's lowest point goes (m).
    pub depth_m: f64,
    /// How far the tip slides along the surface while pressed (m).
    pub slide_m: f64,
    /// Seconds to come down from 1 cm above, to press, to slide, to lift.
    pub approach_s: f64,
    pub press_s: f64,
    pub slide_s: f64,
    pub lift_s: f64,
}

impl Default for PressMotion {
    /// 8 mm deep (well within what a trainee does to a liver), a 2 cm slide at 2 cm/s.
    fn default() -> Self {
        Self {
            tip_radius_m: 6e-3,
            depth_m: 8e-3,
            slide_m: 0.02,
            approach_s: 0.3,
            press_s: 0.5,
            slide_s: 1.0,
            lift_s: 0.3,
        }
    }
}

const CLEARANCE_M: f64 = 0.01;

/// One press after another at `targets`: down along the normal, in, along the surface, out.
pub fn press_and_slide(targets: &[PressTarget], motion: &PressMotion) -> Trajectory {
    let mut rows = Vec::new();
    let mut time_s = 0.0;
    for target in targets {
        let centre = |depth: f64, slide: f64| target.tip_at(motion, depth, slide);
        let keyframes = [
            (0.0, centre(-CLEARANCE_M, 0.0)),
            (motion.approach_s, centre(0.0, 0.0)),
            (motion.press_s, centre(motion.depth_m, 0.0)),
            (motion.slide_s, centre(motion.depth_m, motion.slide_m)),
            (motion.lift_s, centre(-CLEARANCE_M, motion.slide_m)),
        ];
        for (k, (dt, tip)) in keyframes.into_iter().enumerate() {
            // The move from the last press to this one takes as long as an approach.
            let travel_s = if k == 0 && !rows.is_empty() {
                motion.approach_s
            } else {
                0.0
            };
            time_s += dt + travel_s;
            rows.push(TrajectoryRow::new(time_s, &DeviceSample::at(tip)));
        }
    }
    Trajectory { rows }
}

/// How far a held grasp draws the tissue back out along the normal (m): traction.
pub const GRASP_PULL_M: f64 = 0.01;

/// A grasp at `target` held for `hold_s`: down and in as a press, the jaws (button 0) closed
/// at depth, the tissue drawn back out by [`GRASP_PULL_M`] over the slide's time and held
/// there, then let go and lifted.
pub fn grasp_and_hold(target: &PressTarget, motion: &PressMotion, hold_s: f64) -> Trajectory {
    const JAWS_S: f64 = 0.05;
    let centre = |depth: f64| target.tip_at(motion, depth, 0.0);
    let pulled = motion.depth_m - GRASP_PULL_M;
    let keyframes = [
        (0.0, centre(-CLEARANCE_M), false),
        (motion.approach_s, centre(0.0), false),
        (motion.press_s, centre(motion.depth_m), false),
        (JAWS_S, centre(motion.depth_m), true),
        (motion.slide_s, centre(pulled), true),
        (hold_s, centre(pulled), true),
        (JAWS_S, centre(pulled), false),
        (motion.lift_s, centre(-CLEARANCE_M), false),
    ];
    let mut time_s = 0.0;
    let rows = keyframes.map(|(dt, tip, closed)| {
        time_s += dt;
        let sample = DeviceSample {
            buttons: u32::from(closed),
            ..DeviceSample::at(tip)
        };
        TrajectoryRow::new(time_s, &sample)
    });
    Trajectory {
        rows: rows.to_vec(),
    }
}

impl PressTarget {
    /// Where `motion`'s tip is centred with its lowest point `depth_m` below this point of the
    /// surface (negative: above), slid `slide_m` along the surface.
    fn tip_at(&self, motion: &PressMotion, depth_m: f64, slide_m: f64) -> Vector3<f64> {
        let n = self.normal;
        let tangent = n.cross(&helper_axis(&n)).normalize();
        self.point_m + n * (motion.tip_radius_m - depth_m) + tangent * slide_m
    }
}

fn helper_axis(n: &Vector3<f64>) -> Vector3<f64> {
    if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    }
}
