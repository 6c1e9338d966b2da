//! The gallbladder's bed in the default scene: ties where the coarse gallbladder faces the
//! liver.

use std::sync::Arc;

use nalgebra::Vector3;
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::haptic::{
    FaultLog, ForceTrace, HapticLoop, HapticScene, OrganBeds, TickClock,
};
use pgd_surgery::app::scene::{Detail, SceneOrgan, press_targets, scene_of, tie_organs};
use pgd_surgery::contact::{ContactSurface, Coupling, CouplingSettings};
use pgd_surgery::devices::{DeviceSample, Scripted, TICK_S, Trajectory, TrajectoryRow};
use pgd_surgery::dissection::{
    Bed, BedError, Cautery, CauteryMode, CohesiveLaw, Tie, TiedOrgans, TissueHeat,
};
use pgd_surgery::mesh::organs::Organ;
use pgd_surgery::pgd::{Deformation, Vademecum, load};
use pgd_surgery::scenario::AttachmentEntry;
use pgd_surgery::store::OnStale;

use super::vademecums;

fn coarse(organ: &str) -> Vademecum {
    load(&vademecums().join(format!("{organ}.coarse.vdm"))).unwrap()
}

/// Within 3 mm the gallbladder's hepatic face is tied to the liver: a few dozen ties over a
/// patch of its surface (not all of it), each where the gallbladder lies within the gap of
/// the liver's surface; the pancreas, which does not face the liver so close, is refused.
#[test]
fn the_gallbladder_lies_in_a_bed_on_the_liver() {
    let (gallbladder, liver) = (coarse("gallbladder"), coarse("liver"));
    let surface = ContactSurface::new(&liver).unwrap();
    let law = CohesiveLaw::gallbladder_bed();
    let bed = Bed::on(law, &gallbladder, &surface, 3e-3).unwrap();
    let whole: f64 = gallbladder
        .position_areas_m2
        .iter()
        .map(|&a| f64::from(a))
        .sum();
    eprintln!(
        "{} ties over {:.1} cm², {:.1} % of the gallbladder's surface",
        bed.ties.len(),
        bed.area_m2() * 1e4,
        100.0 * bed.area_m2() / whole
    );
    assert!(bed.ties.len() >= 20, "{} ties", bed.ties.len());
    assert!(bed.area_m2() < 0.3 * whole);
    for tie in &bed.ties {
        let at = Vector3::from(gallbladder.position_coords_m[tie.position].map(f64::from));
        let hit = surface.closest(&at).unwrap();
        assert!((at - hit.point_m).norm() <= 3e-3);
    }
    let pancreas = coarse("pancreas");
    match Bed::on(law, &pancreas, &surface, 3e-3) {
        Err(BedError::NotFacing { nearest_m, .. }) => assert!(nearest_m > 3e-3),
        Ok(bed) => panic!("the pancreas tied to the liver by {} ties", bed.ties.len()),
    }
}

/// The gallbladder and the liver of the coarse scene, as a coupling with no contact pairs
/// (the ties alone between them), the bed between them and a deformation for each.
struct Tied {
    organs: [Arc<Vademecum>; 2],
    coupling: Coupling,
    tied: TiedOrgans,
    deformations: [Deformation; 2],
}

impl Tied {
    fn new() -> Self {
        let organs = [coarse("gallbladder"), coarse("liver-exponential")].map(Arc::new);
        let named: Vec<(String, Arc<Vademecum>)> = ["gallbladder", "liver"]
            .into_iter()
            .map(String::from)
            .zip(organs.iter().cloned())
            .collect();
        let settings = CouplingSettings {
            master: "none".into(),
            ..CouplingSettings::default()
        };
        let (coupling, _) = Coupling::new(&named, &[], &settings, None).unwrap();
        let surface = ContactSurface::new(&organs[1]).unwrap();
        let bed = Bed::on(CohesiveLaw::gallbladder_bed(), &organs[0], &surface, 3e-3).unwrap();
        let tied = TiedOrgans::new(bed, (0, organs[0].clone()), (1, organs[1].clone()));
        let deformations = [0, 1].map(|o| Deformation::new(&organs[o], 1));
        Self {
            organs,
            coupling,
            tied,
            deformations,
        }
    }

