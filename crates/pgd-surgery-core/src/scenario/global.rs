//! An attempt's global measures, in the spirit of the GOALS scale (Global Operative
//! Assessment of Laparoscopic Skills, Vassiliou et al. 2005, Am J Surg 190:107–113), whose
//! observer rates depth perception, bimanual dexterity, efficiency, tissue handling and
//! autonomy from 1 to 5. The trainer rates nothing: it measures what each domain is about over
//! the whole attempt, and compares it with the scenario's benchmark, as LAP Mentor's
//! proficiency benchmarks are set from experienced surgeons' runs. Autonomy needs an
//! observer, and is left out.

use serde::{Deserialize, Serialize};

use super::motion::MotionMetrics;
use super::task::{TaskMetrics, results_of};
use super::tasks::{ClipAndCutResult, DissectionResult};

/// What the attempt measured, by GOALS domain.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GlobalMeasures {
    /// Depth perception: the time the instruments' tips (both hands') were out of the
    /// camera's view (s), and the movements they made (fewer, purposeful ones where the
    /// target is reached without overshooting).
    pub out_of_view_s: f64,
    pub movements: usize,
    /// Bimanual dexterity: the share of the time with tissue in hand that both hands worked
    /// (bimanual tasks, weighted by their time on tissue), and the share of the
    /// counter-traction's time it was held in its band; none without such tasks.
    pub both_hands_share: Option<f64>,
    pub countertraction_share: Option<f64>,
    /// Efficiency: the attempt's time (s), each hand's tip path (mm, right then left) and
    /// economy (path over the shortest that does the same; 1 is no wasted motion).
    pub time_s: f64,
    pub path_mm: [f64; 2],
    pub economy: [Option<f64>; 2],
    /// Tissue handling: the time above the tasks' force limits (s), the peak force (N), the
    /// times the holding hand let go, the non-target burns and their area (mm²), blood lost
    /// and bile spilled (ml).
    pub over_limit_s: f64,
    pub peak_force_n: f64,
    pub grasps_lost: u32,
    pub burns: usize,
    pub burned_area_mm2: f64,
    pub blood_lost_ml: f64,
    pub bile_spilled_ml: f64,
}

impl GlobalMeasures {
    /// The measures of an attempt's `tasks`.
    pub fn of(tasks: &[TaskMetrics]) -> Self {
        let hands = |m: &TaskMetrics| match &m.hands {
            Some(h) => [h.right.clone(), h.left.clone()],
            None => [m.motion.clone(), MotionMetrics::default()],
        };
        let motions: Vec<[MotionMetrics; 2]> = tasks.iter().map(hands).collect();
        let per_hand = |k: usize| motions.iter().map(move |m| &m[k]);
        let clips = || results_of::<ClipAndCutResult>(tasks);
        let dissections = || results_of::<DissectionResult>(tasks);
        Self {
            out_of_view_s: motions
                .iter()
                .flatten()
                .filter_map(|m| m.out_of_view_s)
                .sum(),
            movements: motions.iter().flatten().map(|m| m.movements).sum(),
            both_hands_share: both_hands_share(tasks),
            countertraction_share: countertraction_share(tasks),
            time_s: (tasks.iter().map(|m| m.started_s + m.time_s)).fold(0.0, f64::max),
            path_mm: [0, 1].map(|k| per_hand(k).map(|m| m.path_length_mm).sum()),
            economy: [0, 1].map(|k| economy(per_hand(k))),
            over_limit_s: tasks.iter().map(|m| m.time_over_limit_s).sum(),
            peak_force_n: tasks.iter().map(|m| m.peak_force_n).fold(0.0, f64::max),
            grasps_lost: (tasks.iter().filter_map(|m| m.countertraction.as_ref()))
                .map(|c| c.let_go)
                .sum(),
            burns: dissections().map(|r| r.burns.len()).sum(),
            burned_area_mm2: dissections().map(|r| r.burned_area_mm2).sum(),
            blood_lost_ml: clips().map(|r| r.blood_lost_ml).sum(),
            bile_spilled_ml: clips().map(|r| r.bile_spilled_ml).sum(),
        }
    }
}

/// The whole path over the whole shortest path, over the tasks where the tip left its start.
fn economy<'a>(motions: impl Iterator<Item = &'a MotionMetrics>) -> Option<f64> {
    let (path_mm, shortest_mm) = motions
        .filter_map(|m| m.economy.map(|e| (m.path_length_mm, m.path_length_mm / e)))
        .fold((0.0, 0.0), |(p, s), (path, shortest)| {
            (p + path, s + shortest)
        });
    (shortest_mm > 0.0).then(|| path_mm / shortest_mm)
}

fn both_hands_share(tasks: &[TaskMetrics]) -> Option<f64> {
    let (working_s, both_s) = (tasks.iter().filter_map(|m| m.hands.as_ref()))
        .fold((0.0, 0.0), |(w, b), h| {
            (w + h.working_s, b + h.both_working_s)
        });
    (working_s > 0.0).then(|| both_s / working_s)
}

