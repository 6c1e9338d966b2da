//! Clip and divide the cystic duct and artery: expose them to the critical view of safety,
//! then place two clips on the patient's side and one on the gallbladder's across each, and
//! divide it between them.

use serde::{Deserialize, Serialize};

use crate::biliary::{Clip, Division, DivisionOutcome, Part, Structure};
use crate::scenario::task::{
    RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
};

/// `ClipAndCut(organ: "gallbladder", divide, max_force_n, time_limit_s)`: reach the critical
/// view of safety, then clip and divide each structure of `divide` (the cystic duct and the
/// cystic artery when left out) between two clips on the patient's side and one on the
/// gallbladder's; a stump that bleeds must be clipped or coagulated before the task is done. A clip or a cut before the critical view, a clip that does not close its
/// tube, a cut with fewer clips, a stump left open are mistakes; a clip across the common
/// hepatic or bile duct is a major one; dividing either is a bile duct injury, which ends
/// the attempt.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipAndCut {
    #[serde(default = "both")]
    pub divide: Vec<Structure>,
}

fn both() -> Vec<Structure> {
    vec![Structure::CysticDuct, Structure::CysticArtery]
}

/// The mistakes' codes.
const CLIP_BEFORE_VIEW: u16 = 0;
const CUT_BEFORE_VIEW: u16 = 1;
/// Amount: the share of the tube's width the clip closes (%).
const CLIP_OPEN: u16 = 2;
const CLIP_ON_BILE_DUCT: u16 = 3;
/// Amount: the clips on the patient's side.
const TOO_FEW_CLIPS: u16 = 4;
const STUMP_OPEN: u16 = 5;
const BILE_DUCT_INJURY: u16 = 6;

/// The most clips and divisions a run keeps (reserved before the exercise starts).
const MAX_KEPT: usize = 32;

impl TaskType for ClipAndCut {
    const NAME: &'static str = "ClipAndCut";
    const LABEL: &'static str = "clip and cut";
    const FORCE_VERB: &'static str = "pressed or pulled";
    type Run = ClipAndCutRun;

    fn description(&self, _: &TaskShared) -> String {
        let names: Vec<&str> = self.divide.iter().map(|s| s.name()).collect();
        format!(
            "reach the critical view of safety, then clip and divide {}: two clips on the \
             patient's side, one on the gallbladder's, the cut between them",
            names.join(" and ")
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        if !check.scene.biliary {
            check.problem(
                "divide",
                "a ClipAndCut task needs the cystic duct and artery: the scene has no biliary tree",
                "add biliary: Biliary() to the scenario",
            );
        }
        let needs = [
            (
                check.scene.clips,
                "a clip applier",
                "ClipApplier(tip_radius_mm: 6.0)",
            ),
            (
                check.scene.divides,
                "scissors",
                "Scissors(tip_radius_mm: 6.0)",
            ),
        ];
        for (has, what, tool) in needs {
            if !has {
                let message = format!("a ClipAndCut task needs {what}");
                check.problem(
                    "divide",
                    message,
                    format!("add an instrument with tool: {tool}"),
                );
            }
        }
        if self.divide.contains(&Structure::CommonDuct) {
            check.problem(
                "divide",
                "the common duct is never divided: dividing it is a bile duct injury",
                "divide: [CysticDuct, CysticArtery]",
            );
        }
        if self.divide.is_empty() {
            check.problem(
                "divide",
                "nothing to divide",
                "divide: [CysticDuct, CysticArtery]",
            );
        }
    }

    fn run(&self, _: &TaskShared, _: RunSetup) -> ClipAndCutRun {
        ClipAndCutRun {
            divide: self.divide.clone(),
            clips: Vec::with_capacity(MAX_KEPT),
            divisions: Vec::with_capacity(MAX_KEPT),
            view_reached_s: None,
            bile_duct_injury: false,
            blood_lost_m3: 0.0,
            bile_spilled_m3: 0.0,
            bleeding: false,
        }
    }

    fn describe_mistake(&self, _: &TaskShared, code: u16, amount: f64) -> String {
        match code {
            CLIP_BEFORE_VIEW => "placed a clip before the critical view of safety".into(),
            CUT_BEFORE_VIEW => "divided a structure before the critical view of safety".into(),
            CLIP_OPEN => format!("placed a clip that closes only {amount:.0} % of the tube"),
            CLIP_ON_BILE_DUCT => "placed a clip across the common bile or hepatic duct".into(),
            TOO_FEW_CLIPS => format!(
                "divided a structure with {amount:.0} clip(s) on the patient's side (two taught)"
            ),
            STUMP_OPEN => "divided a structure with a stump left open".into(),
            _ => "divided the common bile or hepatic duct: a bile duct injury".into(),
        }
    }
}

/// A clip as the run keeps it: when, and whether the critical view had been reached.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClipPlaced {
    pub time_s: f64,
    pub clip: Clip,
    pub after_view: bool,
}