    /// One tick as the contact stage runs it.
    fn tick(&mut self) {
        for (o, deformation) in self.deformations.iter_mut().enumerate() {
            deformation.evaluate(&self.organs[o]);
            self.coupling.read(o, deformation, &[]);
        }
        self.coupling.tick();
        self.tied.tick(&mut self.coupling);
        for (o, deformation) in self.deformations.iter_mut().enumerate() {
            self.coupling.write(o, deformation);
        }
    }

    /// Each organ's field of its modes (the near field of the pull left out).
    fn fields(&self) -> [Vec<f64>; 2] {
        [0, 1].map(|o| modal_field(&self.organs[o], &self.deformations[o]))
    }
}

/// An organ's field of its modes: what its coefficients move, without the near field of its
/// loads.
fn modal_field(vademecum: &Vademecum, deformation: &Deformation) -> Vec<f64> {
    let mut u = vec![0.0; vademecum.dof_count()];
    for (step, coefficients) in deformation.coefficients.iter().enumerate() {
        vademecum.add_modes(step, coefficients, &mut u);
    }
    u
}

/// The displacement (m) of a blend of load positions in a field.
fn blend_moved(vademecum: &Vademecum, u: &[f64], blend: &[(usize, f64)]) -> Vector3<f64> {
    blend
        .iter()
        .map(|&(m, w)| {
            let node = vademecum.positions[m] as usize;
            Vector3::new(u[3 * node], u[3 * node + 1], u[3 * node + 2]) * w
        })
        .sum()
}

/// The gallbladder pulled off the liver at the middle of its bed, 0.2 N over a patch, held:
/// the ties settle within a few hundred ticks, each carrying its secant stiffness times the
/// separation that both organs' fields of modes leave between its ends (to 1e-3 of the
/// largest force); the pulled point moves a hundredth of what it does free, and the liver
/// takes what the gallbladder's ties take.
#[test]
fn the_bed_holds_the_gallbladder_to_the_liver_through_both_organs_fields() {
    let mut tied = Tied::new();
    let centre = tied.tied.bed.ties.len() / 2;
    let tie = tied.tied.bed.ties[centre];
    let pull = tie.normal.into_inner() * 0.2;
    let load = &mut tied.deformations[0].loads[0];
    load.shares = tied.organs[0].patch_centred_on(tie.position);
    load.force_n = pull;
    let mut free = tied.deformations[0].clone();
    free.evaluate(&tied.organs[0]);
    let u = modal_field(&tied.organs[0], &free);
    let free_moved_m = blend_moved(&tied.organs[0], &u, &[(tie.position, 1.0)]);
    let mut last = Vector3::zeros();
    for _ in 0..400 {
        tied.tick();
        let force = tied.tied.report().force_on_freed_n;
        assert!(force.iter().all(|c| c.is_finite()));
        last = force;
    }
    let fields = tied.fields();
    let law = tied.tied.bed.law;
    let mut worst = 0.0f64;
    let mut largest = 0.0f64;
    for (t, force) in tied.tied.bed.ties.iter().zip(tied.tied.forces_n()) {
        let freed = blend_moved(&tied.organs[0], &fields[0], &[(t.position, 1.0)]);
        let corners = tied.organs[1].triangles[t.facing.triangle];
        let facing: Vec<(usize, f64)> = (0..3)
            .map(|c| (corners[c] as usize, t.facing.barycentric[c]))
            .collect();
        let base = blend_moved(&tied.organs[1], &fields[1], &facing);
        let k = law.stiffness_pa_per_m * (1.0 - t.state.damage(&law)) * t.area_m2;
        let expected = -(freed - base) * k;
        worst = worst.max((force - expected).norm());
        largest = largest.max(force.norm());
    }
    let held_moved_m = blend_moved(&tied.organs[0], &fields[0], &[(tie.position, 1.0)]);
    eprintln!(
        "ties take {:.3} N of the 0.2 N pull; worst tie off its law by {:.2e} N of {:.2e} N; \
         the pulled point moves {:.2} mm tied, {:.2} mm free",
        -last.dot(&tie.normal),
        worst,
        largest,
        held_moved_m.norm() * 1e3,
        free_moved_m.norm() * 1e3
    );
    assert!(
        worst <= 1e-3 * largest,
        "worst {worst:e} N of {largest:e} N"
    );
    assert!(held_moved_m.norm() < 0.01 * free_moved_m.norm());
    let liver_force = tied.deformations[1].coupling_force_n;
    assert!((liver_force + last).norm() <= 1e-12 * last.norm().max(1.0));
}