fn countertraction_share(tasks: &[TaskMetrics]) -> Option<f64> {
    let (in_band_s, total_s) =
        (tasks.iter().filter_map(|m| m.countertraction.as_ref())).fold((0.0, 0.0), |(i, t), c| {
            let total = c.in_band_s + c.slack_s + c.over_s + c.not_held_s;
            (i + c.in_band_s, t + total)
        });
    (total_s > 0.0).then(|| in_band_s / total_s)
}

/// A scenario's proficiency benchmark (`benchmark: Benchmark(…)`): the values an attempt is
/// held to, each left out if not held to. LAP Mentor's were set from the best quartile of
/// experienced surgeons' runs, its safety measures at 95 % correct.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Benchmark {
    /// The score, at least (0–100).
    pub score: Option<f64>,
    /// The attempt's time, at most (s).
    pub time_s: Option<f64>,
    /// Both hands' tip paths together, at most (mm).
    pub path_mm: Option<f64>,
    /// The tips out of the camera's view, at most (s).
    pub out_of_view_s: Option<f64>,
    /// The share of the time on tissue both hands worked, at least (0–1).
    pub both_hands_share: Option<f64>,
    /// Time above the force limits, at most (s).
    pub over_limit_s: Option<f64>,
    /// Non-target burns, at most.
    pub burns: Option<usize>,
    /// Blood lost, at most (ml).
    pub blood_lost_ml: Option<f64>,
}

/// One benchmark value against the attempt's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchmarkLine {
    pub measure: &'static str,
    pub value: f64,
    pub benchmark: f64,
    /// Whether the benchmark is a floor (the value must reach it) rather than a ceiling.
    pub at_least: bool,
    pub met: bool,
}

/// One value a benchmark can hold: its field in the scenario, its name in the debrief, the
/// value given, whether it is a floor rather than a ceiling, the largest it may be (the
/// smallest is 0), and the attempt's value it is held against.
pub(super) struct Limit {
    pub(super) field: &'static str,
    measure: &'static str,
    pub(super) benchmark: Option<f64>,
    at_least: bool,
    pub(super) most: f64,
    attempt: fn(&GlobalMeasures, f64) -> f64,
}

impl Benchmark {
    /// Every value a benchmark can hold, with this one's given where it gives them.
    pub(super) fn limits(&self) -> [Limit; 8] {
        let limit = |field, measure, benchmark, at_least, most, attempt| Limit {
            field,
            measure,
            benchmark,
            at_least,
            most,
            attempt,
        };
        let any = f64::MAX;
        [
            limit("score", "score", self.score, true, 100.0, |_, score| score),
            limit("time_s", "time (s)", self.time_s, false, any, |m, _| {
                m.time_s
            }),
            limit(
                "path_mm",
                "path, both hands (mm)",
                self.path_mm,
                false,
                any,
                |m, _| m.path_mm[0] + m.path_mm[1],
            ),
            limit(
                "out_of_view_s",
                "out of view (s)",
                self.out_of_view_s,
                false,
                any,
                |m, _| m.out_of_view_s,
            ),
            limit(
                "both_hands_share",
                "both hands together",
                self.both_hands_share,
                true,
                1.0,
                |m, _| m.both_hands_share.unwrap_or(0.0),
            ),
            limit(
                "over_limit_s",
                "above the force limits (s)",
                self.over_limit_s,
                false,
                any,
                |m, _| m.over_limit_s,
            ),
            limit(
                "burns",
                "non-target burns",
                self.burns.map(|b| b as f64),
                false,
                any,
                |m, _| m.burns as f64,
            ),
            limit(
                "blood_lost_ml",
                "blood lost (ml)",
                self.blood_lost_ml,
                false,
                any,
                |m, _| m.blood_lost_ml,
            ),
        ]
    }

    /// Each value the benchmark holds, against the attempt's `measures` and `score`.
    pub fn compare(&self, measures: &GlobalMeasures, score: f64) -> Vec<BenchmarkLine> {
        (self.limits().into_iter())
            .filter_map(|limit| {
                let benchmark = limit.benchmark?;
                let value = (limit.attempt)(measures, score);
                Some(BenchmarkLine {
                    measure: limit.measure,
                    value,
                    benchmark,
                    at_least: limit.at_least,
                    met: if limit.at_least {
                        value >= benchmark
                    } else {
                        value <= benchmark
                    },
                })
            })
            .collect()
    }
}

