//! Radial keratotomy on the cornea: radial cuts round its axis, outside the optical zone, to
//! flatten it by the dioptres asked.

use serde::{Deserialize, Serialize};

use super::incision::{check_blade, depth_accuracy};
use crate::mesh::organs::Organ;
use crate::scenario::keratotomy::{
    Keratometer, KeratotomyMetrics, KeratotomyPlan, KeratotomyTracker, MIN_INCISION_M,
};
use crate::scenario::task::{
    RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
};
use crate::scenario::units::{DepthFraction, Dioptres, IncisionCount, Millimetres};

/// `RadialKeratotomy(organ, incisions, optical_zone_mm, depth_fraction, target_correction_d,
/// correction_tolerance_d, max_force_n, time_limit_s)`: `incisions` radial cuts, evenly spaced
/// round the cornea's axis, each from the edge of the central optical zone (`optical_zone_mm`
/// across, left uncut) out towards the limbus, `depth_fraction` of the thickness deep, to
/// flatten the cornea by `target_correction_d` dioptres. Done when as many incisions are made
/// and the blade is lifted. Scored on symmetry, the optical zone respected, depth, and the
/// correction the cut cornea is predicted to give against the target (within
/// `correction_tolerance_d`, 1 D when left out); a cut through the whole thickness perforates
/// the eye and fails the attempt.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RadialKeratotomy {
    pub incisions: IncisionCount,
    pub optical_zone_mm: Millimetres,
    pub depth_fraction: DepthFraction,
    pub target_correction_d: Dioptres,
    #[serde(default = "default_correction_tolerance")]
    pub correction_tolerance_d: Dioptres,
}

fn default_correction_tolerance() -> Dioptres {
    Dioptres(1.0)
}

impl TaskType for RadialKeratotomy {
    const NAME: &'static str = "RadialKeratotomy";
    const LABEL: &'static str = "radial keratotomy";
    type Run = RadialKeratotomyRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "make {} radial incisions in the {} outside a {:.1} mm optical zone, {:.0} % deep, \
             for {:.1} D of correction, under {} N",
            self.incisions.0,
            shared.organ.as_deref().unwrap_or_default(),
            self.optical_zone_mm.0,
            100.0 * self.depth_fraction.0,
            self.target_correction_d.0,
            shared.max_force_n
        )
    }

    /// A scalpel, the generated cornea, and room for the incisions between the optical zone
    /// and the limbus.
    fn check(&self, check: &mut TaskCheck<'_>) {
        check_blade(check);
        let anchors = |name| ["tasks", "RadialKeratotomy", name];
        let organ = check.organ_name();
        let cornea = check
            .organ()
            .map(|e| e.mesh.is_none() && Organ::from_name(&e.name) == Some(Organ::Cornea));
        if cornea == Some(false) {
            check.problem_at(
                "organ",
                &anchors("organ"),
                format!("radial keratotomy cuts the cornea, not the {organ}"),
                "put \"cornea\" in organs and name it here",
            );
        }
        let optical_zone_mm = self.optical_zone_mm.0;
        let outer_mm = crate::cutting::keratotomy::INCISION_END_M * 1e3;
        if outer_mm - optical_zone_mm / 2.0 < MIN_INCISION_M * 1e3 {
            check.problem_at(
                "optical_zone_mm",
                &anchors("optical_zone_mm"),
                format!(
                    "a {optical_zone_mm} mm optical zone leaves no room for incisions: they end \
                     {outer_mm:.2} mm off the axis, {:.1} mm inside the {:.1} mm cornea's limbus",
                    crate::mesh::organs::CORNEA_RIM_M * 1e3 - outer_mm,
                    2.0 * crate::mesh::organs::CORNEA_RIM_M * 1e3,
                ),
                format!(
                    "an optical zone is 3 to 4 mm across; at most {:.1} mm here",
                    2.0 * (outer_mm - MIN_INCISION_M * 1e3)
                ),
            );
        }
        check.within_device();
    }

    fn run(&self, shared: &TaskShared, setup: RunSetup) -> RadialKeratotomyRun {
        let plan = KeratotomyPlan {
            incisions: self.incisions.0,
            optical_zone_m: self.optical_zone_mm.metres(),
            depth_fraction: self.depth_fraction.0,
            target_correction_d: self.target_correction_d.0,
            correction_tolerance_d: self.correction_tolerance_d.0,
        };
        RadialKeratotomyRun {
            organ: shared.organ.clone().unwrap_or_default(),
            tracker: KeratotomyTracker::new(setup.organ, plan),
            keratometer: setup.keratometer,
            perforated_s: None,
        }
    }
}

#[derive(Clone, Debug)]
pub struct RadialKeratotomyRun {
    organ: String,
    tracker: KeratotomyTracker,
    /// The cut cornea's model the correction is predicted with, when the attempt is scored.
    keratometer: Option<Keratometer>,
    /// When the cut went through the whole thickness (a complication).
    perforated_s: Option<f64>,
}

impl TaskRun for RadialKeratotomyRun {
    type Result = RadialKeratotomyResult;

