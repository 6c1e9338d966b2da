//! Scripted runs of the biliary scenarios, made from the scene they run on: both hands'
//! devices through their ports (the right hand changing instruments on its rack), where the
//! left grasper takes the infundibulum, where the hook goes beside a strand of fat. A script
//! may drive a live haptic loop as it is written, so that what it does next can depend on
//! what the scene did (the ties still holding under the hook).

use std::fmt::Write as _;
use std::path::Path;
use std::sync::{Arc, Mutex};

use nalgebra::Vector3;
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::haptic::{Biliary, HapticLoop, TickClock};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::biliary::{BiliaryTree, FatStrand, Structure};
use pgd_surgery::devices::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, Fulcrum, HapticDevice, Instrument, Rack,
    TICK_S, Trajectory,
};
use pgd_surgery::mesh::organs::{Abdomen, Organ, OrganSettings};
use pgd_surgery::scenario::Scenario;
use pgd_surgery::store::OnStale;

/// Where a biliary scenario's scripts start: the organs at rest, the right hand's tip, the
/// scene's tip radius, where the left grasper takes the infundibulum, and the ducts' plane.
pub(super) struct Stage {
    pub(super) abdomen: Abdomen,
    pub(super) start_m: Vector3<f64>,
    pub(super) tip_m: f64,
    pub(super) grasp_m: Vector3<f64>,
    pub(super) plane: Plane,
}

impl Stage {
    /// The stage of `scenario`'s coarse scene.
    pub(super) fn of(scenario: &Scenario) -> Self {
        let abdomen = Abdomen::new(&OrganSettings::default());
        let scene = scenario_scene(
            scenario,
            super::vademecums(),
            Detail::Coarse,
            OnStale::Refuse,
        );
        let tip_m = scene.unwrap().probe.tip_radius_m;
        let grasp_m = grasp_point(&abdomen, tip_m);
        let plane = Plane::of(&scenario.biliary.as_ref().unwrap().tree().unwrap());
        Self {
            abdomen,
            start_m: Vector3::new(0.0, 0.02, -0.075),
            tip_m,
            grasp_m,
            plane,
        }
    }

    /// Both hands' script from their starts (the left grasper beside the infundibulum) to
    /// the infundibulum taken and drawn aside.
    pub(super) fn retracted(&self, scenario: &Scenario) -> Script {
        let left_start_m = self.grasp_m + Vector3::x() * LEFT_START_M;
        let mut script = Script::new(scenario, self.start_m, left_start_m, self.tip_m);
        script.retract(self.grasp_m);
        script
    }
}

/// A script of both hands' devices: the right hand's through the scenario's one port (its
/// rows, the time, the instruments' rack, whose offset the second button changes, and the
/// tip) and the left hand's grasper through its own.
pub(super) struct Script {
    csv: String,
    tip_radius_m: f64,
    pub(super) time_s: f64,
    pub(super) port: Fulcrum,
    rack: Rack,
    tip_m: Vector3<f64>,
    left: LeftHand,
    /// The loop the script drives as it is written, if it does.
    live: Option<Live>,
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

/// The tubes clipped and divided: the cystic duct, then the artery.
const TUBES: [Structure; 2] = [Structure::CysticDuct, Structure::CysticArtery];

/// Where the competent run clips each tube (two on the patient's side, one on the
/// gallbladder's) and cuts it, as shares of its length from the patient's end.
const CLIPS_AT: [f64; 3] = [0.2, 0.35, 0.62];
const CUT_AT: f64 = 0.5;
/// The clip applier's jaws and the scissors' blades (m), as the scenario gives them.
const JAW_M: f64 = 9e-3;
const BLADE_M: f64 = 15e-3;

impl Script {
    /// Both hands at their starts: the left grasper's tip `left_m` beside the infundibulum.
    pub(super) fn new(
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
            live: None,
        };
        script.row(0);
        script
    }

    pub(super) fn device_m(&self) -> Vector3<f64> {
        self.port.handle_for(&self.tip_m).unwrap() - self.rack.offset_m()
    }

    pub(super) fn row(&mut self, buttons: u32) {
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
        if let Some(live) = &self.live {
            live.refresh(&self.csv);
        }
    }

    /// From here on, drives a haptic loop of `scenario`'s coarse scene with what is written
    /// (and first with what was).
    pub(super) fn drive(&mut self, scenario: &Scenario) {
        self.live = Some(Live::new(scenario, &self.csv));
    }

    /// The driven loop, ticked up to the script's time.
    pub(super) fn live(&mut self) -> &mut HapticLoop {
        let live = self.live.as_mut().expect("a script driving a loop");
        live.run_to(self.time_s)
    }

