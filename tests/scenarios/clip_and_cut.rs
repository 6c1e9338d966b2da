//! Calot's triangle through the haptic loop, with two hands: in both runs the left hand's
//! grasper draws the infundibulum aside. The competent run (the triangle's fat cleared with
//! the hook to the critical view of safety, then three clips on each of the cystic duct and
//! artery and a cut between them, the left hand holding to the end) passes with no mistake;
//! the careless run (a clip and two cuts before the view, each leaving a stump open, the left
//! hand letting go, the artery left bleeding) fails, its report naming the mistakes in time
//! order, and scores lower. The runs are made from the scenario's own tree, as the
//! retraction leaves it, and its ports, and checked to be.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector3;
use pgd_surgery::app::attempt::Outcome;
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::haptic::{Biliary, HapticLoop, TickClock};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::biliary::{BiliaryTree, FatStrand, Structure, ViewRecord};
use pgd_surgery::devices::{Fulcrum, HapticDevice, Instrument, Rack, Scripted, TICK_S, Trajectory};
use pgd_surgery::mesh::organs::{Abdomen, Organ, OrganSettings};
use pgd_surgery::report::critical_view::{FAT, Projection, SIZE, Side, colour_of, rgb};
use pgd_surgery::report::write_report;
use pgd_surgery::scenario::tasks::ClipAndCutResult;
use pgd_surgery::scenario::{Scenario, load};
use pgd_surgery::store::OnStale;

const NAME: &str = "lap-chole-clip-and-cut";

fn scenario() -> Scenario {
    load(&super::root().join(format!("scenarios/{NAME}.scenario.ron"))).unwrap()
}

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
    let competent = super::run(NAME, "competent").card;
    assert!(
        competent.score > careless.score + 20.0,
        "{} against {}",
        competent.score,
        careless.score
    );
}

/// A script of both hands' devices: the right hand's through the scenario's one port (its
/// rows, the time, the instruments' rack, whose offset the second button changes, and the
/// tip) and the left hand's grasper through its own.
struct Script {
    csv: String,
    tip_radius_m: f64,
    time_s: f64,
    port: Fulcrum,
    rack: Rack,
    tip_m: Vector3<f64>,
    left: LeftHand,
}

/// The left hand's grasper: its port, its tip and whether its jaws are closed.
struct LeftHand {
    port: Fulcrum,
    tip_m: Vector3<f64>,
    closed: bool,
}

/// Instruments take a moment to move between points and to close (s); the hook is held on
/// the fat while its energy divides the strands within reach (30 W: about 7 J a strand).
const MOVE_S: f64 = 0.6;
const CLOSE_S: f64 = 0.25;
const BURN_S: f64 = 1.2;
/// The left grasper takes the infundibulum this far along the gallbladder's axis from its
/// fundus, its tip's sphere this far into the wall (m); then draws its tip laterally this
/// far over this time (m, s), and keeps it there while the retraction's hold is scored.
const INFUNDIBULUM_T: f64 = 0.75;
const GRASP_INTO_M: f64 = 2.3e-3;
const LEFT_DRAW_M: f64 = 0.022;
const LEFT_DRAW_S: f64 = 1.0;
const RETRACTION_HELD_S: f64 = 2.0;
/// The left grasper starts this far lateral of where it takes the infundibulum (m).
const LEFT_START_M: f64 = 0.024;

/// Where the competent run clips each tube (two on the patient's side, one on the
/// gallbladder's) and cuts it, as shares of its length from the patient's end.
const CLIPS_AT: [f64; 3] = [0.2, 0.35, 0.62];
const CUT_AT: f64 = 0.5;
/// The clip applier's jaws and the scissors' blades (m), as the scenario gives them.
const JAW_M: f64 = 9e-3;
const BLADE_M: f64 = 15e-3;

impl Script {
    /// Both hands at their starts: the left grasper's tip `left_m` beside the infundibulum.
    fn new(
        scenario: &Scenario,
        start_m: Vector3<f64>,
        left_m: Vector3<f64>,
        tip_radius_m: f64,
    ) -> Self {
        let port = scenario.instruments[0].port.fulcrum();
        let instruments: Vec<Instrument> = (scenario.instruments.iter())
            .map(|i| Instrument {
                action: i.tool.action(),
                port: Some(i.port.fulcrum()),
            })
            .collect();
        let mut script = Self {
            csv: "time_s,x_m,y_m,z_m,buttons,left_x_m,left_y_m,left_z_m,left_buttons\n".into(),
            tip_radius_m,
            time_s: 0.0,
            port,
            rack: Rack::new(&instruments),
            tip_m: start_m,
            left: LeftHand {
                port: scenario.left_hand[0].port.fulcrum(),
                tip_m: left_m,
                closed: false,
            },
        };
        script.row(0);
        script
    }

    fn device_m(&self) -> Vector3<f64> {
        self.port.handle_for(&self.tip_m).unwrap() - self.rack.offset_m()
    }

