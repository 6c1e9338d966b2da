//! The `ClipAndCut` task over constructed ticks: a competent sequence (the critical view,
//! then two clips on the patient's side and one on the gallbladder's across each tube, cut
//! between) completes without a mistake; a careless one (a clip and a cut before the view, a
//! stump left open) scores lower, its mistakes named in time order; dividing the
//! common bile duct ends the attempt as a complication. And the scenario's biliary tree and
//! its instruments refused where they are wrong, at their line and field.

use std::path::Path;

use pgd_surgery_core::biliary::{BiliaryTree, Clip, Division, Segment, Structure};
use pgd_surgery_core::scenario::tasks::ClipAndCutResult;
use pgd_surgery_core::scenario::{
    BiliarySample, Exercise, Sample, Scenario, Sites, ViewSample, parse, score,
};

pub const INSTRUMENTS: &str = r#"instruments: [
        Instrument(tool: ClipApplier(tip_radius_mm: 6.0), port: Port(at_mm: (60.0, 139.0, -120.0), shaft_mm: 300.0)),
        Instrument(tool: Scissors(tip_radius_mm: 6.0), port: Port(at_mm: (60.0, 139.0, -120.0), shaft_mm: 300.0)),
    ],"#;

pub fn scenario_text(biliary: &str, instruments: &str, divide: &str) -> String {
    format!(
        r#"Scenario(
    title: "Clip and cut",
    briefing: "Clip and divide the cystic duct and artery.",
    organs: ["liver", "gallbladder", "duodenum"],
    {instruments}
    {biliary}
    tasks: [
        ClipAndCut(organ: "gallbladder", {divide}max_force_n: 2.0, time_limit_s: 120.0),
    ],
)"#
    )
}

fn scenario() -> Scenario {
    let text = scenario_text("biliary: Biliary(),", INSTRUMENTS, "");
    parse(Path::new("clip.scenario.ron"), &text).unwrap()
}

/// Jaws square across `structure` at `share` of its length, `jaw_m` long, centred on it.
fn jaws(tree: &BiliaryTree, structure: Structure, share: f64, jaw_m: f64) -> Segment {
    let tube = tree.tube(structure);
    let at = share * tube.length_m();
    let centre = tube.point_at(at);
    let axis = (tube.point_at(at + 1e-3) - tube.point_at(at - 1e-3)).normalize();
    let across = axis.cross(&nalgebra::Vector3::y()).normalize();
    Segment::new(
        centre - across * (jaw_m / 2.0),
        centre + across * (jaw_m / 2.0),
    )
}

/// What happens at a tick: the view reached, a clip at a share of a tube, a cut there.
#[derive(Clone, Copy)]
pub enum Event {
    View,
    Clip(Structure, f64),
    Cut(Structure, f64),
}

/// Runs `events` (each at its second) through the scenario's exercise, the tree's clips
/// and cuts made as the haptic loop makes them; 60 s in all.
fn run(events: &[(f64, Event)]) -> (Scenario, Vec<pgd_surgery_core::scenario::task::TaskMetrics>) {
    run_on(scenario(), events)
}

/// [`run`] on `scenario` (a clip-and-cut on the default tree).
pub fn run_on(
    scenario: Scenario,
    events: &[(f64, Event)],
) -> (Scenario, Vec<pgd_surgery_core::scenario::task::TaskMetrics>) {
    let tree = scenario.biliary.as_ref().unwrap().tree().unwrap();
    let mut exercise = Exercise::new(scenario, Sites::default());
    let mut clips: Vec<Clip> = Vec::new();
    let mut view = ViewSample::default();
    let mut blood_lost_m3 = 0.0;
    let mut leaks = Vec::new();
    for tick in 0..60_000u32 {
        let time_s = f64::from(tick) * 1e-3;
        let mut biliary = BiliarySample::default();
        for &(at_s, event) in events {
            if (at_s * 1e3).round() as u32 != tick {
                continue;
            }
            match event {
                Event::View => {
                    view = ViewSample {
                        triangle_cleared: 1.0,
                        lower_third_released: 1.0,
                        entering: 2,
                        seen: 2,
                        reached: true,
                    }
                }
                Event::Clip(s, share) => {
                    let clip = Clip::place(&tree, &jaws(&tree, s, share, 9e-3)).unwrap();
                    clips.push(clip);
                    biliary.clip = Some(clip);
                }
                Event::Cut(s, share) => {
                    let (division, open) =
                        Division::cut(&tree, &clips, &jaws(&tree, s, share, 15e-3)).unwrap();
                    leaks.extend(open.into_iter().flatten());
                    biliary.division = Some(division);
                }
            }
        }
        for leak in &mut leaks {
            leak.advance(1e-3);
        }
        blood_lost_m3 = leaks
            .iter()
            .map(|l| l.lost_m3)
            .sum::<f64>()
            .max(blood_lost_m3);
        biliary.view = view;
        biliary.blood_lost_m3 = blood_lost_m3;
        exercise.step(&Sample {
            time_s,
            biliary,
            ..Sample::default()
        });
        if exercise.finished() {
            break;
        }
    }
    let finished = exercise.finish();
    (finished.scenario, finished.tasks)
}

pub const DUCT: Structure = Structure::CysticDuct;
pub const ARTERY: Structure = Structure::CysticArtery;

/// A clip and a cut on the duct before the view, the artery cut with one clip on the
/// gallbladder's side only.
pub fn careless() -> Vec<(f64, Event)> {
    vec![
        (3.0, Event::Clip(DUCT, 0.2)),
        (4.0, Event::Cut(DUCT, 0.6)),
        (5.0, Event::View),
        (8.0, Event::Clip(ARTERY, 0.8)),
        (9.0, Event::Cut(ARTERY, 0.5)),
    ]
}