    /// Holds the first button down where the tip is, the loop running, until `done` says so
    /// (checked every tick) or `most_s` has passed; then lets it go.
    pub(super) fn press_until(&mut self, most_s: f64, done: impl Fn(&HapticLoop) -> bool) {
        self.time_s += 0.001;
        self.row(1);
        let until_s = self.time_s + most_s;
        self.time_s += TICK_S;
        while self.time_s < until_s && !done(self.live()) {
            self.time_s += TICK_S;
        }
        self.row(1);
        self.time_s += 0.001;
        self.row(0);
    }

    /// Moves the left grasper's tip to `to_m` over `over_s`, the right hand still.
    pub(super) fn left_to(&mut self, to_m: Vector3<f64>, over_s: f64) {
        self.time_s += over_s;
        self.left.tip_m = to_m;
        self.row(0);
    }

    /// Closes or opens the left grasper's jaws where its tip is.
    pub(super) fn left_jaws(&mut self, closed: bool) {
        self.time_s += 0.001;
        self.left.closed = closed;
        self.row(0);
    }

    /// The left hand takes the infundibulum at `grasp_m` and draws it laterally, then both
    /// hands wait for the retraction's hold to be scored.
    pub(super) fn retract(&mut self, grasp_m: Vector3<f64>) {
        self.left_to(grasp_m, MOVE_S + 0.9);
        self.left_jaws(true);
        self.left_to(grasp_m + Vector3::x() * LEFT_DRAW_M, LEFT_DRAW_S);
        self.time_s += RETRACTION_HELD_S;
        self.row(0);
    }

    /// Both hands still for `wait_s`.
    pub(super) fn wait(&mut self, wait_s: f64) {
        self.time_s += wait_s;
        self.row(0);
    }

    /// Moves the tip to `to_m`, buttons up.
    pub(super) fn go(&mut self, to_m: Vector3<f64>) {
        self.time_s += MOVE_S;
        self.tip_m = to_m;
        self.row(0);
    }

    /// Holds the first button down where the tip is for `hold_s`.
    pub(super) fn press(&mut self, hold_s: f64) {
        self.time_s += 0.001;
        self.row(1);
        self.time_s += hold_s;
        self.row(1);
        self.time_s += 0.001;
        self.row(0);
    }

