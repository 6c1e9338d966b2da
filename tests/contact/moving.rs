//! Contact and attachments with organs that move: the duodenum grasped, pulled and let go
//! carries the pancreas through its swing; a gallbladder swinging up into the liver pushes it.
//! The references are the moving organ's own displacement (its static field plus its kept
//! modes, not their fit in the vademecum's modes that the coupling reads) and the exact
//! geometry of the moved surface.

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{HapticLoop, HapticScene, OrganMotion, TickClock};
use pgd_surgery::app::scene::{Detail, SceneOrgan, scene_of};
use pgd_surgery::contact::CouplingSettings;
use pgd_surgery::devices::{
    DeviceSample, PressTarget, Scripted, TICK_S, Trajectory, TrajectoryRow,
};
use pgd_surgery::mesh::organs::Organ;
use pgd_surgery::pgd::Vademecum;
use pgd_surgery::store::OnStale;

use crate::common::{carrier_point_near, organ, scene, vademecums};
use crate::exact_distance;

/// The coarse scene with `moving` under reduced dynamics, on the shared vademecums.
fn scene_moving(moving: Organ) -> HapticScene {
    let dir = vademecums();
    scene(); // builds the vademecums if they are missing
    let organs = Organ::ABDOMEN.map(|o| SceneOrgan {
        dynamic: o == moving,
        ..super::linear(o)
    });
    scene_of(
        &organs,
        None,
        &CouplingSettings::default(),
        &dir,
        Detail::Coarse,
        OnStale::Refuse,
    )
    .unwrap()
}

/// Ticks `haptic` once, at tick `tick`.
fn tick(haptic: &mut HapticLoop, tick: u64) {
    haptic.tick(TickClock {
        tick,
        time_s: tick as f64 * TICK_S,
        overruns_in_a_row: 0,
    });
}

/// The moving organ's whole displacement at its load position `m`: its static field there
/// (`field`) plus its kept modes' correction.
fn moved_at(vademecum: &Vademecum, motion: &OrganMotion, field: &[f64], m: usize) -> Vector3<f64> {
    let at = 3 * vademecum.positions[m] as usize;
    let mut u = Vector3::from_column_slice(&field[at..at + 3]);
    for (k, &c) in motion.correction.iter().enumerate() {
        u += Vector3::from_column_slice(&motion.model.basis.mode(k)[at..at + 3]) * c;
    }
    u
}

/// The hand at `target`: above it by 10 mm, 4 mm in by 0.5 s, jaws closed at 1.0 s, out to
/// 15 mm above the rest surface by 1.5 s, held to 2.0 s, opened, 1.5 s more.
fn grasp_pull_release(target: &PressTarget, tip_radius_m: f64) -> Trajectory {
    let tip = |height_m: f64| target.point_m + target.normal * (tip_radius_m + height_m);
    let keys = [
        (0.0, 0.01, 0),
        (0.5, -0.004, 0),
        (1.0, -0.004, 0),
        (1.0, -0.004, 1),
        (1.5, 0.015, 1),
        (2.0, 0.015, 1),
        (2.0, 0.015, 0),
        (3.5, 0.015, 0),
    ];
    let rows = keys
        .iter()
        .map(|&(t, height, buttons)| {
            let sample = DeviceSample {
                buttons,
                ..DeviceSample::at(tip(height))
            };
            TrajectoryRow::new(t, &sample)
        })
        .collect();
    Trajectory { rows }
}

/// The duodenum, moving, grasped 3 cm from the pancreas's interface, pulled 15 mm out and let
/// go: through its swing the pancreas is carried by the duodenum's whole motion, not just its
/// static field (which vanishes once the jaws open). Over the 1.5 s after the release, the rms
/// mismatch between the interface's displacement and the carry stays under a quarter of the
/// interface's rms motion, as for a static press (`the_pancreas_moves_with_the_duodenum_…`).
#[test]
fn the_pancreas_follows_the_duodenum_as_it_swings() {
    let scene = scene_moving(Organ::Duodenum);
    let (d, duodenum) = organ("duodenum");
    let (p, _) = organ("pancreas");
    let coupling = scene.coupling.as_ref().unwrap();
    let attachment = coupling
        .attachments
        .iter()
        .find(|a| (a.carrier, a.carried) == (d, p))
        .unwrap();
    let interface = attachment.interface().to_vec();
    let target = carrier_point_near(duodenum, &interface, 0.03);
    let script = grasp_pull_release(&target, scene.probe.tip_radius_m);
    let mut haptic = HapticLoop::new(&scene, Box::new(Scripted::new("grasp", script))).unwrap();
    let mut field = vec![0.0; duodenum.dof_count()];
    let (mut moved, mut mismatch, mut largest, mut count) = (0.0, 0.0, 0.0_f64, 0.0);
    let mut grasped = false;
    for t in 0..3500 {
        tick(&mut haptic, t);
        let world = haptic.world_mut();
        let mut organs = world.query::<(
            &pgd_surgery::app::haptic::OrganIndex,
            &pgd_surgery::app::haptic::OrganDeformation,
            Option<&OrganMotion>,
        )>();
        let mut duodenum_state = None;
        let mut carry = None;
        for (index, deformation, motion) in organs.iter(world) {
            if index.0 == d {
                deformation.0.field_into(duodenum, &mut field);
                duodenum_state = motion;
            } else if index.0 == p {
                carry = Some(deformation.0.carry);
            }
        }
        let (motion, carry) = (duodenum_state.unwrap(), carry.unwrap());
        grasped |= motion.organ.holding();
        if t < 2020 {
            continue;
        }
        for &m in &interface {
            let u = moved_at(duodenum, motion, &field, m);
            let x = Vector3::from(duodenum.position_coords_m[m].map(f64::from));
            moved += u.norm_squared();
            mismatch += (u - carry.at(&x)).norm_squared();
            largest = largest.max(u.norm());
            count += 1.0;
        }
    }
    let (moved, mismatch) = ((moved / count).sqrt(), (mismatch / count).sqrt());
    eprintln!(
        "after the release: interface moved {:.3} mm rms (largest {:.3} mm), the pancreas differs by {:.3} mm rms",
        moved * 1e3,
        largest * 1e3,
        mismatch * 1e3
    );
    assert!(grasped, "the jaws never took hold");
    assert!(largest > 0.5e-3, "the duodenum hardly swung: {largest}");
    assert!(mismatch < 0.25 * moved);
}