/// A division as the run keeps it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DivisionMade {
    pub time_s: f64,
    pub division: Division,
    pub after_view: bool,
}

#[derive(Clone, Debug)]
pub struct ClipAndCutRun {
    divide: Vec<Structure>,
    clips: Vec<ClipPlaced>,
    divisions: Vec<DivisionMade>,
    view_reached_s: Option<f64>,
    bile_duct_injury: bool,
    blood_lost_m3: f64,
    bile_spilled_m3: f64,
    bleeding: bool,
}

impl ClipAndCutRun {
    fn clipped(&mut self, tick: &mut Tick<'_>, clip: Clip) {
        let after_view = self.view_reached_s.is_some();
        if !after_view {
            tick.mistake(CLIP_BEFORE_VIEW, 0.0);
        }
        if clip.part.is_main_bile_duct() {
            tick.mistake(CLIP_ON_BILE_DUCT, 0.0);
        } else if !clip.closes_lumen() {
            tick.mistake(CLIP_OPEN, 100.0 * clip.closed_share);
        }
        if self.clips.len() < self.clips.capacity() {
            let time_s = tick.sample.time_s;
            self.clips.push(ClipPlaced {
                time_s,
                clip,
                after_view,
            });
        }
    }

    fn divided(&mut self, tick: &mut Tick<'_>, division: Division) {
        let after_view = self.view_reached_s.is_some();
        if !after_view {
            tick.mistake(CUT_BEFORE_VIEW, 0.0);
        }
        match division.outcome {
            DivisionOutcome::BetweenClips => {}
            DivisionOutcome::TooFewClips => {
                tick.mistake(TOO_FEW_CLIPS, division.patient_clips as f64)
            }
            DivisionOutcome::Open => tick.mistake(STUMP_OPEN, 0.0),
            DivisionOutcome::BileDuctInjury => {
                tick.mistake(BILE_DUCT_INJURY, 0.0);
                self.bile_duct_injury = true;
            }
        }
        if self.divisions.len() < self.divisions.capacity() {
            let time_s = tick.sample.time_s;
            self.divisions.push(DivisionMade {
                time_s,
                division,
                after_view,
            });
        }
    }

    /// Whether every structure to divide has been.
    fn all_divided(&self) -> bool {
        (self.divide.iter()).all(|s| self.divisions.iter().any(|d| d.division.structure == *s))
    }
}

impl TaskRun for ClipAndCutRun {
    type Result = ClipAndCutResult;

    /// Done once every structure to divide is divided and nothing bleeds, without a bile duct
    /// injury.
    fn step(&mut self, tick: &mut Tick<'_>) {
        let biliary = tick.sample.biliary;
        if biliary.view.reached && self.view_reached_s.is_none() {
            self.view_reached_s = Some(tick.sample.time_s);
        }
        if let Some(clip) = biliary.clip {
            self.clipped(tick, clip);
        }
        if let Some(division) = biliary.division {
            self.divided(tick, division);
        }
        self.blood_lost_m3 = biliary.blood_lost_m3;
        self.bile_spilled_m3 = biliary.bile_spilled_m3;
        self.bleeding = biliary.bleeding;
        tick.metrics.completed = self.all_divided() && !self.bleeding && !self.bile_duct_injury;
    }

    fn over(&self) -> bool {
        self.bile_duct_injury
    }

    fn progress(&self) -> Option<TaskProgress> {
        let divided = (self.divide.iter())
            .filter(|s| self.divisions.iter().any(|d| d.division.structure == **s))
            .count();
        Some(TaskProgress {
            what: "divided",
            done: divided as f64,
            of: self.divide.len() as f64,
            unit: "",
        })
    }

