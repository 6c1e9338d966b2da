//! The scalpel in the trainer, headless and deterministic: a stroke under the tissue's
//! threshold cuts nothing; one above it cuts along the blade's path; the force stays
//! continuous while cutting but for the give when the tissue parts; the cut organ is softer
//! across the cut than beside it; a press on one lip answers a press on the other as full
//! X-FEM does.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::haptic::{
    ForceTrace, HandTouches, HapticLoop, HapticScene, OrganBody, OrganCut, SceneHand, Tool,
};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::cutting::{CutFace, Enrichment, Front, xfem};
use pgd_surgery::devices::{
    DeviceSample, HapticDevice, Scripted, TICK_S, Trajectory, TrajectoryRow,
};
use pgd_surgery::fem::FemModel;
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

/// The tip at (x, y, z) mm at `t` s.
fn tip_at(t: f64, [x, y, z]: [f64; 3]) -> TrajectoryRow {
    TrajectoryRow::new(t, &DeviceSample::at(Vector3::new(x, y, z) * 1e-3))
}

/// The incision's stroke, then the blade set down on the cut's lip at z = 5.3 mm (5 mm beside
/// it), lightly, under the tissue's threshold; the second hand's probe waits above the liver
/// and then presses the other lip at z = −5.7 mm. Both hold from 10 s.
fn stroke_then_two_lips() -> [Trajectory; 2] {
    let mut blade = stroke(57.8);
    let lip = |y: f64| [35.0, y, 5.3];
    blade.rows.extend([
        tip_at(8.0, lip(85.0)),
        tip_at(9.5, lip(61.5)),
        tip_at(11.0, lip(61.5)),
    ]);
    let other = |y: f64| [35.0, y, -5.7];
    let probe = [
        tip_at(0.0, other(95.0)),
        tip_at(8.0, other(95.0)),
        tip_at(9.5, other(61.0)),
    ];
    let probe = Trajectory {
        rows: [probe.to_vec(), vec![tip_at(11.0, other(61.0))]].concat(),
    };
    [blade, probe]
}

/// Each hand's press on the cut liver as full X-FEM is given it: its patch (mesh nodes), the
/// surface displacement under the tip where the tip holds it (its depth below the rest
/// surface, along the normal), and the force the tick felt.
struct LipPress {
    patch: Vec<(usize, f64)>,
    held_m: Vector3<f64>,
    force_n: Vector3<f64>,
}

/// The two hands' presses on the lips after the stroke, held still, and the faces cut.
fn two_lips() -> ([LipPress; 2], Vec<CutFace>, std::sync::Arc<FemModel>) {
    let scenario = load(&root().join(SCENARIO)).unwrap();
    let mut scene: HapticScene =
        scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    scene.hands.push(SceneHand::default());
    let model = scene
        .cutting
        .as_ref()
        .unwrap()
        .organ(0)
        .unwrap()
        .model
        .clone();
    let devices: Vec<Box<dyn HapticDevice>> = stroke_then_two_lips()
        .into_iter()
        .map(|t| Box::new(Scripted::new("lip", t)) as Box<dyn HapticDevice>)
        .collect();
    let mut haptic = HapticLoop::with_devices(&scene, devices).unwrap();
    haptic.run_simulated((10.5 / TICK_S) as u64);
    let tips = [0, 1].map(|hand| haptic.hand::<Tool>(hand).unwrap().sample.unwrap().tip_m);
    let world = haptic.world_mut();
    let mut organs = world.query::<(&OrganBody, &HandTouches, &OrganCut)>();
    let (body, touches, cut) = organs.iter(world).next().unwrap();
    assert_eq!(body.name, "liver");
    let presses = [0, 1].map(|hand| {
        let touch = &touches.0[hand];
        let contact = touch.contact.expect("each hand presses a lip");
        let positions = &body.vademecum.positions;
        let patch = (touch.patch.shares.iter())
            .map(|&(m, share)| (positions[m] as usize, share))
            .collect();
        let (hit, tip) = (&contact.hit, tips[hand]);
        let depth_m = scene.probe.tip_radius_m - (tip - hit.point_m).dot(&hit.normal);
        LipPress {
            patch,
            held_m: -hit.normal * depth_m,
            force_n: contact.force_n,
        }
    });
    (presses, cut.worker.view().faces.clone(), model)
}