    /// Done when the plan's incisions are made and the blade is lifted. A cut through the
    /// whole thickness is a complication: the task cannot be done any more.
    fn step(&mut self, tick: &mut Tick<'_>) {
        let tracker = &mut self.tracker;
        if tracker.step(tick.sample.blade.as_ref()) {
            self.perforated_s.get_or_insert(tick.sample.time_s);
        }
        tick.metrics.completed = !tracker.cutting()
            && tracker.made() >= tracker.planned()
            && self.perforated_s.is_none();
    }

    fn over(&self) -> bool {
        self.perforated_s.is_some()
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(TaskProgress {
            what: "incisions",
            done: self.tracker.made() as f64,
            of: self.tracker.planned() as f64,
            unit: "",
        })
    }

    /// The incisions, and the correction the cut cornea is predicted to give: a full solve,
    /// which is why it is made when the attempt is scored and not on the haptic thread.
    fn result(&self) -> RadialKeratotomyResult {
        let mut keratotomy = self.tracker.metrics();
        if let Some(keratometer) = &self.keratometer {
            keratotomy.predicted_correction_d = keratometer.correction_d(&keratotomy);
        }
        RadialKeratotomyResult {
            keratotomy,
            complication: self.perforated_s.map(|time_s| {
                format!(
                    "{time_s:.2} s: cut through the whole thickness of the {}: a perforation",
                    self.organ
                )
            }),
        }
    }
}

/// A keratotomy's measures: the incisions against the plan, and the correction they give.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RadialKeratotomyResult {
    pub keratotomy: KeratotomyMetrics,
    /// Written in the metrics every task has.
    #[serde(skip)]
    pub complication: Option<String>,
}

impl TaskResult for RadialKeratotomyResult {
    /// The mean of the symmetry (1 evenly spaced, 0 when a gap is off by half the even
    /// spacing), the optical zone (1 clear, 0 cut to the axis), the depth's accuracy (as an
    /// incision's) and the correction's (1 on the target, 0 at twice the tolerance off it, or
    /// when it could not be predicted); 0 with no incision.
    fn accuracy(&self) -> Option<f64> {
        let rk = &self.keratotomy;
        let made = rk.incisions.len();
        if made == 0 {
            return Some(0.0);
        }
        let symmetry = 1.0 - rk.spacing_error_deg / (180.0 / made as f64);
        let zone = 1.0 - rk.zone_intrusion_mm / (rk.optical_zone_mm / 2.0);
        let depth = depth_accuracy(rk.mean_depth_fraction / rk.target_depth_fraction);
        let correction = rk.predicted_correction_d.map_or(0.0, |d| {
            1.0 - (d - rk.target_correction_d).abs() / (2.0 * rk.correction_tolerance_d)
        });
        let terms = [symmetry, zone, depth, correction];
        Some(terms.iter().map(|t| t.clamp(0.0, 1.0)).sum::<f64>() / terms.len() as f64)
    }

    /// What the keratotomy got wrong, and always the correction it is predicted to give.
    fn feedback(&self) -> Vec<String> {
        let rk = &self.keratotomy;
        let mut lines = Vec::new();
        let made = rk.incisions.len();
        if made != rk.planned {
            lines.push(format!("{made} incisions made of {}", rk.planned));
        }
        if made > 1 && rk.spacing_error_deg > 90.0 / made as f64 {
            lines.push(format!(
                "unevenly spaced: a gap {:.0}° off the even {:.0}°",
                rk.spacing_error_deg,
                360.0 / made as f64
            ));
        }
        if rk.zone_intrusion_mm > 0.0 {
            lines.push(format!(
                "cut {:.1} mm into the {:.1} mm optical zone",
                rk.zone_intrusion_mm, rk.optical_zone_mm
            ));
        }
        let (depth, target) = (rk.mean_depth_fraction, rk.target_depth_fraction);
        if made > 0 && (depth - target).abs() > 0.1 {
            lines.push(format!(
                "{:.0} % deep on average for {:.0} %",
                100.0 * depth,
                100.0 * target
            ));
        }
        let target = rk.target_correction_d;
        lines.push(match rk.predicted_correction_d {
            Some(d) => format!(
                "predicted correction {d:.1} D for {target:.1} D (within {:.1} D counts)",
                rk.correction_tolerance_d
            ),
            None if made == 0 => "no incision, no correction".into(),
            None => "the correction could not be predicted".into(),
        });
        lines
    }

    fn summary(&self) -> Vec<String> {
        let rk = &self.keratotomy;
        let correction = rk
            .predicted_correction_d
            .map_or("none predicted".to_owned(), |d| format!("{d:.1} D"));
        vec![format!(
            "incisions: {} of {}, spacing off by up to {:.0}°, {:.1} mm into the optical zone, {:.0} % deep on average (target {:.0} %){}; correction {correction} (target {:.1} D)",
            rk.incisions.len(),
            rk.planned,
            rk.spacing_error_deg,
            rk.zone_intrusion_mm,
            100.0 * rk.mean_depth_fraction,
            100.0 * rk.target_depth_fraction,
            if rk.perforated { ", PERFORATED" } else { "" },
            rk.target_correction_d
        )]
    }

    fn complication(&self) -> Option<String> {
        self.complication.clone()
    }
}
