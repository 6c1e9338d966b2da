//! What a radial keratotomy task measures: each stroke of the blade on the cornea taken as a
//! radial incision (its angle round the cornea's axis, where it starts and ends off the axis,
//! how deep), their symmetry, the optical zone kept clear, a perforation, and the correction
//! the cut cornea is predicted to give.

use std::f64::consts::TAU;
use std::fmt;
use std::sync::{Arc, Mutex};

use nalgebra::Vector3;
use serde::Serialize;

use super::incision::BladeSample;
use crate::cutting::keratotomy::{Cornea, azimuth_incision};
use crate::cutting::{CutError, CutFace, Front};
use crate::mesh::organs::CORNEA_THICKNESS_M;

/// A stroke reaching less far than this across the cornea (m) is a nick, not an incision.
pub const MIN_INCISION_M: f64 = 0.5e-3;

/// One incision as made: where it lies round the axis and off it, and how deep it went.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RadialIncision {
    /// Round the cornea's axis, from the scene's +x towards +y (degrees, 0–360).
    pub angle_deg: f64,
    /// The nearest and farthest the cut came to and went from the axis (mm).
    pub from_mm: f64,
    pub to_mm: f64,
    /// The deepest the blade cut, as a share of the cornea's thickness.
    pub depth_fraction: f64,
}

/// The keratotomy task's measures.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct KeratotomyMetrics {
    pub planned: usize,
    pub optical_zone_mm: f64,
    pub target_depth_fraction: f64,
    pub target_correction_d: f64,
    pub correction_tolerance_d: f64,
    pub incisions: Vec<RadialIncision>,
    /// The most the angle between neighbouring incisions departs from an even spacing of
    /// those made (degrees).
    pub spacing_error_deg: f64,
    /// How far into the optical zone an incision reached (mm; 0 when none did).
    pub zone_intrusion_mm: f64,
    /// The incisions' depths, averaged, as a share of the thickness.
    pub mean_depth_fraction: f64,
    /// Whether a cut went through the whole thickness.
    pub perforated: bool,
    /// The fall of the central corneal power (D) the incisions are predicted to give: the
    /// cut cornea under the intraocular pressure, solved by full X-FEM when the task is
    /// scored (on the reference cornea, as `pgd cut cornea` solves it). `None` before, or
    /// when it cannot be solved.
    pub predicted_correction_d: Option<f64>,
}

impl KeratotomyMetrics {
    /// The incisions as faces of the cornea: meridians at their angles, over their reach,
    /// as deep as they went (a perforating one through the whole thickness).
    pub fn faces(&self) -> Result<Vec<CutFace>, CutError> {
        self.incisions
            .iter()
            .map(|cut| {
                let reach = (cut.from_mm * 1e-3, cut.to_mm * 1e-3);
                let depth = cut.depth_fraction.min(1.0);
                azimuth_incision(cut.angle_deg.to_radians(), reach, depth)
            })
            .collect()
    }
}

/// The stroke under way: the sum of its front's directions round the axis, and its reach
/// and depth so far.
#[derive(Clone, Debug)]
struct Stroke {
    number: u32,
    azimuth: Vector3<f64>,
    from_m: f64,
    to_m: f64,
    depth_m: f64,
}

/// Follows the strokes on the cornea as incisions.
#[derive(Clone, Debug)]
pub struct KeratotomyTracker {
    organ: Option<usize>,
    metrics: KeratotomyMetrics,
    stroke: Option<Stroke>,
}

/// The plan a keratotomy task asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeratotomyPlan {
    pub incisions: usize,
    pub optical_zone_m: f64,
    pub depth_fraction: f64,
    pub target_correction_d: f64,
    pub correction_tolerance_d: f64,
}

impl KeratotomyTracker {
    /// The `plan` on the scenario's `organ`-th organ, a generated cornea in its own frame
    /// (`None`: not in the scene, nothing is counted). Room is made for four times the
    /// plan's incisions up front, so that the haptic thread, which steps it, allocates
    /// nothing as incisions are made.
    pub fn new(organ: Option<usize>, plan: KeratotomyPlan) -> Self {
        Self {
            organ,
            metrics: KeratotomyMetrics {
                incisions: Vec::with_capacity(4 * plan.incisions),
                planned: plan.incisions,
                optical_zone_mm: plan.optical_zone_m * 1e3,
                target_depth_fraction: plan.depth_fraction,
                target_correction_d: plan.target_correction_d,
                correction_tolerance_d: plan.correction_tolerance_d,
                ..KeratotomyMetrics::default()
            },
            stroke: None,
        }
    }

