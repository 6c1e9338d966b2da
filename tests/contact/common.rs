//! The coarse abdominal scene (all four organs, coupled, linear), built once per test run,
//! and a scripted push run through the haptic schedule with what each tick left recorded.

use std::path::PathBuf;
use std::sync::OnceLock;

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{
    HapticLoop, HapticScene, OrganCoupling, OrganDeformation, OrganIndex, TickClock,
};
use pgd_surgery::app::scene::{Detail, SceneOrgan, scene_of};
use pgd_surgery::contact::{CouplingSettings, PairReport, PointshellDensity};
use pgd_surgery::devices::{PressTarget, Scripted, TICK_S, Trajectory, TrajectoryRow};
use pgd_surgery::fem::Law;
use pgd_surgery::mesh::organs::Organ;
use pgd_surgery::pgd::{Deformation, Vademecum};
use pgd_surgery::store::OnStale;

/// `organ` with linear tissue: the full-FEM references here are linear.
pub fn linear(organ: Organ) -> SceneOrgan {
    SceneOrgan {
        law: Law::Linear,
        ..SceneOrgan::from(organ)
    }
}

/// Where the linear coarse organs are kept: a folder of the tests' shared cache, apart from
/// the scenarios' organs of the same names and other settings.
pub fn vademecums() -> PathBuf {
    crate::cache::vademecum_cache().join("contact")
}

pub fn scene() -> &'static HapticScene {
    static SCENE: OnceLock<HapticScene> = OnceLock::new();
    SCENE.get_or_init(|| {
        let dir = vademecums();
        let organs = Organ::ABDOMEN.map(linear);
        let coupling = CouplingSettings::default();
        scene_of(
            &organs,
            None,
            &coupling,
            &dir,
            Detail::Coarse,
            OnStale::Rebuild,
        )
        .unwrap()
    })
}

pub fn organ(name: &str) -> (usize, &'static Vademecum) {
    let index = scene().organs.iter().position(|(n, _)| n == name).unwrap();
    (index, &scene().organs[index].1)
}

/// The accessible point of `name` whose normal is closest to `direction`.
pub fn facing(name: &str, direction: Vector3<f64>) -> PressTarget {
    let (_, vademecum) = organ(name);
    let normals = vademecum.rest_normals();
    let best = (0..normals.len())
        .max_by(|&a, &b| {
            normals[a]
                .dot(&direction)
                .total_cmp(&normals[b].dot(&direction))
        })
        .unwrap();
    target(vademecum, best)
}

fn target(vademecum: &Vademecum, m: usize) -> PressTarget {
    PressTarget {
        point_m: Vector3::from(vademecum.position_coords_m[m].map(f64::from)),
        normal: vademecum.rest_normals()[m],
    }
}

/// An accessible point of `name` facing `direction` (normal within about 35° of it), as far as
/// can be from `clear_of`'s surface, so that a tool pressing there touches `name` alone.
pub fn facing_clear_of(name: &str, direction: Vector3<f64>, clear_of: &str) -> PressTarget {
    let (_, vademecum) = organ(name);
    let (_, other) = organ(clear_of);
    let at = |v: &Vademecum, m: usize| Vector3::from(v.position_coords_m[m].map(f64::from));
    let clearance = |m: usize| {
        (0..other.positions.len())
            .map(|o| (at(vademecum, m) - at(other, o)).norm())
            .fold(f64::INFINITY, f64::min)
    };
    let normals = vademecum.rest_normals();
    let best = (0..normals.len())
        .filter(|&m| normals[m].dot(&direction) > 0.8)
        .max_by(|&a, &b| clearance(a).total_cmp(&clearance(b)))
        .unwrap();
    target(vademecum, best)
}

/// A point of the carrier's accessible surface facing +y, `distance_m` from the centre of an
/// attachment's `interface` (carrier positions).
pub fn carrier_point_near(
    carrier: &Vademecum,
    interface: &[usize],
    distance_m: f64,
) -> PressTarget {
    let at = |m: usize| Vector3::from(carrier.position_coords_m[m].map(f64::from));
    let centre = interface.iter().map(|&m| at(m)).sum::<Vector3<f64>>() / interface.len() as f64;
    let normals = carrier.rest_normals();
    let off = |m: usize| ((at(m) - centre).norm() - distance_m).abs();
    let nearest = (0..carrier.positions.len())
        .filter(|&m| normals[m].y > 0.5)
        .min_by(|&a, &b| off(a).total_cmp(&off(b)))
        .unwrap();
    target(carrier, nearest)
}

