//! What an incision task measures of the cut: how much of the marked line it covers, how far
//! from the line it strays, how deep it goes, and in how many strokes.

use nalgebra::Vector3;
use serde::Serialize;

/// The cut under way this tick, as the scalpel reports it: where its front is (m), how deep
/// it cuts (m), on which organ (the scenario's `organs[k]`) and in which stroke (counted from
/// one on that organ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BladeSample {
    pub organ: usize,
    pub front_m: Vector3<f64>,
    pub depth_m: f64,
    pub stroke: u32,
}

/// The incision task's measures.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct IncisionMetrics {
    /// The marked line's ends (mm, the scene's frame), for the debrief to draw the cut over.
    pub from_mm: [f64; 3],
    pub to_mm: [f64; 3],
    pub line_length_mm: f64,
    /// How much of the line the cut covers, within the tolerance of it (mm).
    pub covered_mm: f64,
    /// How far the cut's front strayed from the line: on average over its advance, and at
    /// most (mm).
    pub mean_deviation_mm: f64,
    pub max_deviation_mm: f64,
    pub tolerance_mm: f64,
    /// The cut's depth, averaged over its advance, and the deepest (mm), against the target.
    pub mean_depth_mm: f64,
    pub max_depth_mm: f64,
    pub target_depth_mm: f64,
    /// Strokes that cut this organ during the task.
    pub strokes: u32,
}

/// The line is covered in bins of this length (m).
const BIN_M: f64 = 0.0005;

/// Follows the cut against the marked line.
#[derive(Clone, Debug)]
pub struct IncisionTracker {
    organ: Option<usize>,
    from_m: Vector3<f64>,
    along: Vector3<f64>,
    length_m: f64,
    tolerance_m: f64,
    target_depth_m: f64,
    covered: Vec<bool>,
    /// How many of `covered` are.
    covered_bins: usize,
    /// The last front seen, and its stroke.
    last: Option<(u32, Vector3<f64>)>,
    advance_m: f64,
    deviation_sum: f64,
    depth_sum: f64,
    max_deviation_m: f64,
    max_depth_m: f64,
    strokes: u32,
}

impl IncisionTracker {
    /// The line from `from_m` to `to_m` on the scenario's `organ`-th organ (`None`: not in
    /// the scene, nothing is counted), cut within `tolerance_m` of it, `target_depth_m` deep.
    pub fn new(
        organ: Option<usize>,
        from_m: Vector3<f64>,
        to_m: Vector3<f64>,
        tolerance_m: f64,
        target_depth_m: f64,
    ) -> Self {
        let line = to_m - from_m;
        let length_m = line.norm();
        Self {
            organ,
            from_m,
            along: line / length_m.max(f64::MIN_POSITIVE),
            length_m,
            tolerance_m,
            target_depth_m,
            covered: vec![false; (length_m / BIN_M).ceil().max(1.0) as usize],
            covered_bins: 0,
            last: None,
            advance_m: 0.0,
            deviation_sum: 0.0,
            depth_sum: 0.0,
            max_deviation_m: 0.0,
            max_depth_m: 0.0,
            strokes: 0,
        }
    }

    /// The tick's cut, if one is under way: a front that moved on adds its advance.
    pub fn step(&mut self, blade: Option<&BladeSample>) {
        let Some(blade) = blade.filter(|b| Some(b.organ) == self.organ) else {
            return;
        };
        let front = blade.front_m;
        self.max_depth_m = self.max_depth_m.max(blade.depth_m);
        let from = match self.last {
            Some((stroke, last)) if stroke == blade.stroke => last,
            _ => {
                self.strokes += 1;
                self.last = Some((blade.stroke, front));
                return;
            }
        };
        let step_m = (front - from).norm();
        if step_m == 0.0 {
            return;
        }
        let deviation_m = self.distance_m(&front);
        self.advance_m += step_m;
        self.deviation_sum += deviation_m * step_m;
        self.depth_sum += blade.depth_m * step_m;
        self.max_deviation_m = self.max_deviation_m.max(deviation_m);
        self.cover(&from, &front);
        self.last = Some((blade.stroke, front));
    }

    /// The share of the line covered.
    pub fn covered_share(&self) -> f64 {
        self.covered_bins as f64 / self.covered.len() as f64
    }

    /// How far off the line (m) the front strays before it counts as an error: twice the
    /// tolerance.
    pub fn stray_limit_m(&self) -> f64 {
        2.0 * self.tolerance_m
    }

    /// Whether the front has ever strayed beyond [`Self::stray_limit_m`].
    pub fn strayed(&self) -> bool {
        self.max_deviation_m > self.stray_limit_m()
    }

    pub fn metrics(&self) -> IncisionMetrics {
        let mean = |sum: f64| match self.advance_m > 0.0 {
            true => sum / self.advance_m * 1e3,
            false => 0.0,
        };
        IncisionMetrics {
            line_length_mm: self.length_m * 1e3,
            covered_mm: self.covered_share() * self.length_m * 1e3,
            mean_deviation_mm: mean(self.deviation_sum),
            max_deviation_mm: self.max_deviation_m * 1e3,
            tolerance_mm: self.tolerance_m * 1e3,
            mean_depth_mm: mean(self.depth_sum),
            max_depth_mm: self.max_depth_m * 1e3,
            target_depth_mm: self.target_depth_m * 1e3,
            strokes: self.strokes,
            from_mm: (self.from_m * 1e3).into(),
            to_mm: ((self.from_m + self.along * self.length_m) * 1e3).into(),
        }
    }

    /// The distance (m) of `p` from the marked segment.
    fn distance_m(&self, p: &Vector3<f64>) -> f64 {
        let t = (p - self.from_m).dot(&self.along).clamp(0.0, self.length_m);
        (p - (self.from_m + self.along * t)).norm()
    }

    /// Marks the bins of the line the cut from `a` to `b` passes within the tolerance of.
    fn cover(&mut self, a: &Vector3<f64>, b: &Vector3<f64>) {
        let samples = ((b - a).norm() / (0.5 * BIN_M)).ceil() as usize + 1;
        for k in 0..=samples {
            let p = a + (b - a) * (k as f64 / samples as f64);
            let t = (p - self.from_m).dot(&self.along);
            if !(0.0..=self.length_m).contains(&t) || self.distance_m(&p) > self.tolerance_m {
                continue;
            }
            let bin = ((t / BIN_M) as usize).min(self.covered.len() - 1);
            if !self.covered[bin] {
                self.covered[bin] = true;
                self.covered_bins += 1;
            }
        }
    }
}