/// The coarse gallbladder on the liver, as the default scene has them (the gallbladder
/// quasi-static, a probe in the hand); tied to the liver by its bed or not.
fn gallbladder_on_liver(tied: bool) -> HapticScene {
    let organs = [Organ::Gallbladder, Organ::Liver].map(|organ| SceneOrgan {
        dynamic: false,
        ..SceneOrgan::from(organ)
    });
    let settings = CouplingSettings::default();
    let dir = vademecums();
    let mut scene = scene_of(
        &organs,
        None,
        &settings,
        dir,
        Detail::Coarse,
        OnStale::Rebuild,
    )
    .unwrap();
    if tied {
        tie_organs(&mut scene, &AttachmentEntry::gallbladder_bed()).unwrap();
    }
    scene
}

/// Down onto the gallbladder along its normal, 6 mm in by 1 s, held to 2 s.
fn press_script(at: Vector3<f64>, normal: Vector3<f64>, tip_radius_m: f64) -> Trajectory {
    let tip = |out_m: f64| at + normal * (tip_radius_m + out_m);
    let keys = [(0.0, 0.005), (1.0, -0.006), (2.0, -0.006)];
    let rows = keys
        .iter()
        .map(|&(t, out)| TrajectoryRow::new(t, &DeviceSample::at(tip(out))))
        .collect();
    Trajectory { rows }
}

/// What a press recorded: the force at the hand each tick, the ties' sum on the
/// gallbladder, and whether the hand faulted.
struct Press {
    force_n: Vec<Vector3<f64>>,
    ties_n: Vec<Vector3<f64>>,
    released: f64,
    faulted: bool,
}

fn press(scene: &HapticScene, script: Trajectory) -> Press {
    let device = Box::new(Scripted::new("press", script));
    let mut haptic = HapticLoop::new(scene, device).unwrap();
    haptic.keep_trace();
    let mut ties_n = Vec::new();
    for tick in 0..2000 {
        haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        let beds = haptic.world_mut().get_resource::<OrganBeds>();
        ties_n.push(beds.map_or(Vector3::zeros(), |b| b.0[0].report().force_on_freed_n));
    }
    let beds = haptic.world_mut().get_resource::<OrganBeds>();
    let released = beds.map_or(0.0, |b| b.0[0].bed.released_share());
    let faulted = haptic.hand::<FaultLog>(0).unwrap().faulted_ticks > 0;
    let trace = std::mem::take(&mut *haptic.hand_mut::<ForceTrace>(0).unwrap());
    Press {
        force_n: trace.desired_n,
        ties_n,
        released,
        faulted,
    }
}

