//! Free an organ from its bed: divide the connective tissue that ties it with the hook's
//! energy (or tear it by pulling), without burning the organs themselves.

use serde::{Deserialize, Serialize};

use crate::dissection::MAX_BURN_MARKS;
use crate::scenario::sample::{HookTarget, WallSample};
use crate::scenario::task::{
    RunSetup, TaskCheck, TaskProgress, TaskResult, TaskRun, TaskShared, TaskType, Tick,
};
use crate::scenario::units::ReleaseShare;

/// `Dissection(organ, release_share, max_force_n, time_limit_s)`: release `release_share`
/// of the connective tissue that binds `organ` (an `Attachment` of the scenario's) with an
/// electrocautery hook. Energy on an organ's wall instead of the ties is a non-target burn,
/// through the capsule of a solid organ a capsule injury; burning through a hollow organ's
/// wall perforates it, which spills its contents and fails the attempt; energy with the
/// hook on no tissue is an error.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dissection {
    pub release_share: ReleaseShare,
}

/// A burn of an organ's wall: the mistake's amount is its area (mm²).
const BURN: u16 = 0;
/// A solid organ's capsule burned through.
const CAPSULE: u16 = 1;
/// A burst of energy with the hook on nothing: the amount is its energy (J).
const IN_AIR: u16 = 2;

impl TaskType for Dissection {
    const NAME: &'static str = "Dissection";
    const LABEL: &'static str = "dissection";
    const FORCE_VERB: &'static str = "pulled or pressed";
    type Run = DissectionRun;

    fn description(&self, shared: &TaskShared) -> String {
        format!(
            "free the {} from its bed: divide {:.0} % of the connective tissue with the hook, \
             without burning the organs, under {} N",
            shared.organ.as_deref().unwrap_or_default(),
            100.0 * self.release_share.0,
            shared.max_force_n
        )
    }

    fn check(&self, check: &mut TaskCheck<'_>) {
        if !check.scene.hook {
            check.problem(
                "organ",
                "a Dissection task needs an electrocautery hook to dissect with",
                "add an instrument with tool: Hook(tip_radius_mm: 6.0, power_w: 30.0, mode: Cut)",
            );
        }
        let organ = check.organ_name();
        if !check.scene.attachments.iter().any(|a| a.organ == organ) {
            let message = format!("the {organ} is not attached to anything to free it from");
            let hint = format!("add attachments: [Attachment(organ: \"{organ}\", to: \"liver\")]");
            check.problem("organ", message, hint);
        }
    }

    fn run(&self, _: &TaskShared, setup: RunSetup) -> DissectionRun {
        DissectionRun {
            organ_names: setup.organ_names,
            target_share: self.release_share.0,
            released_share: 0.0,
            burns: Vec::with_capacity(MAX_BURN_MARKS),
            energy: EnergySpent::default(),
            in_air_burst_j: 0.0,
            ties_divided: 0,
            ties_torn: 0,
            perforation: None,
        }
    }

    fn describe_mistake(&self, _: &TaskShared, code: u16, amount: f64) -> String {
        match code {
            BURN => {
                format!("burned an organ's wall instead of the connective tissue ({amount:.1} mm²)")
            }
            CAPSULE => "burned through an organ's capsule".to_owned(),
            _ => format!("applied energy with the hook on no tissue ({amount:.2} J)"),
        }
    }
}

/// Where the hook's energy went over the task (J).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EnergySpent {
    pub total_j: f64,
    pub on_ties_j: f64,
    pub on_walls_j: f64,
    pub in_air_j: f64,
}

/// A burn mark the hook left on an organ, where it was first made.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Burn {
    /// The mark in the scene's list of marks.
    mark: usize,
    time_s: f64,
    organ: usize,
    at_mm: [f64; 3],
    area_m2: f64,
    /// Through the capsule of a solid organ.
    capsule: bool,
}

