//! The whole cholecystectomy through the haptic loop: the assistant holds the fundus up, the
//! left hand retracts the infundibulum, the right hand clears the triangle to the critical
//! view, clips and divides the cystic duct and artery, changes back to the hook and frees the
//! gallbladder from its bed. The competent run passes the operation's rubric and meets its
//! benchmark; the careless run (a division before the view, burns on the liver) fails, its
//! debrief naming its errors in time order. The runs are made from the scene they run on.

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{
    Biliary, DeviceForce, HandTouches, HapticLoop, OrganBeds, OrganBody, OrganBurns, TRAINEE_HANDS,
    Tool,
};
use pgd_surgery::biliary::BiliaryTree;
use pgd_surgery::dissection::CauteryMode;
use pgd_surgery::mesh::organs::{Abdomen, Organ};
use pgd_surgery::scenario::tasks::DissectionResult;

use super::script::{Script, Stage};

const NAME: &str = "lap-chole-full";

/// The assistant's hand index: after the trainee's two.
const ASSISTANT: usize = TRAINEE_HANDS;

#[test]
fn the_competent_operation_earns_every_step_and_meets_the_benchmark() {
    let outcome = super::run(NAME, "competent");
    let card = &outcome.card;
    let operation = card.operation.as_ref().unwrap();
    eprintln!("{}", pgd_surgery::report::summary(card));
    let undone: Vec<&str> = (operation.steps.iter())
        .filter(|s| s.done_s.is_none())
        .map(|s| s.name.as_str())
        .collect();
    assert!(undone.is_empty(), "not done: {undone:?}");
    assert!(
        operation.errors.iter().all(|e| e.made.is_empty()),
        "{:?}",
        card.feedback
    );
    assert_eq!((operation.points, operation.possible), (100.0, 100.0));
    assert!(
        card.passed && card.proficient == Some(true),
        "{:?}",
        card.benchmark
    );
    let phases: Vec<&str> = card.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        phases,
        [
            "exposure",
            "hepatocystic triangle",
            "gallbladder off its bed"
        ]
    );
    assert!(card.phases.iter().all(|p| p.completed));
    assert!(
        (card.phases.windows(2)).all(|p| p[0].ended_s <= p[1].started_s),
        "{:?}",
        card.phases
    );
    let result = card.tasks[2].metrics.result::<DissectionResult>().unwrap();
    assert!(result.released_share >= 0.9, "{result:?}");
}

#[test]
fn the_careless_operation_fails_its_debrief_naming_its_errors_in_time_order() {
    let careless = super::run(NAME, "careless").card;
    let operation = careless.operation.as_ref().unwrap();
    eprintln!("{}", pgd_surgery::report::summary(&careless));
    let made = |name: &str| {
        (operation.errors.iter())
            .find(|e| e.name == name)
            .map_or(0, |e| e.made.len())
    };
    assert!(
        made("clip or division before the critical view") >= 3,
        "{operation:?}"
    );
    assert!(made("a stump left open") >= 1, "{operation:?}");
    assert!(made("burn of non-target tissue") >= 1, "{operation:?}");
    assert!(made("liver injury with bleeding") >= 1, "{operation:?}");
    assert!(!careless.passed && careless.proficient == Some(false));
    let times: Vec<f64> = (careless.feedback.iter())
        .filter_map(|line| line.split_once(" s: ")?.0.parse().ok())
        .collect();
    assert!(times.len() >= 6, "{:?}", careless.feedback);
    assert!(times.is_sorted(), "{:?}", careless.feedback);
    let liver = (careless.feedback.iter()).find(|l| l.contains("liver injury"));
    assert!(
        liver.is_some_and(|l| l.contains("liver")),
        "{:?}",
        careless.feedback
    );
}

/// The biliary tree as the loop `script` drives has it now.
fn live_tree(script: &mut Script) -> BiliaryTree {
    script.live().world().resource::<Biliary>().tree().clone()
}

/// The hook's reach in cut (m): its tip's radius and half its zone.
fn reach_m(tip_m: f64) -> f64 {
    tip_m + 0.5 * CauteryMode::Cut.zone_width_m()
}

/// The middles of the bed's ties still holding, where the last tick left them.
fn holding(haptic: &HapticLoop) -> Vec<Vector3<f64>> {
    let bed = &haptic.world().resource::<OrganBeds>().0[0];
    let law = bed.bed.law;
    (bed.bed.ties.iter().zip(bed.ends_m()))
        .filter(|(tie, _)| !tie.state.failed(&law))
        .map(|(_, ends)| ends.middle_m())
        .collect()
}

/// How many ties still holding lie within `within_m` of `at_m`.
fn ties_within(haptic: &HapticLoop, at_m: &Vector3<f64>, within_m: f64) -> usize {
    let near = |m: &Vector3<f64>| (m - at_m).norm() <= within_m;
    holding(haptic).iter().filter(|m| near(m)).count()
}

/// The right hand's instrument's tip.
fn right_tip_m(haptic: &HapticLoop) -> Vector3<f64> {
    haptic.hand::<Tool>(0).unwrap().sample.unwrap().tip_m
}