/// The gallbladder pressed 6 mm where it faces the surgeon most, through the haptic loop:
/// tied, it pushes back harder than alone (the ties take part of the press), the ties' forces settle
/// while the press is held (their sum changing by less than 1 % over the last 0.2 s), none
/// fails, and the hand's force stays finite and changes by at most 20 mN a tick; no fault.
#[test]
fn the_bed_holds_the_gallbladder_against_a_press_through_the_loop() {
    let tied = gallbladder_on_liver(true);
    let target = press_targets(&tied)[0];
    let (at, normal) = (target.point_m, target.normal);
    let script = press_script(at, normal, tied.probe.tip_radius_m);
    let with_bed = press(&tied, script.clone());
    let alone = press(&gallbladder_on_liver(false), script);
    let pushed_back = |p: &Press| p.force_n[1999].dot(&normal);
    let largest_change = (with_bed.force_n.windows(2))
        .map(|w| (w[1] - w[0]).norm())
        .fold(0.0, f64::max);
    let ties = |tick: usize| with_bed.ties_n[tick];
    let drift = (ties(1999) - ties(1799)).norm() / ties(1999).norm();
    eprintln!(
        "pushed back {:.3} N tied, {:.3} N alone; ties hold {:.3} N, drifting {:.2e} over 0.2 s; \
         largest change {largest_change:.4} N/tick; released {:.1} %",
        pushed_back(&with_bed),
        pushed_back(&alone),
        ties(1999).norm(),
        drift,
        100.0 * with_bed.released
    );
    assert!(!with_bed.faulted && !alone.faulted);
    assert!(
        with_bed
            .force_n
            .iter()
            .all(|f| f.iter().all(|c| c.is_finite()))
    );
    assert!(pushed_back(&with_bed) > 1.05 * pushed_back(&alone));
    assert!(drift < 0.01);
    assert_eq!(with_bed.released, 0.0);
    assert!(largest_change <= 0.02, "{largest_change} N in a tick");
}

/// The hook held, at 30 W in cut, at the middle of the bed's centre tie, reaching 4 mm: the
/// live ties whose middles are within reach (counted here from the organs' rest surfaces)
/// share its energy, none is divided before the first could have taken its channel's energy
/// (`TissueHeat::tie_burn_j`) at its share, all are divided by the time they could all have
/// taken theirs, and the bed's released share is then their share of its area; 20 mm clear
/// of the bed the hook heats no tie.
#[test]
fn the_hook_divides_the_ties_within_its_reach() {
    let mut tied = Tied::new();
    tied.tick();
    let (gallbladder, liver) = (&tied.organs[0], &tied.organs[1]);
    let middle = |t: &Tie| {
        let freed = Vector3::from(gallbladder.position_coords_m[t.position].map(f64::from));
        (freed + liver.point(&t.facing)) * 0.5
    };
    let centre = tied.tied.bed.ties[tied.tied.bed.ties.len() / 2];
    let tip = middle(&centre);
    let reach_m = 4e-3;
    let within: Vec<Tie> = (tied.tied.bed.ties.iter())
        .filter(|t| (middle(t) - tip).norm() <= reach_m)
        .copied()
        .collect();
    let hook = Cautery::new(CauteryMode::Cut, 30.0).unwrap();
    let tissue = TissueHeat::SOFT_TISSUE;
    let needed_j: Vec<f64> = (within.iter())
        .map(|t| tissue.tie_burn_j(t.area_m2, 2e-3, CauteryMode::Cut))
        .collect();
    let earliest_s =
        needed_j.iter().copied().fold(f64::INFINITY, f64::min) * within.len() as f64 / hook.power_w;
    let latest_s = needed_j.iter().sum::<f64>() / hook.power_w;
    let tick_s = 1e-3;
    let (mut divided, mut first_s, mut heated_first) = (0, None, None);
    for tick in 1..=((latest_s / tick_s) as usize + 2) {
        let outcome = tied
            .tied
            .burn_near(&tip, reach_m, hook.energy_j(tick_s), CauteryMode::Cut);
        heated_first.get_or_insert(outcome.heated);
        if outcome.divided > 0 && first_s.is_none() {
            first_s = Some(tick as f64 * tick_s);
        }
        divided += outcome.divided;
    }
    let released: f64 = within.iter().map(|t| t.area_m2).sum::<f64>() / tied.tied.bed.area_m2();
    eprintln!(
        "{} ties within {} mm; first divided at {:.3} s (earliest {earliest_s:.3} s), all by \
         {latest_s:.3} s; released {:.1} %",
        within.len(),
        reach_m * 1e3,
        first_s.unwrap_or(f64::NAN),
        100.0 * tied.tied.bed.released_share()
    );
    assert!(!within.is_empty());
    assert_eq!(heated_first, Some(within.len()));
    assert!(first_s.unwrap() >= earliest_s - tick_s);
    assert_eq!(divided, within.len());
    assert!((tied.tied.bed.released_share() - released).abs() < 1e-12);
    let clear = tip + centre.normal.into_inner() * 0.02;
    let outcome = tied.tied.burn_near(&clear, reach_m, 1.0, CauteryMode::Cut);
    assert_eq!(outcome.heated, 0);
}

