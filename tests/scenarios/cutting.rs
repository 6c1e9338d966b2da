//! The scalpel in the trainer, headless and deterministic: a stroke under the tissue's
//! threshold cuts nothing; one above it cuts along the blade's path; the force stays
//! continuous while cutting but for the give when the tissue parts; the cut organ is softer
//! across the cut than beside it.

use nalgebra::Vector3;
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::haptic::{ForceTrace, HapticLoop, OrganBody, OrganCut};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::devices::{DeviceSample, Scripted, TICK_S, Trajectory, TrajectoryRow};
use pgd_surgery::scenario::load;
use pgd_surgery::store::OnStale;

use super::{root, vademecums};

const SCENARIO: &str = "scenarios/liver-capsule-incision.scenario.ron";

/// What a headless run of the incision scene with `trajectory` leaves: every tick's force,
/// the liver's strokes and cut, and its felt compliance along the normal (m/N) at the
/// line's middle and 12 mm beside it, uncut and cut.
struct Cutting {
    trace: ForceTrace,
    strokes: Vec<pgd_surgery::cutting::Stroke>,
    unknowns: usize,
    threshold_n: f64,
    across: [f64; 2],
    beside: [f64; 2],
}

fn cut_with(trajectory: Trajectory) -> Cutting {
    let scenario = load(&root().join(SCENARIO)).unwrap();
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let ticks = ((trajectory.duration_s() + 0.1) / TICK_S).ceil() as u64;
    let device = Box::new(Scripted::new("stroke", trajectory));
    let mut haptic = HapticLoop::new(&scene, device).unwrap();
    haptic.keep_trace();
    haptic.run_simulated(ticks);
    let trace = std::mem::take(&mut *haptic.hand_mut::<ForceTrace>(0).unwrap());
    let world = haptic.world_mut();
    let mut organs = world.query::<(&OrganBody, &OrganCut)>();
    let (body, liver) = organs
        .iter(world)
        .find(|(body, _)| body.name == "liver")
        .expect("the liver is cut");
    let compliance = |at_mm: [f64; 3]| normal_compliance(body, liver, at_mm);
    Cutting {
        trace,
        strokes: liver.scalpel.strokes().to_vec(),
        unknowns: liver.worker.view().unknowns,
        threshold_n: liver.scalpel.threshold_n(),
        across: compliance([35.0, 59.0, 0.3]),
        beside: compliance([35.0, 59.0, 12.3]),
    }
}

/// The patch compliance along the surface's normal (m/N) at the accessible point nearest
/// `at_mm`, of the uncut organ and of the organ as `cut` has cut it.
fn normal_compliance(body: &OrganBody, cut: &OrganCut, at_mm: [f64; 3]) -> [f64; 2] {
    let vademecum = &body.vademecum;
    let hit = body
        .surface
        .closest(&(Vector3::from(at_mm) * 1e-3))
        .unwrap();
    let patch = vademecum.patch(&hit.at);
    let nodes: Vec<(usize, f64)> = patch
        .shares
        .iter()
        .map(|&(m, share)| (vademecum.positions[m] as usize, share))
        .collect();
    let uncut = vademecum.compliance(&patch, &Vector3::zeros());
    let mut y = Default::default();
    let cut = uncut + cut.worker.view().added_compliance(&nodes, &mut y);
    let n = hit.normal;
    [(n.transpose() * uncut * n)[0], (n.transpose() * cut * n)[0]]
}

/// The blade set down on the line's start at (22, y, 0.3) mm, pressed to a tip height of
/// `press_y_mm`, drawn to x = 48 mm, and lifted.
fn stroke(press_y_mm: f64) -> Trajectory {
    let at = |t: f64, x: f64, y: f64| {
        TrajectoryRow::new(t, &DeviceSample::at(Vector3::new(x, y, 0.3) * 1e-3))
    };
    Trajectory {
        rows: vec![
            at(0.0, 22.0, 85.0),
            at(1.0, 22.0, 60.0),
            at(1.5, 22.0, press_y_mm),
            at(5.5, 48.0, press_y_mm - 1.8),
            at(6.0, 48.0, press_y_mm - 1.8),
            at(7.0, 48.0, 85.0),
        ],
    }
}