/// The tool comes from 5 mm off `target` and pushes `depth_m` into it along its normal over
/// `push_s`, then holds for `hold_s`.
pub fn push(target: &PressTarget, depth_m: f64, push_s: f64, hold_s: f64) -> Trajectory {
    let radius_m = scene().probe.tip_radius_m;
    let centre = |depth: f64| target.point_m + target.normal * (radius_m - depth);
    let row = |time_s: f64, p: Vector3<f64>| TrajectoryRow {
        time_s,
        x_m: p.x,
        y_m: p.y,
        z_m: p.z,
        buttons: 0,
        qx: 0.0,
        qy: 0.0,
        qz: 0.0,
        qw: 1.0,
    };
    Trajectory {
        rows: vec![
            row(0.0, centre(-0.005)),
            row(push_s, centre(depth_m)),
            row(push_s + hold_s, centre(depth_m)),
        ],
    }
}

/// What one tick left: each pair's report and each organ's deformation.
pub struct Tick {
    pub pairs: Vec<(usize, usize, PairReport)>,
    pub organs: Vec<Deformation>,
}

/// The same scene with a dense pointshell on the liver and the other organs.
pub fn dense_scene() -> &'static HapticScene {
    static SCENE: OnceLock<HapticScene> = OnceLock::new();
    SCENE.get_or_init(|| {
        scene_with(&CouplingSettings {
            pointshell: PointshellDensity::Dense,
            ..CouplingSettings::default()
        })
    })
}

/// The same scene with the liver's and the other organs' nodes thinned to 15 mm apart.
pub fn sparse_scene() -> &'static HapticScene {
    static SCENE: OnceLock<HapticScene> = OnceLock::new();
    SCENE.get_or_init(|| {
        scene_with(&CouplingSettings {
            pointshell: PointshellDensity::Sparse(15),
            ..CouplingSettings::default()
        })
    })
}

/// The same scene measuring every pointshell node within reach every tick, none skipped as
/// known clear.
pub fn measuring_every_node_scene() -> &'static HapticScene {
    static SCENE: OnceLock<HapticScene> = OnceLock::new();
    SCENE.get_or_init(|| {
        let mut settings = CouplingSettings::default();
        settings.penalty.skip_clear_nodes = false;
        scene_with(&settings)
    })
}

/// The coarse scene with other coupling settings, on the same vademecums.
fn scene_with(settings: &CouplingSettings) -> HapticScene {
    let dir = vademecums();
    scene(); // builds the vademecums if they are missing
    let organs = Organ::ABDOMEN.map(linear);
    scene_of(
        &organs,
        None,
        settings,
        &dir,
        Detail::Coarse,
        OnStale::Refuse,
    )
    .unwrap()
}

/// Runs `trajectory` through the coupled scene's haptic schedule, tick by tick.
pub fn run(trajectory: Trajectory, ticks: u64) -> (HapticLoop, Vec<Tick>) {
    run_on(scene(), trajectory, ticks)
}

/// [`run`] on `scene`.
pub fn run_on(scene: &HapticScene, trajectory: Trajectory, ticks: u64) -> (HapticLoop, Vec<Tick>) {
    let device = Box::new(Scripted::new("push", trajectory));
    let mut haptic = HapticLoop::new(scene, device).unwrap();
    let mut record = Vec::new();
    for tick in 0..ticks {
        haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        record.push(observe(&mut haptic));
    }
    (haptic, record)
}

fn observe(haptic: &mut HapticLoop) -> Tick {
    let world = haptic.world_mut();
    let pairs = world
        .resource::<OrganCoupling>()
        .0
        .pairs
        .iter()
        .map(|p| (p.master, p.shell, *p.report()))
        .collect();
    let mut organs: Vec<(usize, Deformation)> = world
        .query::<(&OrganIndex, &OrganDeformation)>()
        .iter(world)
        .map(|(i, d)| (i.0, d.0.clone()))
        .collect();
    organs.sort_by_key(|o| o.0);
    Tick {
        pairs,
        organs: organs.into_iter().map(|o| o.1).collect(),
    }
}

/// The largest nodal displacement (m) of an organ's field.
pub fn largest_displacement_m(vademecum: &Vademecum, deformation: &Deformation) -> f64 {
    let mut field = vec![0.0; vademecum.dof_count()];
    deformation.field_into(vademecum, &mut field);
    field
        .chunks_exact(3)
        .map(|u| Vector3::new(u[0], u[1], u[2]).norm())
        .fold(0.0, f64::max)
}