    fn row(&mut self, buttons: u32) {
        let d = self.device_m();
        let left = &self.left;
        let l = left.port.handle_for(&left.tip_m).unwrap();
        writeln!(
            self.csv,
            "{:.3},{:.6},{:.6},{:.6},{buttons},{:.6},{:.6},{:.6},{}",
            self.time_s,
            d.x,
            d.y,
            d.z,
            l.x,
            l.y,
            l.z,
            u32::from(left.closed)
        )
        .unwrap();
    }

    /// Moves the left grasper's tip to `to_m` over `over_s`, the right hand still.
    fn left_to(&mut self, to_m: Vector3<f64>, over_s: f64) {
        self.time_s += over_s;
        self.left.tip_m = to_m;
        self.row(0);
    }

    /// Closes or opens the left grasper's jaws where its tip is.
    fn left_jaws(&mut self, closed: bool) {
        self.time_s += 0.001;
        self.left.closed = closed;
        self.row(0);
    }

    /// The left hand takes the infundibulum at `grasp_m` and draws it laterally, then both
    /// hands wait for the retraction's hold to be scored.
    fn retract(&mut self, grasp_m: Vector3<f64>) {
        self.left_to(grasp_m, MOVE_S + 0.9);
        self.left_jaws(true);
        self.left_to(grasp_m + Vector3::x() * LEFT_DRAW_M, LEFT_DRAW_S);
        self.time_s += RETRACTION_HELD_S;
        self.row(0);
    }

    /// Moves the tip to `to_m`, buttons up.
    fn go(&mut self, to_m: Vector3<f64>) {
        self.time_s += MOVE_S;
        self.tip_m = to_m;
        self.row(0);
    }

    /// Holds the first button down where the tip is for `hold_s`.
    fn press(&mut self, hold_s: f64) {
        self.time_s += 0.001;
        self.row(1);
        self.time_s += hold_s;
        self.row(1);
        self.time_s += 0.001;
        self.row(0);
    }

    /// Changes to the next instrument where the tip is; the new one's tip goes where the
    /// rack puts it, and the script moves it back to `self.tip_m`.
    fn change(&mut self) {
        let device = self.device_m();
        self.time_s += 0.001;
        self.row(2);
        self.rack.take(2, &device, &self.tip_m, || true);
        self.rack.take(0, &device, &self.tip_m, || true);
        let taken_up = self
            .port
            .pose(&(device + self.rack.offset_m()))
            .unwrap()
            .tip_m;
        let back_to = std::mem::replace(&mut self.tip_m, taken_up);
        self.time_s += 0.05;
        self.row(0);
        self.go(back_to);
    }

    /// Closes the jaws (or blades), `jaw_m` long beyond the tip's sphere, across `structure`
    /// at `share` of its length, the tube halfway along them.
    fn close_across(&mut self, tree: &BiliaryTree, structure: Structure, share: f64, jaw_m: f64) {
        let tube = tree.tube(structure);
        let on = tube.point_at(share * tube.length_m());
        let along = (on - self.port.port_m).normalize();
        let tip = on - along * (self.tip_radius_m + jaw_m / 2.0);
        self.go(tip - along * 0.01);
        self.go(tip);
        self.press(CLOSE_S);
        self.go(tip - along * 0.01);
    }

    /// Checks that the shipped run `script` is this one; with `PGD_WRITE_RUNS` set, writes it.
    fn check_or_write(&self, script: &str) {
        let path = super::root().join(format!("scenarios/runs/{NAME}.{script}.csv"));
        if std::env::var_os("PGD_WRITE_RUNS").is_some() {
            std::fs::write(&path, &self.csv).unwrap();
            return;
        }
        let shipped = std::fs::read_to_string(&path).unwrap();
        assert!(
            shipped == self.csv,
            "{} is not what the scene's tree and port make now: write it anew with \
             PGD_WRITE_RUNS=1 cargo test --test scenarios clip_and_cut_runs",
            path.display()
        );
    }
}

/// The hook's tip `tip_m` in radius beside a strand, on its side away from the tubes and
/// clear of them (along the normal of the ducts' plane), where it keeps clearest of the
/// organs.
fn by_strand(abdomen: &Abdomen, strand: &FatStrand, plane: &Plane, tip_m: f64) -> Vector3<f64> {
    let clearance = |p: &Vector3<f64>| {
        [Organ::Liver, Organ::Gallbladder, Organ::Duodenum]
            .map(|o| abdomen.value(o, &(*p).into()))
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    };
    let axis = strand.axis;
    let depth = (axis.at(0.5) - plane.point).dot(&plane.normal);
    let beyond = (tip_m + COMMON_DUCT_RADIUS_M + CLEAR_OF_TUBES_M - depth.abs()).max(0.0);
    (1..10)
        .map(|k| axis.at(k as f64 / 10.0) + plane.normal * (depth.signum() * beyond))
        .max_by(|a, b| clearance(a).total_cmp(&clearance(b)))
        .unwrap()
}