/// The dissection scenario's scene with a right hand that stays clear and a left hand whose
/// grasper closes at 1 s on the gallbladder's anterior face below the bed (at rest), then
/// draws it down and forward, away from the liver, `pull_mm` by `pull_until_s`, where it
/// opens the jaws.
fn pulled_off_the_bed(pull_mm: f64, pull_until_s: f64) -> HapticLoop {
    let (_, scene, devices) = blunt_pull(1.0, pull_mm, pull_until_s);
    HapticLoop::with_devices(&scene, devices).unwrap()
}

/// [`pulled_off_the_bed`]'s scenario, scene and scripted hands, the jaws closing at `from_s`.
fn blunt_pull(
    from_s: f64,
    pull_mm: f64,
    pull_until_s: f64,
) -> (
    pgd_surgery::scenario::Scenario,
    HapticScene,
    Vec<Box<dyn pgd_surgery::devices::HapticDevice>>,
) {
    use pgd_surgery::devices::HapticDevice;
    let scenario = super::shipped("gallbladder-liver-bed-dissection");
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let port = scene.hands[1].instruments[0].port.unwrap();
    let row = |time_s: f64, tip_m: Vector3<f64>, buttons: u32| TrajectoryRow {
        buttons,
        ..TrajectoryRow::new(time_s, &DeviceSample::at(port.handle_for(&tip_m).unwrap()))
    };
    let clear = Vector3::new(0.074892, 0.344516, -0.209355);
    let right = Trajectory {
        rows: vec![TrajectoryRow::new(0.0, &DeviceSample::at(clear))],
    };
    let gallbladder = ContactSurface::new(&scene.organs[1].1).unwrap();
    let edge = gallbladder
        .closest(&Vector3::new(0.045, 0.045, -0.062))
        .unwrap();
    let on = edge.point_m + edge.normal * (scene.probe.tip_radius_m - 0.001);
    let away = on + Vector3::new(0.0, 0.4, -1.0).normalize() * pull_mm * 1e-3;
    let left = Trajectory {
        rows: vec![
            row(0.0, on + edge.normal * 0.01, 0),
            row(from_s - 0.1, on, 0),
            row(from_s, on, 1),
            row(pull_until_s, away, 1),
            row(pull_until_s + 0.001, away, 0),
        ],
    };
    let devices: Vec<Box<dyn HapticDevice>> = vec![
        Box::new(Scripted::new("right", right)),
        Box::new(Scripted::new("left", left)),
    ];
    (scenario, scene, devices)
}

fn tick_at(haptic: &mut HapticLoop, tick: u64) {
    haptic.tick(TickClock {
        tick,
        time_s: tick as f64 * TICK_S,
        overruns_in_a_row: 0,
    });
}