    /// The tick's cut, if one is under way on the cornea. A stroke that ends is counted as
    /// an incision if it reached far enough across. True on the tick a cut first goes
    /// through the whole thickness.
    pub fn step(&mut self, blade: Option<&BladeSample>) -> bool {
        let blade = blade.filter(|b| Some(b.organ) == self.organ);
        if self.stroke.as_ref().map(|s| s.number) != blade.map(|b| b.stroke) {
            self.end_stroke();
        }
        let Some(blade) = blade else {
            return false;
        };
        let off_axis = Vector3::new(blade.front_m.x, blade.front_m.y, 0.0);
        let r = off_axis.norm();
        let stroke = self.stroke.get_or_insert(Stroke {
            number: blade.stroke,
            azimuth: Vector3::zeros(),
            from_m: r,
            to_m: r,
            depth_m: 0.0,
        });
        stroke.azimuth += off_axis.try_normalize(1e-9).unwrap_or_else(Vector3::zeros);
        (stroke.from_m, stroke.to_m) = (stroke.from_m.min(r), stroke.to_m.max(r));
        stroke.depth_m = stroke.depth_m.max(blade.depth_m);
        let perforates = blade.depth_m >= CORNEA_THICKNESS_M && !self.metrics.perforated;
        self.metrics.perforated |= perforates;
        perforates
    }

    /// Incisions made so far, the stroke under way counted if it is one already.
    pub fn made(&self) -> usize {
        let under_way = self.stroke.as_ref().is_some_and(Stroke::is_incision);
        self.metrics.incisions.len() + usize::from(under_way)
    }

    /// The incisions the plan asks for.
    pub fn planned(&self) -> usize {
        self.metrics.planned
    }

    /// Whether a stroke is under way.
    pub fn cutting(&self) -> bool {
        self.stroke.is_some()
    }

    pub fn metrics(&self) -> KeratotomyMetrics {
        let mut tracker = self.clone();
        tracker.end_stroke();
        let mut metrics = tracker.metrics;
        let (spacing, intrusion, depth) = summary(&metrics);
        metrics.spacing_error_deg = spacing;
        metrics.zone_intrusion_mm = intrusion;
        metrics.mean_depth_fraction = depth;
        metrics
    }

    fn end_stroke(&mut self) {
        let Some(stroke) = self.stroke.take().filter(Stroke::is_incision) else {
            return;
        };
        let angle = stroke.azimuth.y.atan2(stroke.azimuth.x).rem_euclid(TAU);
        self.metrics.incisions.push(RadialIncision {
            angle_deg: angle.to_degrees(),
            from_mm: stroke.from_m * 1e3,
            to_mm: stroke.to_m * 1e3,
            depth_fraction: stroke.depth_m / CORNEA_THICKNESS_M,
        });
    }
}

impl Stroke {
    fn is_incision(&self) -> bool {
        self.to_m - self.from_m >= MIN_INCISION_M
    }
}

/// The spacing error (degrees), the optical zone's intrusion (mm) and the mean depth
/// fraction of the incisions in `metrics`.
fn summary(metrics: &KeratotomyMetrics) -> (f64, f64, f64) {
    let cuts = &metrics.incisions;
    if cuts.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    let mut angles: Vec<f64> = cuts.iter().map(|c| c.angle_deg).collect();
    angles.sort_by(f64::total_cmp);
    let even = 360.0 / angles.len() as f64;
    let spacing = (0..angles.len())
        .map(|k| {
            let next = angles.get(k + 1).copied().unwrap_or(angles[0] + 360.0);
            (next - angles[k] - even).abs()
        })
        .fold(0.0, f64::max);
    let nearest = cuts.iter().map(|c| c.from_mm).fold(f64::INFINITY, f64::min);
    let intrusion = (metrics.optical_zone_mm / 2.0 - nearest).max(0.0);
    let depth = cuts.iter().map(|c| c.depth_fraction).sum::<f64>() / cuts.len() as f64;
    (spacing, intrusion, depth)
}