#[derive(Clone, Debug)]
pub struct DissectionRun {
    organ_names: Vec<String>,
    target_share: f64,
    released_share: f64,
    /// Room for every mark the scene keeps, reserved before the exercise starts.
    burns: Vec<Burn>,
    energy: EnergySpent,
    /// The energy of the burst with the hook on nothing under way (J).
    in_air_burst_j: f64,
    ties_divided: u32,
    ties_torn: u32,
    /// When and where a hollow organ's wall was burned through.
    perforation: Option<Burn>,
}

impl DissectionRun {
    /// A burn on a wall: a mark of its own is a non-target burn; a hollow wall burned
    /// through is a perforation, a capsule a capsule injury.
    fn burned(&mut self, tick: &mut Tick<'_>, wall: &WallSample) {
        let sample = tick.sample;
        let at_mm = sample.tip_m.map_or([0.0; 3], |tip| (tip * 1e3).into());
        let burn = Burn {
            mark: wall.mark,
            time_s: sample.time_s,
            organ: wall.organ,
            at_mm,
            area_m2: wall.area_m2,
            capsule: false,
        };
        if wall.new_mark {
            tick.mistake(BURN, wall.area_m2 * 1e6);
            if self.burns.len() < self.burns.capacity() {
                self.burns.push(burn);
            }
        }
        if !wall.through_now {
            return;
        }
        match wall.hollow {
            true => {
                self.perforation.get_or_insert(burn);
            }
            false => {
                tick.mistake(CAPSULE, 0.0);
                let burned = self.burns.iter_mut().find(|b| b.mark == wall.mark);
                if let Some(mark) = burned {
                    mark.capsule = true;
                }
            }
        }
    }

    /// Ends a burst of energy in the air, noting it.
    fn end_burst(&mut self, tick: &mut Tick<'_>) {
        if self.in_air_burst_j > 0.0 {
            tick.mistake(IN_AIR, self.in_air_burst_j);
            self.in_air_burst_j = 0.0;
        }
    }
}

impl TaskRun for DissectionRun {
    type Result = DissectionResult;

    /// Done once the share of the attachment is released without a perforation.
    fn step(&mut self, tick: &mut Tick<'_>) {
        let hook = tick.sample.hook;
        self.energy.total_j += hook.energy_j;
        match hook.on {
            HookTarget::Off => self.end_burst(tick),
            HookTarget::Ties { divided, .. } => {
                self.end_burst(tick);
                self.energy.on_ties_j += hook.energy_j;
                self.ties_divided += divided;
            }
            HookTarget::Wall(wall) => {
                self.end_burst(tick);
                self.energy.on_walls_j += hook.energy_j;
                self.burned(tick, &wall);
            }
            HookTarget::Air => {
                self.energy.in_air_j += hook.energy_j;
                self.in_air_burst_j += hook.energy_j;
            }
        }
        self.ties_torn += tick.sample.ties_torn;
        self.released_share = tick.sample.released_share;
        tick.metrics.completed =
            self.released_share >= self.target_share && self.perforation.is_none();
    }

    fn over(&self) -> bool {
        self.perforation.is_some()
    }

    fn progress(&self) -> Option<TaskProgress> {
        Some(TaskProgress {
            what: "released",
            done: 100.0 * self.released_share,
            of: 100.0 * self.target_share,
            unit: "%",
        })
    }

    fn result(&self) -> DissectionResult {
        let name = |organ: usize| self.organ_names.get(organ).cloned().unwrap_or_default();
        let made = |burn: &Burn| BurnMade {
            organ: name(burn.organ),
            time_s: burn.time_s,
            at_mm: burn.at_mm,
            area_mm2: burn.area_m2 * 1e6,
            through_capsule: burn.capsule,
        };
        DissectionResult {
            released_share: self.released_share,
            target_share: self.target_share,
            ties_divided: self.ties_divided,
            ties_torn: self.ties_torn,
            burns: self.burns.iter().map(made).collect(),
            burned_area_mm2: (self.burns.iter()).fold(0.0, |sum, b| sum + b.area_m2 * 1e6),
            capsule_injuries: self.burns.iter().filter(|b| b.capsule).count(),
            perforation: self.perforation.as_ref().map(made),
            energy: self.energy,
        }
    }
}