/// The dissection's competent run replayed through the haptic loop: as the hook divides the
/// ties the released share only grows, every tie force and both hands' forces stay finite, and
/// in the ten ticks after a tie is divided the force the physics asks of each hand changes by
/// at most 20 mN a tick (the hook held still while it burns; its own motion in and out of contact steps the
/// force by the tissue's stiffness times its speed, which is the script's, not the bed's).
#[test]
fn the_plane_opens_under_the_hook_without_a_force_step() {
    use pgd_surgery::app::haptic::DeviceForce;
    use pgd_surgery::devices::HapticDevice;
    let root = super::root();
    let scenario = super::shipped("gallbladder-liver-bed-dissection");
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let run = root.join("scenarios/runs/gallbladder-liver-bed-dissection.competent.csv");
    let hands = Trajectory::load_hands(&run).unwrap();
    let ticks = (hands[0].duration_s() / TICK_S) as u64;
    let devices: Vec<Box<dyn HapticDevice>> = (hands.into_iter())
        .map(|hand| Box::new(Scripted::new("run", hand)) as Box<dyn HapticDevice>)
        .collect();
    let mut haptic = HapticLoop::with_devices(&scene, devices).unwrap();
    let mut released = 0.0_f64;
    let mut last_n: [Option<Vector3<f64>>; 2] = [None; 2];
    let mut largest_step_n = [0.0_f64; 2];
    // The last tick a tie was divided in: its force leaves the organs in the ticks after.
    let mut after_division: Option<u64> = None;
    for tick in 0..ticks {
        tick_at(&mut haptic, tick);
        let bed = &haptic.world().resource::<OrganBeds>().0[0];
        let share = bed.bed.released_share();
        assert!(
            share >= released,
            "tick {tick}: healed from {released} to {share}"
        );
        if share > released {
            after_division = Some(tick);
        }
        released = share;
        assert!(
            bed.forces_n()
                .iter()
                .all(|f| f.iter().all(|c| c.is_finite()))
        );
        for hand in 0..2 {
            let desired_n = haptic.hand::<DeviceForce>(hand).unwrap().desired_n;
            assert!(desired_n.iter().all(|c| c.is_finite()), "tick {tick}");
            if let Some(last) = last_n[hand]
                && after_division.is_some_and(|d| tick < d + 10)
            {
                largest_step_n[hand] = largest_step_n[hand].max((desired_n - last).norm());
            }
            last_n[hand] = Some(desired_n);
        }
    }
    eprintln!(
        "{:.1} % released; as ties are divided the hands' forces step {:.2} and {:.2} mN a tick at most",
        100.0 * released,
        largest_step_n[0] * 1e3,
        largest_step_n[1] * 1e3
    );
    assert!(released > 0.33, "{released}");
    assert!(
        largest_step_n.iter().all(|&s| s <= 0.02),
        "{largest_step_n:?} N in a tick"
    );
}

/// Every tie of the bed divided, the grasper draws the gallbladder 30 mm down and forward
/// and opens its jaws: freed, the gallbladder hangs from its duodenal end alone and swings, a
/// point of its hepatic face moving back and forth by millimetres (the motion turning at
/// least twice), the swing dying down from the first second to the fourth, all finite.
#[test]
fn a_freed_gallbladder_hangs_from_what_is_left_and_swings() {
    use pgd_surgery::app::haptic::{OrganBody, OrganMotion};
    let pull_until_s = 4.0;
    let mut haptic = pulled_off_the_bed(30.0, pull_until_s);
    {
        let mut beds = haptic.world_mut().resource_mut::<OrganBeds>();
        let bed = &mut beds.0[0].bed;
        let law = bed.law;
        bed.ties.iter_mut().for_each(|t| t.state.sever(&law));
    }
    for tick in 0..(pull_until_s / TICK_S) as u64 {
        tick_at(&mut haptic, tick);
    }
    // A point of the gallbladder's hepatic face, the first tie's.
    let node = {
        let tie = haptic.world().resource::<OrganBeds>().0[0].bed.ties[0];
        let mut bodies = haptic.world_mut().query::<(&OrganBody, &OrganMotion)>();
        let (body, _) = (bodies.iter(haptic.world()))
            .find(|(b, _)| b.name == "gallbladder")
            .unwrap();
        body.vademecum.positions[tie.position] as usize
    };
    let first = (pull_until_s / TICK_S) as u64;
    let mut swing_m = Vec::new();
    // The jaws open on the second tick.
    tick_at(&mut haptic, first);
    tick_at(&mut haptic, first + 1);
    for tick in first + 2..first + 4002 {
        tick_at(&mut haptic, tick);
        let mut motions = haptic.world_mut().query::<(&OrganBody, &OrganMotion)>();
        let (_, motion) = (motions.iter(haptic.world()))
            .find(|(b, _)| b.name == "gallbladder")
            .unwrap();
        assert!(!motion.organ.holding());
        swing_m.push(motion.moved_at(&[(node, 1.0)]));
    }
    let second = |k: usize| &swing_m[k * 1000..(k + 1) * 1000];
    let range_m = |part: &[Vector3<f64>]| {
        let mean = part.iter().sum::<Vector3<f64>>() / part.len() as f64;
        part.iter().map(|p| (p - mean).norm()).fold(0.0, f64::max)
    };
    let ranges: Vec<f64> = (0..4).map(|k| range_m(second(k))).collect();
    let turns = (swing_m.windows(3))
        .filter(|w| (w[1].x - w[0].x) * (w[2].x - w[1].x) < 0.0)
        .count();
    eprintln!("freed: swing each second {ranges:?} m, the x motion turning {turns} times");
    assert!(swing_m.iter().all(|p| p.iter().all(|c| c.is_finite())));
    assert!(ranges[0] > 1e-3, "{ranges:?}");
    assert!(turns >= 2, "{turns} turns");
    assert!(ranges[3] < ranges[0], "{ranges:?}");
}

