//! An operation scored as surgical educators publish their scores: a weighted list of the
//! steps done and the errors made, each with its points, read from what the tasks measured.
//! The template is the laparoscopic cholecystectomy score of Eubanks et al. (1999, J Am Coll
//! Surg 189:566–574): points for each step done, points taken for each error each time it is
//! made, and an error a patient would carry (a bile duct injury) failing the attempt whatever
//! the total. Where their rater watches, the trainer reads its own measures: a task finished,
//! when the critical view was reached, where each clip and division went, what the hook
//! burned; the events below say which.

use serde::{Deserialize, Serialize};

use super::task::{TaskMetrics, results_of};
use super::tasks::{BurnMade, ClipAndCutResult, ClipPlaced, DissectionResult, DivisionMade};
use crate::biliary::{DivisionOutcome, Part, Structure};

/// A scenario's operation-level rubric (`operation: Operation(steps: […], errors: […])`):
/// when present, the attempt's score is this one's.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename = "Operation")]
pub struct OperationRubric {
    pub steps: Vec<ScoredStep>,
    #[serde(default)]
    pub errors: Vec<ScoredError>,
}

/// A step of the operation and the points it earns once done.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename = "Step")]
pub struct ScoredStep {
    pub name: String,
    pub points: f64,
    pub done: Event,
}

/// An error and the points it costs each time it is made; a major one fails the attempt.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename = "Error")]
pub struct ScoredError {
    pub name: String,
    pub points: f64,
    #[serde(default)]
    pub major: bool,
    pub made: Event,
}

/// Something an attempt can be seen to do, read from its tasks' measures. Tasks are numbered
/// from 1 in the scenario's order.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
pub enum Event {
    /// Task `n` finished within its time.
    Finished(usize),
    /// The critical view of safety reached before any clip or division (a clip-and-cut).
    CriticalView,
    /// The structure divided between its clips, as taught (a clip-and-cut).
    DividedBetweenClips(Structure),
    /// At least this share of the bed's attachment released (a dissection).
    Released(f64),
    /// A clip or a division before the critical view of safety, each.
    BeforeCriticalView,
    /// The common duct clipped or divided, each.
    BileDuctInjury,
    /// A structure divided with a stump left open, each.
    OpenStump,
    /// The gallbladder's wall burned through: bile spilled (a dissection).
    Perforation,
    /// A burn through the liver's capsule, each: a liver injury that bleeds.
    LiverInjury,
    /// A burn on tissue other than the ties, each.
    NonTargetBurn,
    /// At least this much blood lost (ml), over the clip-and-cut tasks.
    BloodLost(f64),
}

impl Event {
    /// Each time the attempt did it (s from its start), in order, with where: empty if it
    /// never did.
    pub fn occurrences(self, tasks: &[TaskMetrics]) -> Vec<Occurrence> {
        let clip_and_cut = || results_of::<ClipAndCutResult>(tasks);
        let dissections = || results_of::<DissectionResult>(tasks);
        let clips = || clip_and_cut().flat_map(|r| r.clips.iter());
        let divisions = || clip_and_cut().flat_map(|r| r.divisions.iter());
        let burns = || dissections().flat_map(|r| r.burns.iter());
        let clip_on = |c: &ClipPlaced| Occurrence::on(c.time_s, c.clip.part);
        let cut_on = |d: &DivisionMade| Occurrence::on(d.time_s, d.division.part);
        let mut occurrences: Vec<Occurrence> = match self {
            Event::Finished(n) => (tasks.get(n.wrapping_sub(1)).into_iter())
                .filter(|m| m.completed)
                .map(|m| Occurrence::at(m.started_s + m.time_s))
                .collect(),
            Event::CriticalView => clip_and_cut()
                .filter_map(view_first)
                .map(Occurrence::at)
                .collect(),
            Event::DividedBetweenClips(structure) => divisions()
                .filter(|d| d.division.structure == structure)
                .filter(|d| d.division.outcome == DivisionOutcome::BetweenClips)
                .map(cut_on)
                .take(1)
                .collect(),
            Event::Released(share) => dissections()
                .filter(|r| r.released_share >= share)
                .map(|_| {
                    Occurrence::at(task_end(tasks, |m| {
                        m.result::<DissectionResult>().is_some()
                    }))
                })
                .collect(),
            Event::BeforeCriticalView => (clips().filter(|c| !c.after_view).map(clip_on))
                .chain(divisions().filter(|d| !d.after_view).map(cut_on))
                .collect(),
            Event::BileDuctInjury => (clips())
                .filter(|c| c.clip.structure == Structure::CommonDuct)
                .map(clip_on)
                .chain(
                    divisions()
                        .filter(|d| d.division.outcome == DivisionOutcome::BileDuctInjury)
                        .map(cut_on),
                )
                .collect(),
            Event::OpenStump => divisions()
                .filter(|d| d.division.outcome == DivisionOutcome::Open)
                .map(cut_on)
                .collect(),
            Event::Perforation => (dissections().filter_map(|r| r.perforation.as_ref()))
                .map(Occurrence::burned)
                .collect(),
            Event::LiverInjury => burns()
                .filter(|b| b.organ == "liver" && b.through_capsule)
                .map(Occurrence::burned)
                .collect(),
            Event::NonTargetBurn => burns().map(Occurrence::burned).collect(),
            Event::BloodLost(ml) => {
                let lost: f64 = clip_and_cut().map(|r| r.blood_lost_ml).sum();
                let end = task_end(tasks, |m| m.result::<ClipAndCutResult>().is_some());
                (lost >= ml)
                    .then(|| Occurrence::at(end))
                    .into_iter()
                    .collect()
            }
        };
        occurrences.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        occurrences
    }