/// The model of the cornea under the intraocular pressure that predicts a keratotomy's
/// correction, shared by the attempts at a scenario; it keeps its last answer, since an attempt is scored more than once (for the
/// screen, then for the report).
#[derive(Clone)]
pub struct Keratometer {
    cornea: Arc<Cornea>,
    last: Arc<Mutex<Option<Prediction>>>,
}

/// Incisions and the correction (D) predicted for them.
type Prediction = (Vec<RadialIncision>, f64);

impl Keratometer {
    pub fn new(cornea: Arc<Cornea>) -> Self {
        Self {
            cornea,
            last: Arc::default(),
        }
    }

    /// The correction (D, the fall of the central power) the incisions of `metrics` give,
    /// solved as the reference solver solves a keratotomy (`pgd cut cornea`).
    pub fn correction_d(&self, metrics: &KeratotomyMetrics) -> Option<f64> {
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((incisions, correction)) = last.as_ref()
            && incisions == &metrics.incisions
        {
            return Some(*correction);
        }
        let faces = metrics.faces().ok()?;
        let correction = -self.cornea.power_change_d(&faces, Front::Inward).ok()?;
        *last = Some((metrics.incisions.clone(), correction));
        Some(correction)
    }
}

impl fmt::Debug for Keratometer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Keratometer")
    }
}

impl PartialEq for Keratometer {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.cornea, &other.cornea)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blade(stroke: u32, angle_deg: f64, r_mm: f64, depth_fraction: f64) -> BladeSample {
        let a = angle_deg.to_radians();
        BladeSample {
            organ: 0,
            front_m: Vector3::new(a.cos(), a.sin(), 0.0) * r_mm * 1e-3,
            depth_m: depth_fraction * CORNEA_THICKNESS_M,
            stroke,
        }
    }

    fn plan() -> KeratotomyPlan {
        KeratotomyPlan {
            incisions: 4,
            optical_zone_m: 3e-3,
            depth_fraction: 0.8,
            target_correction_d: 3.0,
            correction_tolerance_d: 1.0,
        }
    }

    /// Strokes drawn out from `from_mm` to 5 mm at `angles`, `depth` deep, lifted between.
    fn cut(angles: &[f64], from_mm: f64, depth: f64) -> KeratotomyMetrics {
        let mut tracker = KeratotomyTracker::new(Some(0), plan());
        for (k, &angle) in angles.iter().enumerate() {
            for step in 0..=10 {
                let r = from_mm + (5.0 - from_mm) * step as f64 / 10.0;
                tracker.step(Some(&blade(k as u32 + 1, angle, r, depth)));
            }
            tracker.step(None);
        }
        tracker.metrics()
    }

    #[test]
    fn even_incisions_outside_the_zone_are_symmetric_and_clear_of_it() {
        let m = cut(&[10.0, 100.0, 190.0, 280.0], 1.6, 0.8);
        assert_eq!(m.incisions.len(), 4);
        assert!(m.spacing_error_deg < 1e-9, "{}", m.spacing_error_deg);
        assert_eq!(m.zone_intrusion_mm, 0.0);
        assert!((m.mean_depth_fraction - 0.8).abs() < 1e-12);
        assert!((m.incisions[1].angle_deg - 100.0).abs() < 1e-9);
        assert!((m.incisions[0].from_mm - 1.6).abs() < 1e-12);
        assert!(!m.perforated);
    }

    /// Two incisions 60° apart instead of 90°, one of them 1 mm inside the 1.5 mm radius.
    #[test]
    fn uneven_incisions_into_the_zone_are_measured() {
        let m = cut(&[0.0, 60.0, 180.0, 270.0], 0.5, 0.8);
        assert!(
            (m.spacing_error_deg - 30.0).abs() < 1e-9,
            "{}",
            m.spacing_error_deg
        );
        assert!((m.zone_intrusion_mm - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_full_thickness_cut_perforates_once_and_a_nick_is_no_incision() {
        let mut tracker = KeratotomyTracker::new(Some(0), plan());
        assert!(!tracker.step(Some(&blade(1, 0.0, 2.0, 0.9))));
        assert!(tracker.step(Some(&blade(1, 0.0, 2.2, 1.02))));
        assert!(!tracker.step(Some(&blade(1, 0.0, 2.3, 1.1))));
        tracker.step(None);
        assert!(tracker.metrics().perforated);
        assert_eq!(tracker.metrics().incisions.len(), 0, "0.3 mm is a nick");
    }
}