impl BenchmarkLine {
    /// The line in words, for the debrief.
    pub fn describe(&self) -> String {
        let bound = if self.at_least { "at least" } else { "at most" };
        let verdict = if self.met { "met" } else { "not met" };
        format!(
            "benchmark {}: {:.2} against {bound} {:.2}, {verdict}",
            self.measure, self.value, self.benchmark
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::task::TaskOutcome;
    use crate::scenario::tasks::{BurnMade, EnergySpent};
    use crate::scenario::{BimanualMetrics, CountertractionMetrics};

    fn motion(
        path_length_mm: f64,
        shortest_mm: f64,
        out_s: f64,
        movements: usize,
    ) -> MotionMetrics {
        MotionMetrics {
            path_length_mm,
            economy: (shortest_mm > 0.0).then(|| path_length_mm / shortest_mm),
            movements,
            out_of_view_s: Some(out_s),
            ..MotionMetrics::default()
        }
    }

    fn burn(time_s: f64) -> BurnMade {
        BurnMade {
            organ: "liver".into(),
            time_s,
            at_mm: [0.0; 3],
            area_mm2: 4.0,
            through_capsule: false,
        }
    }

    /// A bimanual retraction (0–20 s), a one-handed clip-and-cut (20–60 s) that lost blood
    /// and spilled bile, a dissection (60–90 s) with two burns.
    fn attempt() -> Vec<TaskMetrics> {
        let retraction = TaskMetrics {
            time_s: 20.0,
            time_over_limit_s: 0.3,
            peak_force_n: 1.2,
            hands: Some(BimanualMetrics {
                right: motion(100.0, 50.0, 1.0, 3),
                left: motion(40.0, 25.0, 0.5, 2),
                working_s: 10.0,
                both_working_s: 6.0,
                idle_drift_mm: [0.0; 2],
            }),
            countertraction: Some(CountertractionMetrics {
                in_band_s: 8.0,
                slack_s: 1.0,
                over_s: 0.5,
                not_held_s: 0.5,
                let_go: 1,
            }),
            ..TaskMetrics::default()
        };
        let clip_and_cut = TaskMetrics {
            started_s: 20.0,
            time_s: 40.0,
            time_over_limit_s: 0.7,
            peak_force_n: 2.5,
            motion: motion(200.0, 50.0, 2.0, 5),
            outcome: Some(TaskOutcome::new(ClipAndCutResult {
                view_reached_s: None,
                clips: Vec::new(),
                divisions: Vec::new(),
                cystic_duct_clips: 0,
                artery_clips: 0,
                blood_lost_ml: 3.0,
                bile_spilled_ml: 1.0,
                still_bleeding: false,
                bile_duct_injury: false,
            })),
            ..TaskMetrics::default()
        };
        let dissection = TaskMetrics {
            started_s: 60.0,
            time_s: 30.0,
            motion: motion(0.0, 0.0, 0.0, 0),
            outcome: Some(TaskOutcome::new(DissectionResult {
                released_share: 1.0,
                target_share: 0.9,
                ties_divided: 10,
                ties_torn: 0,
                burns: vec![burn(65.0), burn(70.0)],
                burned_area_mm2: 8.0,
                capsule_injuries: 0,
                perforation: None,
                energy: EnergySpent::default(),
            })),
            ..TaskMetrics::default()
        };
        vec![retraction, clip_and_cut, dissection]
    }

    /// Each measure against its sum worked out by hand; the economy of a hand is its whole
    /// path over its whole shortest path, a task whose tip never left its start left out.
    #[test]
    fn the_measures_add_up_over_the_tasks_and_the_hands() {
        let m = GlobalMeasures::of(&attempt());
        assert_eq!((m.out_of_view_s, m.movements), (3.5, 10));
        assert_eq!(m.both_hands_share, Some(0.6));
        assert_eq!(m.countertraction_share, Some(0.8));
        assert_eq!((m.time_s, m.path_mm), (90.0, [300.0, 40.0]));
        assert_eq!(m.economy, [Some(3.0), Some(1.6)]);
        assert_eq!(
            (m.over_limit_s, m.peak_force_n, m.grasps_lost),
            (1.0, 2.5, 1)
        );
        assert_eq!((m.burns, m.burned_area_mm2), (2, 8.0));
        assert_eq!((m.blood_lost_ml, m.bile_spilled_ml), (3.0, 1.0));
        let none = GlobalMeasures::of(&[]);
        assert_eq!((none.both_hands_share, none.economy), (None, [None, None]));
    }

    /// A ceiling is met at its value and not above; a floor at its value and not below.
    #[test]
    fn benchmarks_are_met_at_their_value_and_not_past_it() {
        let measures = GlobalMeasures::of(&attempt());
        let benchmark = Benchmark {
            score: Some(80.0),
            time_s: Some(90.0),
            both_hands_share: Some(0.6),
            blood_lost_ml: Some(2.9),
            ..Benchmark::default()
        };
        let met = |score| -> Vec<(&str, bool)> {
            (benchmark.compare(&measures, score).into_iter())
                .map(|l| (l.measure, l.met))
                .collect()
        };
        assert_eq!(
            met(79.9),
            [
                ("score", false),
                ("time (s)", true),
                ("both hands together", true),
                ("blood lost (ml)", false)
            ]
        );
        assert!(met(80.0)[0].1);
        let line = &benchmark.compare(&measures, 80.0)[3];
        assert_eq!(
            line.describe(),
            "benchmark blood lost (ml): 3.00 against at most 2.90, not met"
        );
    }
}