    /// Changes to the next instrument where the tip is; the new one's tip goes where the
    /// rack puts it, and the script moves it back to `self.tip_m`.
    pub(super) fn change(&mut self) {
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
    pub(super) fn close_across(
        &mut self,
        tree: &BiliaryTree,
        structure: Structure,
        share: f64,
        jaw_m: f64,
    ) {
        let tube = tree.tube(structure);
        let on = tube.point_at(share * tube.length_m());
        let along = (on - self.port.port_m).normalize();
        let tip = on - along * (self.tip_radius_m + jaw_m / 2.0);
        self.go(tip - along * 0.01);
        self.go(tip);
        self.press(CLOSE_S);
        self.go(tip - along * 0.01);
    }

    /// The hook beside each of `strands` in turn, clear of the tubes, its energy on for
    /// `burn_s` at each.
    pub(super) fn clear_strands(
        &mut self,
        abdomen: &Abdomen,
        strands: &[FatStrand],
        plane: &Plane,
        burn_s: f64,
    ) {
        for strand in strands {
            self.go(by_strand(abdomen, strand, plane, self.tip_radius_m));
            self.press(burn_s);
        }
    }

    /// The triangle as taught, from the hook in hand to the scissors: every strand of the
    /// fat cleared, a second's pause at `start_m`, then the clip applier's three clips on
    /// each of the cystic duct and artery and the scissors' cut between them, each closed
    /// across its tube where `tree_now` has it then.
    pub(super) fn triangle_as_taught(
        &mut self,
        abdomen: &Abdomen,
        plane: &Plane,
        start_m: Vector3<f64>,
        tree_now: impl Fn(&mut Self) -> BiliaryTree,
    ) {
        let strands = tree_now(self).fat.strands;
        self.clear_strands(abdomen, &strands, plane, BURN_S);
        self.go(start_m);
        self.wait(1.0);
        self.change();
        for structure in TUBES {
            for share in CLIPS_AT {
                let tree = tree_now(self);
                self.close_across(&tree, structure, share, JAW_M);
            }
        }
        self.go(start_m);
        self.change();
        for structure in TUBES {
            let tree = tree_now(self);
            self.close_across(&tree, structure, CUT_AT, BLADE_M);
        }
    }

    /// The careless start of the triangle: four strands touched for a moment, then the clip
    /// applier's clip on the cystic duct near the gallbladder, long before the view.
    pub(super) fn clip_in_haste(
        &mut self,
        abdomen: &Abdomen,
        tree: &BiliaryTree,
        plane: &Plane,
        start_m: Vector3<f64>,
    ) {
        self.clear_strands(abdomen, &tree.fat.strands[..4], plane, CLOSE_S);
        self.go(start_m);
        self.change();
        self.close_across(tree, Structure::CysticDuct, 0.8, JAW_M);
    }

    /// Then the scissors, and both tubes divided halfway along, wherever the clips are.
    pub(super) fn divide_in_haste(&mut self, tree: &BiliaryTree, start_m: Vector3<f64>) {
        self.go(start_m);
        self.change();
        for structure in TUBES {
            self.close_across(tree, structure, 0.5, BLADE_M);
        }
    }

    /// Checks that the shipped run `script` of scenario `name` is this one; with
    /// `PGD_WRITE_RUNS` set, writes it.
    pub(super) fn check_or_write(&self, name: &str, script: &str) {
        let path = super::root().join(format!("scenarios/runs/{name}.{script}.csv"));
        if std::env::var_os("PGD_WRITE_RUNS").is_some() {
            std::fs::write(&path, &self.csv).unwrap();
            return;
        }
        let shipped = std::fs::read_to_string(&path).unwrap();
        assert!(
            shipped == self.csv,
            "{} is not what the scene's tree and port make now: write it anew with \
             PGD_WRITE_RUNS=1 cargo test --test scenarios runs_are_made",
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
pub(super) fn retracted(scenario: &Scenario, script: &Script) -> BiliaryTree {
    let mut live = Live::new(scenario, &script.csv);
    let haptic = live.run_to(script.time_s);
    haptic.world().resource::<Biliary>().tree().clone()
}

/// The hook keeps this far clear of the tubes (m) beyond its tip's radius.
const CLEAR_OF_TUBES_M: f64 = 1e-3;

/// The usual common duct's radius (m).
const COMMON_DUCT_RADIUS_M: f64 = 3e-3;

/// The plane of the cystic and common hepatic ducts.
pub(super) struct Plane {
    point: Vector3<f64>,
    normal: Vector3<f64>,
}

impl Plane {
    pub(super) fn of(tree: &BiliaryTree) -> Self {
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

/// A haptic loop driven by a script as it is written: each hand's device reads the rows
/// written so far, and holds the last.
struct Live {
    haptic: HapticLoop,
    hands: Vec<Arc<Mutex<Trajectory>>>,
    /// The next tick to run.
    tick: u64,
}

impl Live {
    /// The loop of `scenario`'s coarse scene on the script `csv`.
    fn new(scenario: &Scenario, csv: &str) -> Self {
        let scene = scenario_scene(
            scenario,
            super::vademecums(),
            Detail::Coarse,
            OnStale::Refuse,
        );
        let hands: Vec<_> = (read(csv).into_iter())
            .map(|hand| Arc::new(Mutex::new(hand)))
            .collect();
        let devices = (hands.iter())
            .map(|hand| Box::new(Growing(hand.clone())) as Box<dyn HapticDevice>)
            .collect();
        let haptic = HapticLoop::with_devices(&scene.unwrap(), devices).unwrap();
        Self {
            haptic,
            hands,
            tick: 0,
        }
    }

    /// The devices read `csv` from now on.
    fn refresh(&self, csv: &str) {
        for (shared, hand) in self.hands.iter().zip(read(csv)) {
            *shared.lock().unwrap() = hand;
        }
    }

    /// The loop, ticked up to `time_s`.
    fn run_to(&mut self, time_s: f64) -> &mut HapticLoop {
        let last = (time_s / TICK_S).round() as u64;
        while self.tick <= last {
            self.haptic.tick(TickClock {
                tick: self.tick,
                time_s: self.tick as f64 * TICK_S,
                overruns_in_a_row: 0,
            });
            self.tick += 1;
        }
        &mut self.haptic
    }
}

/// Each hand's trajectory in the script `csv`, as the shipped file will read.
fn read(csv: &str) -> Vec<Trajectory> {
    Trajectory::read_hands(Path::new("script"), csv.as_bytes()).unwrap()
}

/// A device that replays a trajectory still being written.
struct Growing(Arc<Mutex<Trajectory>>);

impl HapticDevice for Growing {
    fn name(&self) -> &str {
        "a script being written"
    }

    fn limits(&self) -> DeviceLimits {
        DeviceLimits::default()
    }

    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError> {
        Ok(self.0.lock().unwrap().sample(time_s))
    }

    fn render(&mut self, _force: EdgeForce) -> Result<(), DeviceError> {
        Ok(())
    }
}