    fn result(&self) -> ClipAndCutResult {
        let clips_on = |part: Part| self.clips.iter().filter(|c| c.clip.part == part).count();
        ClipAndCutResult {
            view_reached_s: self.view_reached_s,
            clips: self.clips.clone(),
            divisions: self.divisions.clone(),
            cystic_duct_clips: clips_on(Part::CysticDuct),
            artery_clips: clips_on(Part::CysticArtery),
            blood_lost_ml: self.blood_lost_m3 * 1e6,
            bile_spilled_ml: self.bile_spilled_m3 * 1e6,
            still_bleeding: self.bleeding,
            bile_duct_injury: self.bile_duct_injury,
        }
    }
}

/// A clip-and-cut's measures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClipAndCutResult {
    /// When the critical view of safety was reached (s from the exercise's start).
    pub view_reached_s: Option<f64>,
    pub clips: Vec<ClipPlaced>,
    pub divisions: Vec<DivisionMade>,
    pub cystic_duct_clips: usize,
    pub artery_clips: usize,
    pub blood_lost_ml: f64,
    pub bile_spilled_ml: f64,
    /// Whether a stump still bled when the task ended.
    pub still_bleeding: bool,
    pub bile_duct_injury: bool,
}

impl TaskResult for ClipAndCutResult {
    /// The share of the divisions made as taught: after the critical view, between clips.
    fn accuracy(&self) -> Option<f64> {
        let taught = (self.divisions.iter())
            .filter(|d| d.after_view && d.division.outcome == DivisionOutcome::BetweenClips)
            .count();
        Some(taught as f64 / self.divisions.len().max(1) as f64)
    }

    fn feedback(&self) -> Vec<String> {
        let early_clips = (self.clips.iter().filter(|c| !c.after_view)).map(|c| {
            format!(
                "clipped {} at {:.1} s, before the critical view of safety",
                c.clip.part.name(),
                c.time_s
            )
        });
        let early_cuts = (self.divisions.iter().filter(|d| !d.after_view)).map(|d| {
            format!(
                "divided {} at {:.1} s, before the critical view of safety",
                d.division.part.name(),
                d.time_s
            )
        });
        let open = (self.clips.iter().filter(|c| !c.clip.closes_lumen())).map(|c| {
            format!(
                "the clip on {} at {:.1} s closes {:.0} % of it",
                c.clip.part.name(),
                c.time_s,
                100.0 * c.clip.closed_share
            )
        });
        early_clips.chain(early_cuts).chain(open).collect()
    }

    fn unfinished(&self) -> Option<String> {
        Some(match self.still_bleeding {
            true => " (a stump still bleeding)".into(),
            false => String::new(),
        })
    }

    fn complication(&self) -> Option<String> {
        let injury = (self.divisions.iter())
            .find(|d| d.division.outcome == DivisionOutcome::BileDuctInjury)?;
        Some(format!(
            "a bile duct injury: {} divided at {:.1} s",
            injury.division.part.name(),
            injury.time_s
        ))
    }

    fn summary(&self) -> Vec<String> {
        let view = match self.view_reached_s {
            Some(t) => format!("critical view of safety reached at {t:.1} s"),
            None => "critical view of safety not reached".into(),
        };
        let mut lines = vec![
            view,
            format!(
                "clips: {} on the cystic duct, {} on the artery",
                self.cystic_duct_clips, self.artery_clips
            ),
        ];
        for made in &self.divisions {
            let d = &made.division;
            lines.push(format!(
                "{} divided at {:.0} mm from its origin at {:.1} s: {}",
                d.part.name(),
                d.arc_length_m * 1e3,
                made.time_s,
                match d.outcome {
                    DivisionOutcome::BetweenClips => "between clips, as taught",
                    DivisionOutcome::TooFewClips => "too few clips",
                    DivisionOutcome::Open => "a stump left open",
                    DivisionOutcome::BileDuctInjury => "a bile duct injury",
                }
            ));
        }
        lines.push(format!(
            "blood lost {:.1} mL, bile spilled {:.1} mL",
            self.blood_lost_ml, self.bile_spilled_ml
        ));
        lines
    }
}