/// A burn as the report lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BurnMade {
    pub organ: String,
    pub time_s: f64,
    /// Where the hook's tip was (mm, the scene's frame).
    pub at_mm: [f64; 3],
    pub area_mm2: f64,
    pub through_capsule: bool,
}

/// A dissection's measures: how much was released, the burns and where the energy went.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DissectionResult {
    pub released_share: f64,
    pub target_share: f64,
    pub ties_divided: u32,
    /// Ties torn by the grasper's pull (blunt dissection).
    pub ties_torn: u32,
    /// The non-target burns, in order.
    pub burns: Vec<BurnMade>,
    pub burned_area_mm2: f64,
    pub capsule_injuries: usize,
    /// The hollow organ's wall burned through: its contents spilled.
    pub perforation: Option<BurnMade>,
    pub energy: EnergySpent,
}

impl TaskResult for DissectionResult {
    /// The share of the attachment released, of what was asked.
    fn accuracy(&self) -> Option<f64> {
        Some((self.released_share / self.target_share).clamp(0.0, 1.0))
    }

    fn unfinished(&self) -> Option<String> {
        Some(format!(
            " ({:.0} % of the attachment released of {:.0} %)",
            100.0 * self.released_share,
            100.0 * self.target_share
        ))
    }

    fn feedback(&self) -> Vec<String> {
        let at = |b: &BurnMade| {
            let [x, y, z] = b.at_mm;
            format!("at ({x:.0}, {y:.0}, {z:.0}) mm, {:.1} s", b.time_s)
        };
        let mut lines: Vec<String> = (self.burns.iter())
            .map(|b| {
                let capsule = if b.through_capsule {
                    ", through its capsule"
                } else {
                    ""
                };
                format!("burned the {} {}{capsule}", b.organ, at(b))
            })
            .collect();
        if self.energy.in_air_j > 0.0 {
            lines.push(format!(
                "{:.2} J applied with the hook on no tissue",
                self.energy.in_air_j
            ));
        }
        lines
    }

    fn summary(&self) -> Vec<String> {
        let e = &self.energy;
        vec![format!(
            "released {:.0} % of the attachment (target {:.0} %), {} ties divided, {} torn; {} \
             non-target burns ({:.1} mm², {} through a capsule); energy {:.1} J: {:.1} J on the \
             ties, {:.1} J on the organs, {:.2} J on no tissue",
            100.0 * self.released_share,
            100.0 * self.target_share,
            self.ties_divided,
            self.ties_torn,
            self.burns.len(),
            self.burned_area_mm2,
            self.capsule_injuries,
            e.total_j,
            e.on_ties_j,
            e.on_walls_j,
            e.in_air_j
        )]
    }