    /// The task type the event is read from, if it needs one in the scenario: its name as
    /// scenarios write it.
    pub fn needs(self) -> Option<&'static str> {
        match self {
            Event::Finished(_) => None,
            Event::CriticalView
            | Event::DividedBetweenClips(_)
            | Event::BeforeCriticalView
            | Event::BileDuctInjury
            | Event::OpenStump
            | Event::BloodLost(_) => Some("ClipAndCut"),
            Event::Released(_) | Event::Perforation | Event::LiverInjury | Event::NonTargetBurn => {
                Some("Dissection")
            }
        }
    }
}

/// When the critical view was reached, if before every clip and division.
fn view_first(result: &ClipAndCutResult) -> Option<f64> {
    let view_s = result.view_reached_s?;
    let first_clip = result.clips.iter().map(|c| c.time_s);
    let first_cut = result.divisions.iter().map(|d| d.time_s);
    first_clip
        .chain(first_cut)
        .all(|t| t >= view_s)
        .then_some(view_s)
}

/// When the last task that `is` ended (s from the attempt's start).
fn task_end(tasks: &[TaskMetrics], is: impl Fn(&TaskMetrics) -> bool) -> f64 {
    (tasks.iter().filter(|m| is(m)))
        .map(|m| m.started_s + m.time_s)
        .fold(0.0, f64::max)
}

/// One time an event happened: when (s from the attempt's start), and where, in words, where
/// the measures say (the tube clipped or divided, the organ burned and the point).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Occurrence {
    pub time_s: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub place: Option<String>,
}

impl Occurrence {
    fn at(time_s: f64) -> Self {
        Self {
            time_s,
            place: None,
        }
    }

    fn on(time_s: f64, part: Part) -> Self {
        Self {
            time_s,
            place: Some(part.name().to_owned()),
        }
    }

    fn burned(burn: &BurnMade) -> Self {
        let [x, y, z] = burn.at_mm;
        Self {
            time_s: burn.time_s,
            place: Some(format!("the {} at ({x:.0}, {y:.0}, {z:.0}) mm", burn.organ)),
        }
    }
}

/// A step as scored: when it was done, if it was.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepScored {
    pub name: String,
    pub points: f64,
    pub done_s: Option<f64>,
}

/// An error as scored: each time it was made, and what it cost.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorScored {
    pub name: String,
    pub points_each: f64,
    pub major: bool,
    pub made: Vec<Occurrence>,
}

/// The operation's score: the points of the steps done less those of the errors made, as a
/// share of all the steps' points (0–100).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OperationScore {
    pub steps: Vec<StepScored>,
    pub errors: Vec<ErrorScored>,
    pub points: f64,
    pub possible: f64,
    pub score: f64,
    pub major_error: bool,
}

impl OperationRubric {
    /// The attempt's `tasks` scored by this rubric.
    pub fn score(&self, tasks: &[TaskMetrics]) -> OperationScore {
        let steps: Vec<StepScored> = (self.steps.iter())
            .map(|step| StepScored {
                name: step.name.clone(),
                points: step.points,
                done_s: step.done.occurrences(tasks).first().map(|o| o.time_s),
            })
            .collect();
        let errors: Vec<ErrorScored> = (self.errors.iter())
            .map(|error| ErrorScored {
                name: error.name.clone(),
                points_each: error.points,
                major: error.major,
                made: error.made.occurrences(tasks),
            })
            .collect();
        let earned: f64 = (steps.iter().filter(|s| s.done_s.is_some()))
            .map(|s| s.points)
            .sum();
        let lost: f64 = (errors.iter())
            .map(|e| e.points_each * e.made.len() as f64)
            .sum();
        let possible: f64 = steps.iter().map(|s| s.points).sum();
        let points = earned - lost;
        OperationScore {
            major_error: errors.iter().any(|e| e.major && !e.made.is_empty()),
            score: (100.0 * points / possible.max(f64::MIN_POSITIVE)).clamp(0.0, 100.0),
            points,
            possible,
            steps,
            errors,
        }
    }
}

