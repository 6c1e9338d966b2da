//! The haptic loop benchmark (`pgd bench haptics`), with the app because it runs the app's
//! haptic world: tick compute time over a scripted sweep of the four-organ scene
//! (simulated clock), per organ pressed, and against the same contact solved by full FEM;
//! then the real-time loop's punctuality with each timer while the render side's CPU work
//! (every organ's whole displacement field, 60 times a second) runs beside it.

use std::fmt;
use std::time::{Duration, Instant};

use serde::Serialize;

use super::haptic::{
    HapticLoop, HapticScene, HapticThread, RealTimeReport, SceneBiliary, SceneHand, Scheduling,
    TickTimes,
};
use super::scene::{press_targets, tie_organs};
use crate::bench::fem::median_ms;
use crate::biliary::CriticalViewRule;
use crate::devices::{
    Action, HapticDevice, Instrument, PressMotion, PressTarget, Scripted, TICK_S, TimerMode,
    grasp_and_hold, press_and_slide,
};
use crate::fem::{FemError, Law, Loads, NewtonSettings};
use crate::mesh::Surface;
use crate::mesh::organs::{self, Organ, OrganSettings};
use crate::pgd::{self, SurfaceModes};
use crate::scenario::{AttachmentEntry, BiliaryEntry};

#[derive(Clone, Debug, Serialize)]
pub struct SweepFigures {
    /// Which organs the script presses.
    pub pressed: String,
    /// How many hands press.
    pub hands: usize,
    pub ticks: u64,
    pub contact_ticks: u64,
    /// Ticks the left hand's grasper held an organ (first run; none with one hand).
    pub left_holding_ticks: u64,
    /// Ticks whose press went beyond a nonlinear vademecum's range (first run).
    pub beyond_range_ticks: u64,
    /// Medians over the repeats of each run's quantiles (µs).
    pub compute_p50_us: f64,
    pub compute_p99_us: f64,
    pub compute_max_us: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FemContact {
    pub organ: &'static str,
    pub nodes: usize,
    /// One Newton solve (assembly, factorization, solve) of the liver press (ms, median).
    pub newton_ms: f64,
    /// `newton_ms` over the four-organ sweep's tick p50.
    pub ratio_to_tick_p50: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct HapticBenchReport {
    pub organs: Vec<String>,
    /// How deep the sweep presses each organ (mm).
    pub depth_mm: f64,
    pub repeats: usize,
    pub sweeps: Vec<SweepFigures>,
    pub fem_contact: FemContact,
    /// The render side's CPU work per frame: every organ's deformed surface and its normals,
    /// each organ pressed by a tool (ms, median).
    pub render_cpu_ms: f64,
    /// Real-time runs while the render side's CPU work runs.
    pub realtime: Vec<RealTimeReport>,
    pub realtime_seconds: f64,
    /// With `--hands 2`: the four-organ sweep with one hand...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub one_hand: Option<HandsTick>,
    /// ...and with two at once: the left hand a grasper holding the gallbladder drawn out
    /// (where it moves) while the right sweeps.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub two_hands: Option<HandsTick>,
    /// Where the scene has a gallbladder and a liver: the four-organ sweep (with every hand)
    /// with the gallbladder tied to the liver by its bed and without, in the same run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bed: Option<BedTick>,
    /// Where the scene has the liver, the gallbladder and the duodenum: the four-organ sweep
    /// with the biliary tree among them and without, in the same run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub biliary: Option<BiliaryTick>,
}

/// The tick's compute with the biliary tree (its tubes' nodes all told) and without (µs).
#[derive(Clone, Debug, Serialize)]
pub struct BiliaryTick {
    pub tube_nodes: usize,
    pub with_tree: HandsTick,
    pub without_tree: HandsTick,
}

/// The tick's compute with the gallbladder's bed and without (µs, as [`HandsTick`]).
#[derive(Clone, Debug, Serialize)]
pub struct BedTick {
    pub ties: usize,
    pub with_bed: HandsTick,
    pub without_bed: HandsTick,
}

/// The tick's compute with so many hands (µs; medians over the repeats of each run's
/// quantiles).
#[derive(Clone, Debug, Serialize)]
pub struct HandsTick {
    pub hands: usize,
    pub contact_ticks: u64,
    /// Ticks the left hand's grasper held an organ.
    pub left_holding_ticks: u64,
    pub tick_p50_us: f64,
    pub tick_p99_us: f64,
    pub tick_max_us: f64,
}

impl From<&SweepFigures> for HandsTick {
    fn from(sweep: &SweepFigures) -> Self {
        Self {
            hands: sweep.hands,
            contact_ticks: sweep.contact_ticks,
            left_holding_ticks: sweep.left_holding_ticks,
            tick_p50_us: sweep.compute_p50_us,
            tick_p99_us: sweep.compute_p99_us,
            tick_max_us: sweep.compute_max_us,
        }
    }
}

/// Runs the benchmark on `scene` (the four organs), each organ pressed as `motion` says,
/// `repeats` times per sweep and `realtime_seconds` per timer; with `hands` 2, the four-organ
/// sweep again with both hands pressing at once.
pub fn run(
    scene: &HapticScene,
    motion: &PressMotion,
    repeats: usize,
    realtime_seconds: f64,
    hands: usize,
) -> Result<HapticBenchReport, FemError> {
    let targets = press_targets(scene);
    let mut sweeps = vec![sweep(scene, "all", &targets, motion, repeats)];
    for ((name, _), target) in scene.organs.iter().zip(&targets) {
        let pressed = std::slice::from_ref(target);
        sweeps.push(sweep(scene, name, pressed, motion, repeats));
    }
    let (one_hand, two_hands) = match hands {
        2 => {
            let both = sweep(&with_left_hand(scene), "all", &targets, motion, repeats);
            let one = HandsTick::from(&sweeps[0]);
            sweeps.push(both);
            (Some(one), sweeps.last().map(HandsTick::from))
        }
        _ => (None, None),
    };
    let bed = bed_tick(scene, &targets, motion, repeats, hands);
    let biliary = biliary_tick(scene, &targets, motion, repeats);
    let fem_contact = fem_contact(&targets[0], repeats, sweeps[0].compute_p50_us)?;
    let render_cpu_ms = render_cpu(scene, &targets, repeats);
    let realtime = [
        (TimerMode::Sleep, Scheduling::Normal),
        (TimerMode::Sleep, Scheduling::RealTime),
        (TimerMode::default(), Scheduling::RealTime),
    ]
    .into_iter()
    .map(|(timer, scheduling)| {
        let device = device(&targets, motion);
        realtime(scene, device, timer, scheduling, realtime_seconds)
    })
    .collect();
    Ok(HapticBenchReport {
        organs: scene.organs.iter().map(|o| o.0.clone()).collect(),
        depth_mm: motion.depth_m * 1e3,
        repeats,
        sweeps,
        fem_contact,
        render_cpu_ms,
        realtime,
        realtime_seconds,
        one_hand,
        two_hands,
        bed,
        biliary,
    })
}

/// The four-organ sweep with the usual biliary tree in the scene and without; none where the
/// scene lacks an organ the tree runs between.
fn biliary_tick(
    scene: &HapticScene,
    targets: &[PressTarget],
    motion: &PressMotion,
    repeats: usize,
) -> Option<BiliaryTick> {
    let between = ["liver", "gallbladder", "duodenum"];
    if !between
        .iter()
        .all(|name| scene.organs.iter().any(|(n, _)| n == name))
    {
        return None;
    }
    let tree = BiliaryEntry::default().tree().ok()?;
    let tube_nodes = tree.tubes.iter().map(|t| t.rod.nodes()).sum();
    let mut with = scene.clone();
    with.biliary = Some(SceneBiliary {
        tree,
        rule: CriticalViewRule::default(),
    });
    let run = |scene: &HapticScene| HandsTick::from(&sweep(scene, "all", targets, motion, repeats));
    Some(BiliaryTick {
        tube_nodes,
        without_tree: run(scene),
        with_tree: run(&with),
    })
}

/// The four-organ sweep with `hands` hands, with the gallbladder tied to the liver by its
/// bed and without; none where the scene lacks either.
fn bed_tick(
    scene: &HapticScene,
    targets: &[PressTarget],
    motion: &PressMotion,
    repeats: usize,
    hands: usize,
) -> Option<BedTick> {
    let mut without = match hands {
        2 => with_left_hand(scene),
        _ => scene.clone(),
    };
    without.beds.clear();
    let mut with = without.clone();
    tie_organs(&mut with, &AttachmentEntry::gallbladder_bed()).ok()?;
    let ties = with.beds[0].bed.ties.len();
    let run = |scene: &HapticScene| HandsTick::from(&sweep(scene, "all", targets, motion, repeats));
    Some(BedTick {
        ties,
        without_bed: run(&without),
        with_bed: run(&with),
    })
}

/// `scene` with a left hand holding a grasper in the open.
fn with_left_hand(scene: &HapticScene) -> HapticScene {
    let mut both = scene.clone();
    both.hands.push(SceneHand {
        instruments: vec![Instrument {
            action: Action::Grasp,
            port: None,
        }],
        ..SceneHand::default()
    });
    both
}

fn device(targets: &[PressTarget], motion: &PressMotion) -> Box<dyn HapticDevice> {
    let trajectory = press_and_slide(targets, motion);
    Box::new(Scripted::new("benchmark sweep", trajectory))
}

/// A device per hand of `scene`: the right sweeps `targets` in order; the left grasps the
/// gallbladder (else the first organ) and holds it drawn out while the right sweeps.
fn devices(
    scene: &HapticScene,
    targets: &[PressTarget],
    motion: &PressMotion,
) -> Vec<Box<dyn HapticDevice>> {
    let mut devices = vec![device(targets, motion)];
    if scene.hands.len() > 1 {
        let mut organs = scene.organs.iter();
        let held = organs.position(|(name, _)| name == "gallbladder");
        let target = &targets[held.unwrap_or(0)];
        let sweep_s = press_and_slide(targets, motion).duration_s();
        let trajectory = grasp_and_hold(target, motion, sweep_s);
        devices.push(Box::new(Scripted::new("benchmark grasp", trajectory)));
    }
    devices
}

fn sweep(
    scene: &HapticScene,
    pressed: &str,
    targets: &[PressTarget],
    motion: &PressMotion,
    repeats: usize,
) -> SweepFigures {
    let ticks = (press_and_slide(targets, motion).duration_s() / TICK_S) as u64;
    let runs: Vec<_> = (0..repeats.max(1))
        .map(|_| {
            let devices = devices(scene, targets, motion);
            let mut haptic = HapticLoop::with_devices(scene, devices).expect("scene was built");
            haptic.run_simulated(ticks)
        })
        .collect();
    let median = |f: &dyn Fn(&TickTimes) -> f64| {
        let mut v: Vec<f64> = runs.iter().map(|r| f(&r.compute)).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    SweepFigures {
        pressed: pressed.to_owned(),
        hands: scene.hands.len(),
        ticks,
        contact_ticks: runs[0].force.contact_ticks,
        left_holding_ticks: runs[0].left_force.as_ref().map_or(0, |f| f.holding_ticks),
        beyond_range_ticks: runs[0].range.beyond_ticks,
        compute_p50_us: median(&|t| t.p50_us),
        compute_p99_us: median(&|t| t.p99_us),
        compute_max_us: median(&|t| t.max_us),
    }
}

/// The liver press of the sweep, solved by full FEM: the force the tick found, applied as the
/// same patch load, one Newton solve on the liver mesh.
fn fem_contact(
    target: &PressTarget,
    repeats: usize,
    tick_p50_us: f64,
) -> Result<FemContact, FemError> {
    let mesh = organs::generate(Organ::Liver, &OrganSettings::default())?;
    let nodes = mesh.node_count();
    let model = pgd::organ::clamped_model(mesh, pgd::organ::material(Organ::Liver, Law::Linear))?;
    let surface = Surface::extract(model.mesh());
    let mut loads = Loads::new(nodes);
    let force_n = target.normal * -0.25;
    loads.add_point_load(
        model.mesh(),
        &surface,
        nalgebra::Point3::from(target.point_m),
        target.normal,
        force_n.into(),
        PressMotion::default().tip_radius_m,
    )?;
    let mut failure = None;
    let newton_ms = median_ms(repeats.max(1), &mut || {
        if let Err(e) = model.solve_static(&loads, &NewtonSettings::default()) {
            failure = Some(e);
        }
    });
    if let Some(e) = failure {
        return Err(e);
    }
    Ok(FemContact {
        organ: "liver",
        nodes,
        newton_ms,
        ratio_to_tick_p50: newton_ms * 1e3 / tick_p50_us,
    })
}

/// What the window does on the CPU per frame, timed: each organ pressed by 0.2 N at its
/// press target, its surface vertices formed and their normals ([`crate::bench::frame`]).
fn render_cpu(scene: &HapticScene, targets: &[PressTarget], repeats: usize) -> f64 {
    let organs: Vec<_> = scene
        .organs
        .iter()
        .zip(targets)
        .map(|((name, v), t)| (name.clone(), v.as_ref(), t.point_m, t.normal))
        .collect();
    crate::bench::frame::run(&organs, 0.2, repeats.max(1) * 4)
        .surface_only
        .p50_ms
}

/// The real-time loop driven by `device` for `seconds` with `timer`, while this thread does
/// what a renderer does on the CPU each 60 Hz frame: read the latest snapshot and form every
/// organ's surface.
fn realtime(
    scene: &HapticScene,
    device: Box<dyn HapticDevice>,
    timer: TimerMode,
    scheduling: Scheduling,
    seconds: f64,
) -> RealTimeReport {
    let mut haptic = HapticLoop::new(scene, device).expect("scene was built");
    let mut snapshots = haptic.publish();
    let thread = HapticThread::spawn(haptic, timer, scheduling).expect("a thread can be spawned");
    let mut surfaces: Vec<(SurfaceModes, Vec<f64>)> = scene
        .organs
        .iter()
        .map(|(_, v)| (SurfaceModes::new(v), vec![0.0; 3 * v.positions.len()]))
        .collect();
    let mut positions = Vec::new();
    let frame = Duration::from_secs_f64(1.0 / 60.0);
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end {
        let started = Instant::now();
        let snapshot = snapshots.read();
        for ((organ, (_, vademecum)), (surface, u)) in
            snapshot.organs.iter().zip(&scene.organs).zip(&mut surfaces)
        {
            organ
                .deformation
                .deformed_surface(vademecum, surface, u, &mut positions);
        }
        std::hint::black_box(&positions);
        std::thread::sleep(frame.saturating_sub(started.elapsed()));
    }
    thread.stop().0
}

impl fmt::Display for HapticBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "haptic loop: {}, each pressed {} mm (medians of {} runs)",
            self.organs.join(", "),
            self.depth_mm,
            self.repeats
        )?;
        writeln!(
            f,
            "{:<14} {:>5} {:>7} {:>8} {:>8} {:>9} {:>9} {:>9}",
            "pressed", "hands", "ticks", "contact", "beyond", "p50 µs", "p99 µs", "max µs"
        )?;
        for s in &self.sweeps {
            writeln!(
                f,
                "{:<14} {:>5} {:>7} {:>8} {:>8} {:>9.1} {:>9.1} {:>9.1}",
                s.pressed,
                s.hands,
                s.ticks,
                s.contact_ticks,
                s.beyond_range_ticks,
                s.compute_p50_us,
                s.compute_p99_us,
                s.compute_max_us
            )?;
        }
        if let (Some(one), Some(two)) = (&self.one_hand, &self.two_hands) {
            writeln!(
                f,
                "two hands at once: tick p99 {:.1} µs against one hand's {:.1} µs ({:.2}x); \
                 the left grasper held for {} ticks",
                two.tick_p99_us,
                one.tick_p99_us,
                two.tick_p99_us / one.tick_p99_us.max(f64::MIN_POSITIVE),
                two.left_holding_ticks
            )?;
        }
        if let Some(bed) = &self.bed {
            writeln!(
                f,
                "the gallbladder tied to the liver ({} ties): tick p99 {:.1} µs against {:.1} µs \
                 untied ({:.2}x)",
                bed.ties,
                bed.with_bed.tick_p99_us,
                bed.without_bed.tick_p99_us,
                bed.with_bed.tick_p99_us / bed.without_bed.tick_p99_us.max(f64::MIN_POSITIVE),
            )?;
        }
        if let Some(biliary) = &self.biliary {
            let (with, without) = (&biliary.with_tree, &biliary.without_tree);
            writeln!(
                f,
                "the biliary tree in the scene ({} tube nodes): tick p50 {:.1} µs, p99 {:.1} µs \
                 against {:.1} µs and {:.1} µs without ({:.2}x at p99)",
                biliary.tube_nodes,
                with.tick_p50_us,
                with.tick_p99_us,
                without.tick_p50_us,
                without.tick_p99_us,
                with.tick_p99_us / without.tick_p99_us.max(f64::MIN_POSITIVE),
            )?;
        }
        writeln!(
            f,
            "render side on the CPU, per frame (four organs pressed: surfaces and normals): {:.2} ms",
            self.render_cpu_ms
        )?;
        let c = &self.fem_contact;
        writeln!(
            f,
            "full FEM, the same liver press ({} nodes, one Newton solve): {:.1} ms = {:.0}x the tick p50",
            c.nodes, c.newton_ms, c.ratio_to_tick_p50
        )?;
        writeln!(
            f,
            "real time, {:.0} s each, render-side CPU work beside it:",
            self.realtime_seconds
        )?;
        for r in &self.realtime {
            writeln!(
                f,
                "  {:?}, {}: lateness p50 {:.1} / p99 {:.1} / max {:.1} µs; period error p99 {:.1} µs; {} skipped of {}",
                r.timer,
                r.scheduling,
                r.lateness.p50_us,
                r.lateness.p99_us,
                r.lateness.max_us,
                r.period_error.p99_us,
                r.skipped,
                r.ticks
            )?;
        }
        Ok(())
    }
}
