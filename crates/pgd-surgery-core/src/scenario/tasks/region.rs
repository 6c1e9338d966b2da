//! What retraction and grasp share: a region of an organ moved along a direction and held
//! there, its checks and its measures.

use serde::Serialize;

use crate::scenario::task::{Hold, TaskCheck, TaskProgress, TaskShared, Watched};

use super::force_control::held;

/// The region nearest `at_mm` on the task's organ, to be moved along `towards`.
pub(super) fn watched(
    shared: &TaskShared,
    at_mm: (f64, f64, f64),
    towards: (f64, f64, f64),
) -> Option<Watched<'_>> {
    Some(Watched {
        organ: shared.organ.as_deref()?,
        at_mm,
        towards,
    })
}

/// The direction to move the region in must have a length.
pub(super) fn check_towards(check: &mut TaskCheck<'_>, (x, y, z): (f64, f64, f64)) {
    if !(x * x + y * y + z * z).is_normal() {
        check.problem(
            "towards",
            "the direction to move the region in has no length",
            "give a direction such as (0.0, 0.0, 1.0) (towards the head)",
        );
    }
}

/// The region's move as it runs: the farthest it went and the hold there.
#[derive(Clone, Debug, Default)]
pub(super) struct RegionMove {
    pub move_mm: f64,
    pub hold_s: f64,
    pub moved_mm: Option<f64>,
    pub hold: Hold,
}

impl RegionMove {
    pub fn new(move_mm: f64, hold_s: f64) -> Self {
        Self {
            move_mm,
            hold_s,
            ..Self::default()
        }
    }

    /// Takes how far the region has moved this tick (m); returns it in mm.
    pub fn moved(&mut self, moved_m: f64) -> f64 {
        let moved_mm = moved_m * 1e3;
        self.moved_mm = Some(self.moved_mm.map_or(moved_mm, |most| most.max(moved_mm)));
        moved_mm
    }

    /// Takes whether the hold holds at `time_s`; true once it has held long enough.
    pub fn hold(&mut self, holding: bool, time_s: f64) -> bool {
        // Stepped whatever `holding` is: a break must end the hold under way.
        let longest_s = self.hold.step(holding, time_s);
        holding && longest_s >= self.hold_s
    }

    pub fn progress(&self) -> TaskProgress {
        match self.moved_mm.unwrap_or(0.0) < self.move_mm {
            true => TaskProgress {
                what: "moved",
                done: self.moved_mm.unwrap_or(0.0).max(0.0),
                of: self.move_mm,
                unit: "mm",
            },
            false => TaskProgress {
                what: "held",
                done: self.hold.longest_s,
                of: self.hold_s,
                unit: "s",
            },
        }
    }

    pub fn result(&self) -> RegionResult {
        RegionResult {
            moved_mm: self.moved_mm,
            move_target_mm: self.move_mm,
            hold_s: self.hold_s,
            longest_hold_s: self.hold.longest_s,
        }
    }
}

/// The farthest the region moved along its direction (mm), of how far, and the hold asked
/// and the longest.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RegionResult {
    pub moved_mm: Option<f64>,
    pub move_target_mm: f64,
    pub hold_s: f64,
    pub longest_hold_s: f64,
}

impl RegionResult {
    /// " (moved at most 12 of 20 mm)" while short of the distance, else the hold's.
    pub(super) fn unfinished(&self) -> String {
        match self.moved_mm {
            Some(moved) if moved < self.move_target_mm => format!(
                " (moved at most {moved:.0} of {:.0} mm)",
                self.move_target_mm
            ),
            _ => held(self.longest_hold_s, self.hold_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two holds of 0.6 s with a break between do not make a hold of 1 s; one unbroken does.
    #[test]
    fn a_break_ends_the_hold() {
        let mut region = RegionMove::new(20.0, 1.0);
        let held = |region: &mut RegionMove, from_s: f64, to_s: f64| {
            (0..=6).any(|k| region.hold(true, from_s + (to_s - from_s) * f64::from(k) / 6.0))
        };
        assert!(!held(&mut region, 0.0, 0.6));
        assert!(!region.hold(false, 0.7));
        assert!(!held(&mut region, 0.8, 1.4));
        assert!((region.hold.longest_s - 0.6).abs() < 1e-12);
        assert!(held(&mut region, 1.5, 2.5));
    }
}