/// What the left hand felt over a pull (each tick while its jaws held, then 0.2 s after they
/// open), and the ties' sum on the gallbladder at the end of the pull.
struct Pull {
    force_n: Vec<Vector3<f64>>,
    released_at: usize,
    ties_n: Vector3<f64>,
}

/// The grasper draws the gallbladder 30 mm away from the liver from 1 s to 4 s, its bed whole
/// or every tie divided; what the hand felt until the jaws open.
fn pull_off(severed: bool) -> Pull {
    use pgd_surgery::app::haptic::DeviceForce;
    let pull_until_s = 4.0;
    let mut haptic = pulled_off_the_bed(30.0, pull_until_s);
    if severed {
        let mut beds = haptic.world_mut().resource_mut::<OrganBeds>();
        let bed = &mut beds.0[0].bed;
        let law = bed.law;
        bed.ties.iter_mut().for_each(|t| t.state.sever(&law));
    }
    let mut force_n = Vec::new();
    let released_at = (pull_until_s / TICK_S) as usize;
    let mut ties_n = Vector3::zeros();
    for tick in 0..released_at + 200 {
        tick_at(&mut haptic, tick as u64);
        force_n.push(haptic.hand::<DeviceForce>(1).unwrap().desired_n);
        if tick + 1 == released_at {
            let bed = &haptic.world().resource::<OrganBeds>().0[0];
            ties_n = bed.report().force_on_freed_n;
        }
    }
    Pull {
        force_n,
        released_at,
        ties_n,
    }
}

/// A grasped gallbladder feels its bed: drawn 30 mm away from the liver, it pulls back on the
/// hand at least twice as hard as the same gallbladder with every tie divided (the ties hold
/// its kept modes as well as its static field), the ties' sum on it points back against the
/// pull, and the hand's force stays finite and changes by at most 20 mN a tick, while the jaws
/// hold and as they open (the open jaws press none of the tissue they let go).
#[test]
fn a_grasped_gallbladder_feels_its_bed() {
    let (tied, freed) = (pull_off(false), pull_off(true));
    let last = |p: &Pull| p.force_n[p.released_at - 1].norm();
    let largest_change = (tied.force_n.windows(2))
        .map(|w| (w[1] - w[0]).norm())
        .fold(0.0, f64::max);
    let away = Vector3::new(0.0, 0.4, -1.0).normalize();
    eprintln!(
        "drawn 30 mm: {:.3} N tied, {:.3} N freed; the ties pull back {:.3} N; largest change {:.2} mN a tick",
        last(&tied),
        last(&freed),
        -tied.ties_n.dot(&away),
        largest_change * 1e3
    );
    assert!((tied.force_n.iter().chain(&freed.force_n)).all(|f| f.iter().all(|c| c.is_finite())));
    assert!(last(&tied) >= 2.0 * last(&freed));
    assert!(tied.ties_n.dot(&away) < 0.0);
    assert!(largest_change <= 0.02, "{largest_change} N in a tick");
}