/// Where the left grasper's tip takes the infundibulum: lateral of its axis, its sphere
/// `GRASP_INTO_M` into the wall.
fn grasp_point(abdomen: &Abdomen, tip_m: f64) -> Vector3<f64> {
    let (fundus, neck) = abdomen.gallbladder_axis_m();
    let mut at = fundus.coords + (neck - fundus) * INFUNDIBULUM_T;
    while abdomen.value(Organ::Gallbladder, &at.into()) < tip_m - GRASP_INTO_M {
        at.x += 1e-4;
    }
    at
}

/// The tree as the left hand's retraction leaves it: `script` (the retraction, the right hand
/// still) run on the scenario's scene.
fn retracted(scenario: &Scenario, script: &Script) -> BiliaryTree {
    let scene = scenario_scene(
        scenario,
        super::vademecums(),
        Detail::Coarse,
        OnStale::Refuse,
    );
    let scene = scene.unwrap();
    let hands = Trajectory::read_hands(Path::new("retraction"), script.csv.as_bytes()).unwrap();
    let devices = (hands.into_iter())
        .map(|hand| Box::new(Scripted::new("retraction", hand)) as Box<dyn HapticDevice>)
        .collect();
    let mut haptic = HapticLoop::with_devices(&scene, devices).unwrap();
    let ticks = (script.time_s / TICK_S).round() as u64;
    for tick in 0..=ticks {
        haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
    }
    haptic.world().resource::<Biliary>().tree().clone()
}

/// The hook keeps this far clear of the tubes (m) beyond its tip's radius.
const CLEAR_OF_TUBES_M: f64 = 1e-3;

/// The usual common duct's radius (m).
const COMMON_DUCT_RADIUS_M: f64 = 3e-3;

/// The plane of the cystic and common hepatic ducts.
struct Plane {
    point: Vector3<f64>,
    normal: Vector3<f64>,
}

impl Plane {
    fn of(tree: &BiliaryTree) -> Self {
        let junction = tree.tube(Structure::CommonDuct).rod.positions[tree.junction_node];
        let cystic = tree.tube(Structure::CysticDuct);
        let gallbladder_end = cystic.rod.positions[cystic.rod.nodes() - 1];
        let hilum = tree.tube(Structure::CommonDuct).rod.positions[0];
        let normal = (gallbladder_end - junction)
            .cross(&(hilum - junction))
            .normalize();
        Self {
            point: junction,
            normal,
        }
    }
}

/// The scenario's two scripted runs are what its own tree and port make (with
/// `PGD_WRITE_RUNS` set, they are written anew: after a change to the scene).
#[test]
fn the_clip_and_cut_runs_are_made_from_the_scenes_tree() {
    let scenario = scenario();
    let abdomen = Abdomen::new(&OrganSettings::default());
    let start = Vector3::new(0.0, 0.02, -0.075);
    let duct = Structure::CysticDuct;
    let artery = Structure::CysticArtery;
    let scene = scenario_scene(
        &scenario,
        super::vademecums(),
        Detail::Coarse,
        OnStale::Refuse,
    );
    let tip_m = scene.unwrap().probe.tip_radius_m;
    let grasp = grasp_point(&abdomen, tip_m);
    let left_start = grasp + Vector3::x() * LEFT_START_M;
    let mut retraction = Script::new(&scenario, start, left_start, tip_m);
    retraction.retract(grasp);
    // The fat stays where it was; the tubes follow the gallbladder drawn aside.
    let tree = retracted(&scenario, &retraction);
    let plane = Plane::of(&scenario.biliary.as_ref().unwrap().tree().unwrap());

    let mut competent = Script::new(&scenario, start, left_start, tip_m);
    competent.retract(grasp);
    for strand in &tree.fat.strands {
        competent.go(by_strand(&abdomen, strand, &plane, tip_m));
        competent.press(BURN_S);
    }
    competent.go(start);
    competent.time_s += 1.0;
    competent.row(0);
    competent.change();
    for structure in [duct, artery] {
        for share in CLIPS_AT {
            competent.close_across(&tree, structure, share, JAW_M);
        }
    }
    competent.go(start);
    competent.change();
    for structure in [duct, artery] {
        competent.close_across(&tree, structure, CUT_AT, BLADE_M);
    }
    competent.go(start);
    competent.time_s += 1.0;
    competent.row(0);
    competent.check_or_write("competent");

    let mut careless = Script::new(&scenario, start, left_start, tip_m);
    careless.retract(grasp);
    for strand in &tree.fat.strands[..4] {
        careless.go(by_strand(&abdomen, strand, &plane, tip_m));
        careless.press(CLOSE_S);
    }
    careless.go(start);
    careless.change();
    careless.close_across(&tree, duct, 0.8, JAW_M);
    // The left hand lets go of the infundibulum while the right hand works.
    careless.left_jaws(false);
    careless.go(start);
    careless.change();
    careless.close_across(&tree, duct, 0.5, BLADE_M);
    careless.close_across(&tree, artery, 0.5, BLADE_M);
    careless.go(start);
    careless.time_s += 3.0;
    careless.row(0);
    careless.check_or_write("careless");
}