/// The gallbladder, moving, set swinging up into the liver along its kept mode that lifts it
/// most (8 mm at its largest), the tool far away: in the very next tick the liver feels the
/// contact, pushed the way the gallbladder moves, where the exact geometry of the moved
/// gallbladder (static field plus kept modes, as a triangle surface) holds liver points
/// inside it.
#[test]
fn a_swinging_gallbladder_pushes_the_liver() {
    let scene = scene_moving(Organ::Gallbladder);
    let (g, gallbladder) = organ("gallbladder");
    let (l, liver) = organ("liver");
    let away = Vector3::new(0.0, 0.0, 0.5);
    let still = Trajectory {
        rows: vec![
            TrajectoryRow::new(0.0, &DeviceSample::at(away)),
            TrajectoryRow::new(1.0, &DeviceSample::at(away)),
        ],
    };
    let mut haptic = HapticLoop::new(&scene, Box::new(Scripted::new("away", still))).unwrap();
    let world = haptic.world_mut();
    let mut motions = world.query::<&mut OrganMotion>();
    let mut motion = motions.single_mut(world).unwrap();
    let positions = &gallbladder.positions;
    let lift = |k: usize| {
        let mode = motion.model.basis.mode(k);
        positions
            .iter()
            .map(|&n| mode[3 * n as usize + 2])
            .sum::<f64>()
    };
    let k = (0..motion.model.basis.len())
        .max_by(|&a, &b| lift(a).abs().total_cmp(&lift(b).abs()))
        .unwrap();
    let largest = positions
        .iter()
        .map(|&n| {
            Vector3::from_column_slice(&motion.model.basis.mode(k)[3 * n as usize..][..3]).norm()
        })
        .fold(0.0, f64::max);
    let amplitude = 0.008 / largest * lift(k).signum();
    motion.organ.state.q[k] = amplitude;
    let mode = motion.model.basis.mode(k).to_vec();
    tick(&mut haptic, 0);

    let moved: Vec<[f32; 3]> = positions
        .iter()
        .zip(&gallbladder.position_coords_m)
        .map(|(&n, rest)| {
            let at = 3 * n as usize;
            [0, 1, 2].map(|c| rest[c] + (amplitude * mode[at + c]) as f32)
        })
        .collect();
    let mesh = pgd_surgery::parry_interop::trimesh(&moved, &gallbladder.triangles).unwrap();
    let inside = liver
        .position_coords_m
        .iter()
        .map(|p| exact_distance(&mesh, &Vector3::from(p.map(f64::from))))
        .filter(|&d| d < 0.0 && d > -0.01)
        .count();
    let world = haptic.world_mut();
    let coupling = &world
        .resource::<pgd_surgery::app::haptic::OrganCoupling>()
        .0;
    let pair = coupling
        .pairs
        .iter()
        .find(|pair| (pair.master, pair.shell) == (g, l))
        .unwrap()
        .report();
    eprintln!(
        "liver points inside the moved gallbladder: {inside}; the pair: {} nodes in contact, {:.1} mm deepest, force on the liver {:.3?} N",
        pair.nodes_in_contact,
        pair.deepest_m * 1e3,
        pair.force_on_shell_n.as_slice()
    );
    assert!(inside > 0, "the swing was meant to reach into the liver");
    assert!(pair.nodes_in_contact > 0);
    assert!(
        pair.force_on_shell_n.z > 0.0,
        "the liver is pushed up, as the gallbladder moves"
    );
}