    fn complication(&self) -> Option<String> {
        self.perforation.as_ref().map(|p| {
            let [x, y, z] = p.at_mm;
            let spilled = match p.organ.as_str() {
                "gallbladder" => "bile spilled",
                _ => "its contents spilled",
            };
            format!(
                "{:.2} s: burned through the {}'s wall at ({x:.0}, {y:.0}, {z:.0}) mm: a \
                 perforation, {spilled}",
                p.time_s, p.organ
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::scenario::sample::{HookSample, HookTarget, Sample, WallSample};
    use crate::scenario::{Exercise, Finished, Sites, parse, score};

    use super::DissectionResult;

    const SCENARIO: &str = r#"Scenario(title: "t", briefing: "b", organs: ["liver", "gallbladder"],
        tool: Hook(tip_radius_mm: 6.0, power_w: 30.0),
        attachments: [Attachment(organ: "gallbladder", to: "liver")],
        tasks: [Dissection(organ: "gallbladder", release_share: 0.5, max_force_n: 2.0,
                           time_limit_s: 10.0)])"#;

    /// A tick at `time_s` whose hook delivered 30 mJ to `on`, with `released` of the bed.
    fn tick(time_s: f64, on: HookTarget, released: f64) -> Sample {
        let energy_j = if on == HookTarget::Off { 0.0 } else { 0.03 };
        Sample {
            time_s,
            hook: HookSample { energy_j, on },
            released_share: released,
            ..Sample::default()
        }
    }

    fn wall(organ: usize, mark: usize, new_mark: bool, through_now: bool) -> HookTarget {
        HookTarget::Wall(WallSample {
            organ,
            mark,
            new_mark,
            area_m2: 0.785e-6,
            through_now,
            hollow: organ == 1,
        })
    }

    /// Energy on no tissue for 0.1 s (one error, its energy), a burn of the liver whose second
    /// tick goes through its capsule (a burn and a capsule injury, on that mark), ties
    /// divided and torn to half the bed: done, the energy apportioned, the burn listed with
    /// its organ, the torn ties counted apart from the divided ones.
    #[test]
    fn a_dissection_counts_its_burns_and_its_energy() {
        let scenario = parse(Path::new("t.scenario.ron"), SCENARIO).unwrap();
        let mut exercise = Exercise::new(scenario, Sites::default());
        let mut samples = Vec::new();
        samples.extend((0..100).map(|k| tick(k as f64 * 1e-3, HookTarget::Air, 0.0)));
        samples.push(tick(0.1, HookTarget::Off, 0.0));
        samples.push(tick(0.2, wall(0, 0, true, false), 0.0));
        samples.push(tick(0.201, wall(0, 0, false, true), 0.0));
        samples.push(tick(
            0.3,
            HookTarget::Ties {
                heated: 2,
                divided: 1,
            },
            0.3,
        ));
        samples.push(Sample {
            ties_torn: 3,
            ..tick(0.35, HookTarget::Off, 0.4)
        });
        samples.push(tick(
            0.4,
            HookTarget::Ties {
                heated: 1,
                divided: 1,
            },
            0.5,
        ));
        for sample in &samples {
            exercise.step(sample);
        }
        assert!(exercise.finished());
        let Finished {
            scenario,
            tasks: metrics,
            ..
        } = exercise.finish();
        let m = &metrics[0];
        let done = m.result::<DissectionResult>().unwrap();
        assert!(m.completed, "{m:#?}");
        assert_eq!((done.ties_divided, done.ties_torn), (2, 3));
        assert_eq!(done.burns.len(), 1);
        assert_eq!(
            (done.burns[0].organ.as_str(), done.capsule_injuries),
            ("liver", 1)
        );
        assert!(done.perforation.is_none());
        assert!(
            (done.energy.in_air_j - 3.0).abs() < 1e-9,
            "{:?}",
            done.energy
        );
        assert!((done.energy.on_walls_j - 0.06).abs() < 1e-9);
        assert!((done.energy.on_ties_j - 0.06).abs() < 1e-9);
        assert_eq!(m.errors.len(), 3, "{:?}", m.errors);
        let card = score(&scenario, metrics);
        assert!(card.feedback.iter().any(|l| l.contains("burned the liver")));
    }

    /// Burned through the gallbladder's wall: the task ends there, not done, and the attempt
    /// fails whatever its score, saying where and that bile spilled.
    #[test]
    fn a_perforation_ends_the_task_and_fails_the_attempt() {
        let scenario = parse(Path::new("t.scenario.ron"), SCENARIO).unwrap();
        let mut exercise = Exercise::new(scenario, Sites::default());
        exercise.step(&tick(
            0.0,
            HookTarget::Ties {
                heated: 1,
                divided: 1,
            },
            0.4,
        ));
        exercise.step(&Sample {
            tip_m: Some(nalgebra::Vector3::new(0.04, 0.03, -0.06)),
            ..tick(0.1, wall(1, 0, true, true), 0.4)
        });
        assert!(exercise.finished());
        let Finished {
            scenario,
            tasks: metrics,
            ..
        } = exercise.finish();
        assert!(!metrics[0].completed);
        let card = score(&scenario, metrics);
        assert!(!card.passed);
        let complication = card.feedback.join("\n");
        assert!(
            complication.contains("burned through the gallbladder's wall at (40, 30, -60) mm: a perforation, bile spilled"),
            "{complication}"
        );
    }
}