/// A grasper drawing the gallbladder off its bed by the face beside it (blunt dissection):
/// the wall carries the pull to the ties within its reach of the jaws, which go taut and
/// tear, every one of them, before the jaws open;
/// each torn tie counts as released; the work the hand did is at least the fracture energy of
/// the ties torn (the rest is stored or damped); the hand's force stays finite and changes by
/// at most 20 mN a tick.
#[test]
fn a_grasper_tears_the_ties_near_its_jaws() {
    use pgd_surgery::app::haptic::{DeviceForce, Tool};
    let pull_until_s = 4.0;
    let mut haptic = pulled_off_the_bed(30.0, pull_until_s);
    let (mut gripped, mut most_taut_n, mut torn) = (0, 0.0_f64, 0);
    let (mut work_j, mut largest_change, mut last_force) = (0.0, 0.0_f64, Vector3::zeros());
    let mut last_tip: Option<Vector3<f64>> = None;
    for tick in 0..(pull_until_s / TICK_S) as usize {
        tick_at(&mut haptic, tick as u64);
        let force = haptic.hand::<DeviceForce>(1).unwrap().desired_n;
        let tip = haptic.hand::<Tool>(1).unwrap().hand.unwrap().tip_m;
        if let Some(last) = last_tip {
            work_j -= 0.5 * (force + last_force).dot(&(tip - last));
        }
        assert!(force.iter().all(|f| f.is_finite()), "tick {tick}");
        largest_change = largest_change.max((force - last_force).norm());
        (last_tip, last_force) = (Some(tip), force);
        let report = *haptic.world().resource::<OrganBeds>().0[0].wall_report();
        gripped = gripped.max(report.strands);
        most_taut_n = most_taut_n.max(report.force_on_jaws_n.norm());
        torn += report.torn;
    }
    let bed = &haptic.world().resource::<OrganBeds>().0[0].bed;
    let failed: Vec<&pgd_surgery::dissection::Tie> = bed
        .ties
        .iter()
        .filter(|t| t.state.failed(&bed.law))
        .collect();
    let fracture_j: f64 = (failed.iter())
        .map(|t| t.area_m2 * bed.law.fracture_energy_j_per_m2)
        .sum();
    let released = bed.released_share();
    eprintln!(
        "blunt: {gripped} ties gripped, {torn} torn ({:.1} % of the bed); the wall pulled up to {most_taut_n:.3} N; \
         the hand's work {:.2} mJ against {:.2} mJ of fracture; largest change {:.2} mN a tick",
        100.0 * released,
        work_j * 1e3,
        fracture_j * 1e3,
        largest_change * 1e3
    );
    assert!(gripped >= 3, "{gripped} ties within the wall's reach");
    assert_eq!(torn, gripped);
    assert_eq!(failed.len(), torn);
    assert!(released > 0.0);
    assert!(work_j >= fracture_j, "{work_j} J for {fracture_j} J");
    assert!(largest_change <= 0.02, "{largest_change} N in a tick");
}

/// Blunt dissection scored: the same pull as an attempt at the dissection exercise, made once
/// the retraction task has run out (15 s, the jaws open all along): the ties it tears count as
/// released for the `Dissection` task, which reports them torn (none divided, no energy) and
/// says so in its summary.
#[test]
fn the_dissection_counts_the_ties_a_pull_tears() {
    use pgd_surgery::app::attempt::run_simulated;
    use pgd_surgery::scenario::tasks::DissectionResult;
    let (scenario, scene, devices) = blunt_pull(16.0, 30.0, 19.0);
    let outcome = run_simulated(scenario, &scene, devices, 20_000).unwrap();
    let metrics = &outcome.card.tasks[1].metrics;
    let done = metrics.result::<DissectionResult>().unwrap();
    let summary = pgd_surgery::report::summary(&outcome.card);
    eprintln!("{summary}");
    assert!(done.ties_torn >= 3, "{} torn", done.ties_torn);
    assert_eq!(done.ties_divided, 0);
    assert_eq!(done.energy.total_j, 0.0);
    assert!(done.released_share > 0.0);
    assert!(
        summary.contains(&format!("0 ties divided, {} torn", done.ties_torn)),
        "{summary}"
    );
}