impl OperationScore {
    /// The debrief's lines: the errors in the order they were made, then the steps not done.
    pub fn feedback(&self) -> Vec<String> {
        let mut made: Vec<(&Occurrence, &ErrorScored)> = (self.errors.iter())
            .flat_map(|e| e.made.iter().map(move |o| (o, e)))
            .collect();
        made.sort_by(|a, b| a.0.time_s.total_cmp(&b.0.time_s));
        let errors = made.into_iter().map(|(o, e)| {
            let major = if e.major { ", a major error" } else { "" };
            let place = o.place.as_ref().map_or(String::new(), |p| format!(", {p}"));
            format!(
                "{:.1} s: {}{place} (−{} points{major})",
                o.time_s, e.name, e.points_each
            )
        });
        let missed = (self.steps.iter().filter(|s| s.done_s.is_none()))
            .map(|s| format!("not done: {} ({} points)", s.name, s.points));
        errors.chain(missed).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::task::TaskOutcome;
    use crate::scenario::tasks::EnergySpent;

    fn burn(organ: &str, time_s: f64, through_capsule: bool) -> BurnMade {
        BurnMade {
            organ: organ.into(),
            time_s,
            at_mm: [0.0; 3],
            area_mm2: 4.0,
            through_capsule,
        }
    }

    /// A dissection from 10 s to 60 s that released `released` of the bed, with `burns` and
    /// a perforation if given.
    fn dissection(
        released: f64,
        burns: Vec<BurnMade>,
        perforation: Option<BurnMade>,
    ) -> TaskMetrics {
        TaskMetrics {
            started_s: 10.0,
            time_s: 50.0,
            completed: released >= 0.9,
            outcome: Some(TaskOutcome::new(DissectionResult {
                released_share: released,
                target_share: 0.9,
                ties_divided: 0,
                ties_torn: 0,
                burned_area_mm2: 4.0 * burns.len() as f64,
                capsule_injuries: burns.iter().filter(|b| b.through_capsule).count(),
                burns,
                perforation,
                energy: EnergySpent::default(),
            })),
            ..TaskMetrics::default()
        }
    }

    fn rubric() -> OperationRubric {
        let step = |name: &str, points, done| ScoredStep {
            name: name.into(),
            points,
            done,
        };
        let error = |name: &str, points, major, made| ScoredError {
            name: name.into(),
            points,
            major,
            made,
        };
        OperationRubric {
            steps: vec![
                step("dissection finished", 10.0, Event::Finished(1)),
                step("gallbladder freed", 30.0, Event::Released(0.9)),
            ],
            errors: vec![
                error("gallbladder perforated", 20.0, true, Event::Perforation),
                error("liver injury", 10.0, false, Event::LiverInjury),
                error("non-target burn", 2.0, false, Event::NonTargetBurn),
            ],
        }
    }

    fn outcome(task: TaskMetrics) -> (Vec<Option<f64>>, Vec<Vec<f64>>, OperationScore) {
        let scored = rubric().score(&[task]);
        let done = scored.steps.iter().map(|s| s.done_s).collect();
        let made = (scored.errors.iter())
            .map(|e| e.made.iter().map(|o| o.time_s).collect())
            .collect();
        (done, made, scored)
    }

    /// Each dissection event counts exactly when the attempt makes it: the bed freed, a burn
    /// on the gallbladder (non-target only), a burn through the liver's capsule (an injury
    /// and a non-target burn), the wall burned through (a perforation, major).
    #[test]
    fn each_dissection_event_counts_exactly_when_made() {
        let nothing: Vec<Vec<f64>> = vec![vec![]; 3];
        let (done, made, scored) = outcome(dissection(0.95, vec![], None));
        assert_eq!(
            (done, made),
            (vec![Some(60.0), Some(60.0)], nothing.clone())
        );
        assert_eq!((scored.score, scored.major_error), (100.0, false));

        let (done, made, scored) = outcome(dissection(0.5, vec![], None));
        assert_eq!((done, made), (vec![None, None], nothing));
        assert_eq!(scored.score, 0.0);

        let burns = vec![burn("gallbladder", 20.0, false), burn("liver", 25.0, true)];
        let (_, made, scored) = outcome(dissection(0.95, burns, None));
        assert_eq!(made, [vec![], vec![25.0], vec![20.0, 25.0]]);
        assert_eq!(scored.points, 40.0 - 10.0 - 2.0 * 2.0);
        assert_eq!(scored.score, 100.0 * 26.0 / 40.0);

        let hole = burn("gallbladder", 30.0, true);
        let (_, made, scored) = outcome(dissection(0.95, vec![], Some(hole)));
        assert_eq!(made, [vec![30.0], vec![], vec![]]);
        assert!(scored.major_error);
        assert_eq!(
            scored.feedback(),
            [
                "30.0 s: gallbladder perforated, the gallbladder at (0, 0, 0) mm (−20 points, a major error)"
            ]
        );
    }
}
