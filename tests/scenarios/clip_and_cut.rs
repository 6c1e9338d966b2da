//! Calot's triangle through the haptic loop, with two hands: in both runs the left hand's
//! grasper draws the infundibulum aside. The competent run (the triangle's fat cleared with
//! the hook to the critical view of safety, then three clips on each of the cystic duct and
//! artery and a cut between them, the left hand holding to the end) passes with no mistake;
//! the careless run (a clip and two cuts before the view, each leaving a stump open, the left
//! hand letting go, the artery left bleeding) fails, its report naming the mistakes in time
//! order (every shipped pair's scores are ordered in `allocations.rs`). The runs are made from the scenario's own tree, as the
//! retraction leaves it, and its ports, and checked to be.

use std::path::Path;

use pgd_surgery::app::attempt::Outcome;
use pgd_surgery::biliary::{Structure, ViewRecord};
use pgd_surgery::report::critical_view::{FAT, Projection, SIZE, Side, colour_of, rgb};
use pgd_surgery::report::write_report;
use pgd_surgery::scenario::tasks::ClipAndCutResult;

use super::script::{Stage, retracted};

const NAME: &str = "lap-chole-clip-and-cut";

#[test]
fn the_competent_clip_and_cut_reaches_the_view_then_clips_and_divides_as_taught() {
    let outcome = super::run(NAME, "competent");
    let card = &outcome.card;
    let retraction = &card.tasks[0].metrics;
    assert!(retraction.completed, "{retraction:#?}");
    let metrics = &card.tasks[1].metrics;
    let result = metrics.result::<ClipAndCutResult>().unwrap();
    eprintln!("{:#?}", result);
    eprintln!("score {:.1}, errors {:?}", card.score, metrics.errors);
    assert!(metrics.completed, "{metrics:#?}");
    assert!(metrics.errors.is_empty(), "{:?}", metrics.errors);
    let view_s = result.view_reached_s.expect("the critical view reached");
    assert!(
        result
            .clips
            .iter()
            .all(|c| c.time_s > view_s && c.clip.closes_lumen())
    );
    assert_eq!((result.cystic_duct_clips, result.artery_clips), (3, 3));
    assert_eq!(result.blood_lost_ml, 0.0);
    // The left hand kept the infundibulum drawn aside within its band, still, to the end.
    let hold = metrics.countertraction.as_ref().unwrap();
    assert!(hold.in_band_share() > 0.95 && hold.let_go == 0, "{hold:?}");
    let hands = metrics.hands.as_ref().unwrap();
    assert!(hands.left.path_length_mm < 1.0, "{hands:?}");
    assert!(hands.right.path_length_mm > 100.0, "{hands:?}");
    assert!(card.passed, "{card:#?}");
    let (picture, record) = doublet("competent", &outcome);
    assert!(record.reached() && record.time_s == Some(view_s));
    assert!(
        record.clips.is_empty(),
        "kept as it was when the view was reached"
    );
    let duct = colour_at(&picture, &record, Side::Front, Structure::CysticDuct);
    assert!(
        nearer(duct, rgb(colour_of(Structure::CysticDuct)), rgb(FAT)),
        "{duct:?}"
    );
}

/// The report's critical view of `outcome`, written and read back (RGB rows), and what it
/// was drawn from.
fn doublet(stem: &str, outcome: &Outcome) -> (Vec<u8>, ViewRecord) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("clip-and-cut-report");
    let files = write_report(&dir, stem, &outcome.card, &outcome.force_trace).unwrap();
    let path = files.critical_view.expect("a critical view picture");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!((info.width, info.height), SIZE);
    let record = outcome.card.critical_view.clone().unwrap();
    (pixels, record)
}

/// The colour drawn from `side` where a quarter of `structure`'s length from its patient
/// end falls (away from the careless run's cuts).
fn colour_at(pixels: &[u8], record: &ViewRecord, side: Side, structure: Structure) -> [u8; 3] {
    let tube = record
        .tubes
        .iter()
        .find(|t| t.structure == structure)
        .unwrap();
    let at = tube.positions_m[tube.positions_m.len() / 4];
    let (x, y) = Projection::new(record, side).in_picture(&at).unwrap();
    let at = 3 * (y as usize * SIZE.0 as usize + x as usize);
    [pixels[at], pixels[at + 1], pixels[at + 2]]
}

/// Whether `colour` is nearer `this` than `that`.
fn nearer(colour: [u8; 3], this: [u8; 3], that: [u8; 3]) -> bool {
    let distance = |c: [u8; 3]| {
        (colour.iter().zip(c))
            .map(|(&a, b)| (i32::from(a) - i32::from(b)).pow(2))
            .sum::<i32>()
    };
    distance(this) < distance(that)
}

#[test]
fn the_careless_clip_and_cut_fails_naming_what_it_did_before_the_view() {
    let careless_outcome = super::run(NAME, "careless");
    let careless = &careless_outcome.card;
    let metrics = &careless.tasks[1].metrics;
    eprintln!("score {:.1}, errors {:?}", careless.score, metrics.errors);
    let result = metrics.result::<ClipAndCutResult>().unwrap();
    assert_eq!(result.view_reached_s, None);
    let said: Vec<&str> = (metrics.errors.iter())
        .map(|e| e.split_once(": ").map_or(e.as_str(), |(_, what)| what))
        .collect();
    assert_eq!(
        said,
        [
            "placed a clip before the critical view of safety",
            "the left hand let go of the gallbladder",
            "divided a structure before the critical view of safety",
            "divided a structure with a stump left open",
            "divided a structure before the critical view of safety",
            "divided a structure with a stump left open",
        ]
    );
    assert!(
        result.still_bleeding && result.blood_lost_ml > 1.0,
        "{result:#?}"
    );
    assert!(!metrics.completed, "the artery still bleeds");
    assert_eq!(metrics.countertraction.as_ref().unwrap().let_go, 1);
    assert!(!careless.passed);
    let (picture, record) = doublet("careless", &careless_outcome);
    assert!(!record.reached());
    // The fat left hides the artery from the front; from behind it lies in front of the fat.
    let artery = rgb(colour_of(Structure::CysticArtery));
    let front = colour_at(&picture, &record, Side::Front, Structure::CysticArtery);
    assert!(nearer(front, rgb(FAT), artery), "{front:?}");
    let behind = colour_at(&picture, &record, Side::Behind, Structure::CysticArtery);
    assert!(nearer(behind, artery, rgb(FAT)), "{behind:?}");
}

/// The scenario's two scripted runs are what its own tree and port make (with
/// `PGD_WRITE_RUNS` set, they are written anew: after a change to the scene).
#[test]
fn the_clip_and_cut_runs_are_made_from_the_scenes_tree() {
    let scenario = super::shipped(NAME);
    let stage = Stage::of(&scenario);
    let (abdomen, start, plane) = (&stage.abdomen, stage.start_m, &stage.plane);
    // The fat stays where it was; the tubes follow the gallbladder drawn aside.
    let tree = retracted(&scenario, &stage.retracted(&scenario));

    let mut competent = stage.retracted(&scenario);
    competent.triangle_as_taught(abdomen, plane, start, |_| tree.clone());
    competent.go(start);
    competent.wait(1.0);
    competent.check_or_write(NAME, "competent");

    let mut careless = stage.retracted(&scenario);
    careless.clip_in_haste(abdomen, &tree, plane, start);
    // The left hand lets go of the infundibulum while the right hand works.
    careless.left_jaws(false);
    careless.divide_in_haste(&tree, start);
    careless.go(start);
    careless.wait(3.0);
    careless.check_or_write(NAME, "careless");
}