/// The 6 × 6 compliance (m/N) of the two patches on `model` cut by `faces`: block (read,
/// loaded), from full X-FEM solves of a unit force along each axis on each patch.
fn two_patch_compliance(
    model: &FemModel,
    faces: &[CutFace],
    patches: [&[(usize, f64)]; 2],
) -> Matrix6<f64> {
    let mesh = model.mesh();
    let enrichment = Enrichment::with_front(mesh, faces, Front::Nearest);
    let unit = |loaded: usize, axis: usize| {
        let mut f = vec![0.0; 3 * mesh.node_count()];
        (patches[loaded].iter()).for_each(|&(n, share)| f[3 * n + axis] += share);
        f
    };
    let loads: Vec<Vec<f64>> = (0..6).map(|k| unit(k / 3, k % 3)).collect();
    let columns: Vec<&[f64]> = loads.iter().map(Vec::as_slice).collect();
    let solutions = xfem::solve_each(model, &enrichment, &columns).unwrap();
    Matrix6::from_fn(|row, column| {
        let u = &solutions[column].nodes_m;
        let read = patches[row / 3];
        read.iter()
            .map(|&(n, share)| share * u[3 * n + row % 3])
            .sum()
    })
}

/// After the stroke, the blade presses one lip of the cut lightly while the other hand's
/// probe presses the other lip: each hand feels what full X-FEM of the cut liver gives under
/// both presses held where the tips hold them, within the felt-force target (7 %), and
/// closer than if the cut changed only each press's own compliance and left the uncut organ
/// to carry one lip's press to the other.
#[test]
fn a_press_on_one_lip_answers_a_press_on_the_other_as_full_xfem_does() {
    let (presses, faces, model) = two_lips();
    assert!(!faces.is_empty(), "the stroke cut nothing");
    let patches = [presses[0].patch.as_slice(), presses[1].patch.as_slice()];
    let cut = two_patch_compliance(&model, &faces, patches);
    let uncut = two_patch_compliance(&model, &[], patches);
    let held = Vector6::from_iterator(presses.iter().flat_map(|p| p.held_m.iter().copied()));
    let full = cut.lu().solve(&held).unwrap();
    let mut own_only = cut;
    for (read, loaded) in [(0, 1), (1, 0)] {
        let block: Matrix3<f64> = uncut.fixed_view::<3, 3>(3 * read, 3 * loaded).into_owned();
        own_only
            .fixed_view_mut::<3, 3>(3 * read, 3 * loaded)
            .copy_from(&block);
    }
    let own_only = own_only.lu().solve(&held).unwrap();
    let errors = presses.iter().enumerate().map(|(hand, press)| {
        let relative = |forces: &Vector6<f64>| {
            let reference = full.fixed_rows::<3>(3 * hand).into_owned();
            (forces.fixed_rows::<3>(3 * hand) - reference).norm() / reference.norm()
        };
        let felt = Vector6::from_fn(|k, _| {
            if k / 3 == hand {
                press.force_n[k % 3]
            } else {
                0.0
            }
        });
        let (error, without) = (relative(&felt), relative(&own_only));
        eprintln!(
            "hand {hand}: felt {:?} N, error {error:.2e}; the cut's own part alone {without:.2e}",
            press.force_n
        );
        (error, without)
    });
    for (hand, (error, without)) in errors.collect::<Vec<_>>().into_iter().enumerate() {
        assert!(error < 0.07, "hand {hand} off full X-FEM by {error}");
        assert!(
            without > 2.0 * error,
            "hand {hand}: the cut's cross term changes nothing ({without} vs {error})"
        );
    }
}