/// Where the hook goes to divide the ties around `middle_m`: within its reach of it, where
/// the tip keeps clearest of the organs at rest.
fn beside_tie(abdomen: &Abdomen, middle_m: &Vector3<f64>, reach_m: f64) -> Vector3<f64> {
    let clearance = |p: &Vector3<f64>| {
        [Organ::Liver, Organ::Gallbladder, Organ::Duodenum]
            .map(|o| abdomen.value(o, &(*p).into()))
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    };
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let n = 200;
    (0..n)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * k as f64;
            middle_m + Vector3::new(r * a.cos(), r * a.sin(), z) * (reach_m - 5e-4)
        })
        .max_by(|a, b| clearance(a).total_cmp(&clearance(b)))
        .unwrap()
}

/// How far inside the hook's reach ties must be for the competent run to apply energy (m).
const SAFE_MARGIN_M: f64 = 2e-3;

/// The hook frees the gallbladder from its bed, the nearest ties first: beside them, the
/// energy on while two ties at least are well within its reach. The organs move as ties
/// give, and a tie may give, or move out of reach, within a tick without the hook: with two
/// in reach, one going leaves the other to take the energy, which never reaches a wall. A
/// tie left alone, beyond the reach of others, is left.
fn free_from_bed(script: &mut Script, abdomen: &Abdomen, reach_m: f64) {
    let within_m = reach_m - SAFE_MARGIN_M;
    let mut tried: Vec<Vector3<f64>> = Vec::new();
    loop {
        let haptic = script.live();
        let tip = right_tip_m(haptic);
        let mut middles = holding(haptic);
        middles.sort_by(|a, b| (a - tip).norm().total_cmp(&(b - tip).norm()));
        let target = (middles.iter())
            .map(|m| beside_tie(abdomen, m, reach_m))
            .filter(|at| tried.iter().all(|t| (t - at).norm() > 1e-4))
            .find(|at| ties_within(haptic, at, within_m) >= 2);
        let Some(at) = target else {
            return;
        };
        tried.push(at);
        script.go(at);
        if ties_within(script.live(), &at, within_m) >= 2 {
            script.press_until(1.5, |h| ties_within(h, &right_tip_m(h), within_m) < 2);
        }
    }
}

#[test]
fn the_operations_runs_are_made_from_the_scene() {
    let scenario = super::shipped(NAME);
    let stage = Stage::of(&scenario);
    let (abdomen, start, plane, tip_m) = (&stage.abdomen, stage.start_m, &stage.plane, stage.tip_m);

    let mut competent = stage.retracted(&scenario);
    competent.drive(&scenario);
    // The assistant's grasper holds the fundus up: it touches the gallbladder, and nothing
    // else, pressing within the device's limit.
    let haptic = competent.live();
    let held_n = haptic.assistant::<DeviceForce>().unwrap().desired_n;
    eprintln!("the assistant holds the fundus with {:.3} N", held_n.norm());
    assert!(
        held_n.norm() > 0.01 && held_n.norm() <= scenario.device.max_force_n.0,
        "{held_n:?}"
    );
    let world = haptic.world_mut();
    let touched: Vec<String> = (world.query::<(&OrganBody, &HandTouches)>())
        .iter(world)
        .filter(|(_, touches)| touches.0[ASSISTANT].contact.is_some())
        .map(|(body, _)| body.name.clone())
        .collect();
    assert_eq!(touched, ["gallbladder"]);
    let tree = live_tree(&mut competent);
    competent.triangle_as_taught(abdomen, plane, start, live_tree);
    competent.go(start);
    competent.change();
    free_from_bed(&mut competent, abdomen, reach_m(tip_m));
    let burns = competent
        .live()
        .world()
        .resource::<OrganBurns>()
        .0
        .marks()
        .len();
    assert_eq!(burns, 0, "the hook burned a wall");
    competent.go(start);
    competent.wait(1.0);
    competent.check_or_write(NAME, "competent");

    let mut careless = stage.retracted(&scenario);
    careless.clip_in_haste(abdomen, &tree, plane, start);
    careless.divide_in_haste(&tree, start);
    careless.go(start);
    careless.change();
    // The triangle's task ends at its time limit, the artery still bleeding; in the bed's
    // phase the hook's energy goes on the liver's surface, well away from the bed.
    careless.wait(CLIP_AND_CUT_S - careless.time_s + 1.0);
    careless.go(on_the_liver(abdomen, &careless, tip_m));
    careless.press(LIVER_BURN_S);
    careless.go(start);
    careless.wait(3.0);
    careless.check_or_write(NAME, "careless");
}

/// When the triangle's task ends unfinished: the exposure's time and its time limit (s).
const CLIP_AND_CUT_S: f64 = 3.0 + 90.0;

/// How long the careless run holds the hook's energy on the liver (s).
const LIVER_BURN_S: f64 = 0.5;

/// Where the hook's tip, along its line from its port towards the liver's anterior edge,
/// first presses the liver 1 mm deep: clear of the gallbladder and of the bed.
fn on_the_liver(abdomen: &Abdomen, script: &Script, tip_m: f64) -> Vector3<f64> {
    let port = script.port.port_m;
    let towards = Vector3::new(-0.02, 0.03, -0.03);
    let along = (towards - port).normalize();
    let mut at = port;
    while abdomen.value(Organ::Liver, &at.into()) > tip_m - 1e-3 {
        at += along * 1e-4;
        assert!(
            (at - port).norm() < script.port.shaft_m,
            "the liver out of reach"
        );
    }
    let gallbladder = abdomen.value(Organ::Gallbladder, &at.into());
    assert!(gallbladder > 0.02, "{gallbladder} m from the gallbladder");
    at
}