#[test]
fn a_stroke_under_the_threshold_cuts_nothing() {
    let light = cut_with(stroke(62.0));
    let peak = light
        .trace
        .desired_n
        .iter()
        .map(|f| f.norm())
        .fold(0.0, f64::max);
    eprintln!(
        "peak {peak:.3} N under a threshold of {:.3} N",
        light.threshold_n
    );
    assert!(peak > 0.2 && peak < light.threshold_n, "peak {peak} N");
    assert!(light.strokes.is_empty(), "{:?}", light.strokes);
    assert_eq!(light.unknowns, 0);
}

/// Pressed past the threshold, the blade cuts from where the tissue gave to within a step
/// of where it stopped, on the path (the blade's edge along it) within 0.5 mm across.
#[test]
fn a_stroke_above_the_threshold_cuts_along_the_blade() {
    let cut = cut_with(stroke(57.8));
    assert_eq!(cut.strokes.len(), 1, "{:?}", cut.strokes);
    let stroke = cut.strokes[0];
    let [sx, _, sz] = stroke.start_m.map(|c| c * 1e3);
    let [ex, _, ez] = stroke.end_m.map(|c| c * 1e3);
    eprintln!(
        "cut from x = {sx:.2} to {ex:.2} mm, {:.2} mm long, {:.2} mm deep; {} enriched unknowns",
        stroke.length_m * 1e3,
        stroke.max_depth_m * 1e3,
        cut.unknowns
    );
    assert!((20.0..26.0).contains(&sx), "the tissue gave at x = {sx} mm");
    assert!(48.0 - ex < 2.0 && ex < 48.5, "the cut ended at x = {ex} mm");
    assert!(
        (sz - 0.3).abs() < 0.5 && (ez - 0.3).abs() < 0.5,
        "across: {sz}, {ez} mm"
    );
    assert!(cut.unknowns > 0, "the cut enriched nothing");
}

/// Tick to tick the force changes by at most 20 mN while the blade presses and cuts, but
/// for the give when the tissue parts (and each segment's give after it): the drops that
/// follow a cut step, which are drops, never rises.
#[test]
fn the_force_is_continuous_but_for_the_give() {
    let cut = cut_with(stroke(57.8));
    let forces: Vec<f64> = cut.trace.desired_n.iter().map(|f| f.norm()).collect();
    let jumps: Vec<(usize, f64)> = forces
        .windows(2)
        .enumerate()
        .map(|(k, w)| (k + 1, w[1] - w[0]))
        .filter(|(_, d)| d.abs() > 0.02)
        .collect();
    eprintln!("jumps above 20 mN: {jumps:?}");
    let give = jumps.first().map_or(0, |j| j.0);
    let largest = forces
        .windows(2)
        .enumerate()
        .filter(|(k, _)| k + 1 != give)
        .map(|(_, w)| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    eprintln!("largest change but the give: {largest:.4} N");
    assert!(jumps.iter().all(|(_, d)| *d < 0.0), "a rise: {jumps:?}");
    let give = jumps.first().expect("the tissue gave");
    assert!(
        forces[give.0 - 1] >= cut.threshold_n,
        "gave below the threshold"
    );
}

/// The cut liver still deforms under the tool, and is softer across the cut than beside it:
/// its felt compliance grows at the line's middle more than 12 mm beside it.
#[test]
fn the_cut_organ_is_softer_across_the_cut_than_beside_it() {
    let cut = cut_with(stroke(57.8));
    let softer = |[uncut, cut]: [f64; 2]| cut / uncut;
    let (across, beside) = (softer(cut.across), softer(cut.beside));
    eprintln!(
        "compliance across the cut {:.4e} → {:.4e} m/N (×{across:.3}), beside it ×{beside:.3}",
        cut.across[0], cut.across[1]
    );
    assert!(cut.across[1] > 0.0 && cut.beside[1] > 0.0);
    assert!(
        across > 1.02,
        "the cut does not soften the tissue across it: ×{across}"
    );
    assert!(
        across > beside,
        "softer beside the cut (×{beside}) than across it (×{across})"
    );
}