pub fn competent() -> Vec<(f64, Event)> {
    vec![
        (5.0, Event::View),
        (8.0, Event::Clip(DUCT, 0.2)),
        (9.0, Event::Clip(DUCT, 0.35)),
        (10.0, Event::Clip(DUCT, 0.8)),
        (12.0, Event::Cut(DUCT, 0.6)),
        (15.0, Event::Clip(ARTERY, 0.2)),
        (16.0, Event::Clip(ARTERY, 0.35)),
        (17.0, Event::Clip(ARTERY, 0.8)),
        (19.0, Event::Cut(ARTERY, 0.6)),
    ]
}

#[test]
fn a_competent_clip_and_cut_completes_without_a_mistake() {
    let (scenario, metrics) = run(&competent());
    let m = &metrics[0];
    assert!(m.completed, "{m:#?}");
    assert!(m.errors.is_empty(), "{:?}", m.errors);
    let result = m.result::<ClipAndCutResult>().unwrap();
    assert_eq!(result.view_reached_s, Some(5.0));
    assert_eq!((result.cystic_duct_clips, result.artery_clips), (3, 3));
    assert_eq!(result.blood_lost_ml, 0.0);
    assert!(score(&scenario, metrics).score > 0.0);
}

/// A clip and a cut on the duct before the view, the artery cut with one clip on the
/// gallbladder's side only: its patient stump bleeds.
#[test]
fn a_careless_clip_and_cut_names_its_mistakes_in_time_order_and_scores_lower() {
    let (scenario, metrics) = run(&careless());
    let m = &metrics[0];
    assert_eq!(
        m.errors,
        [
            "3.00 s: placed a clip before the critical view of safety",
            "4.00 s: divided a structure before the critical view of safety",
            "4.00 s: divided a structure with a stump left open",
            "9.00 s: divided a structure with a stump left open",
        ]
    );
    let result = m.result::<ClipAndCutResult>().unwrap();
    assert!(result.blood_lost_ml > 1.0, "{}", result.blood_lost_ml);
    let careless_card = score(&scenario, metrics);
    let (scenario, metrics) = run(&competent());
    let competent_card = score(&scenario, metrics);
    assert!(
        careless_card.score < competent_card.score,
        "{} against {}",
        careless_card.score,
        competent_card.score
    );
    assert!(!careless_card.passed);
}

/// The common bile duct divided, even between clips, is a bile duct injury: the task ends
/// there, not completed, and the attempt fails with the complication named.
#[test]
fn dividing_the_common_bile_duct_ends_the_attempt() {
    let scenario = scenario();
    let tree = scenario.biliary.as_ref().unwrap().tree().unwrap();
    let share = (tree.junction_arc_m() + 6e-3) / tree.tube(Structure::CommonDuct).length_m();
    let (scenario, metrics) = run(&[
        (5.0, Event::View),
        (6.0, Event::Cut(Structure::CommonDuct, share)),
    ]);
    let m = &metrics[0];
    assert!(!m.completed);
    assert!(
        m.time_s < 7.0,
        "the task ended at the injury, not at its limit: {}",
        m.time_s
    );
    let card = score(&scenario, metrics);
    assert!(!card.passed);
    let said = format!("{card:?}");
    assert!(
        said.contains("a bile duct injury: the common bile duct divided at 6.0 s"),
        "{said}"
    );
}

#[test]
fn wrong_biliary_trees_and_instruments_are_refused_at_their_field() {
    let file = Path::new("clip.scenario.ron");
    let error = |text: String| parse(file, &text).unwrap_err();

    let long = error(scenario_text(
        "biliary: Biliary(anatomy: Anatomy(cystic_duct_mm: 60.0)),",
        INSTRUMENTS,
        "",
    ));
    assert_eq!(long.field, "biliary.anatomy.cystic_duct_mm");
    assert_eq!(long.line, 9, "{long}");
    assert!(long.hint.contains("from 16 to 40"), "{long}");

    let press = scenario_text("", INSTRUMENTS, "").replace(
        r#"ClipAndCut(organ: "gallbladder", "#,
        r#"ForceControl(organ: "liver", min_force_n: 0.1, hold_s: 1.0, "#,
    );
    let unclippable = error(press);
    assert!(
        unclippable
            .message
            .contains("a clip applier needs a duct or an artery to clip"),
        "{unclippable}"
    );
    assert_eq!(unclippable.line, 6, "{unclippable}");

    let common = error(scenario_text(
        "biliary: Biliary(),",
        INSTRUMENTS,
        "divide: [CysticDuct, CommonDuct], ",
    ));
    assert_eq!(common.field, "tasks[0].divide");
    assert!(common.message.contains("never divided"), "{common}");

    let unknown = error(scenario_text(
        "biliary: Biliary(),",
        INSTRUMENTS,
        "divide: [CysticDuct, HepaticArtery], ",
    ));
    assert!(unknown.message.contains("HepaticArtery"), "{unknown}");
    assert!(
        unknown.hint.contains("CysticArtery") || unknown.message.contains("CysticArtery"),
        "{unknown}"
    );

    let share = error(scenario_text(
        "biliary: Biliary(critical_view: CriticalView(triangle_cleared: 1.5)),",
        INSTRUMENTS,
        "",
    ));
    assert_eq!(share.field, "biliary.critical_view.triangle_cleared");
}
