//! A coarse liver (a quarter of the papers' node count, ~11 mm edges), its FEM model and its
//! linear vademecum for a 12 mm tool (a tool patch must be wider than the edges under it),
//! built once per test run; and scripted runs of a haptic world over it.

use std::sync::{Arc, OnceLock};

use nalgebra::{Matrix3, Point3, Vector3};
use pgd_surgery::app::haptic::{ForceTrace, HapticLoop, HapticScene};
use pgd_surgery::app::scene::press_targets;
use pgd_surgery::contact::Probe;
use pgd_surgery::devices::{
    HapticDevice, PressMotion, PressTarget, SafetySettings, Scripted, Trajectory, press_and_slide,
};
use pgd_surgery::fem::{FemModel, Law, Loads, NewtonSettings, PatchKernel};
use pgd_surgery::mesh::Surface;
use pgd_surgery::mesh::organs::{Organ, OrganSettings, generate, region};
use pgd_surgery::pgd::{
    BuildSettings, OrganModel, Silent, Vademecum, build, default_load_steps_m, organ,
};

pub const TIP_RADIUS_M: f64 = 0.012;

pub struct Liver {
    pub model: FemModel,
    pub vademecum: Arc<Vademecum>,
}

pub fn liver() -> &'static Liver {
    static LIVER: OnceLock<Liver> = OnceLock::new();
    LIVER.get_or_init(|| coarse_liver(Law::Linear))
}

/// The coarse liver under the trainer's exponential law, its vademecum with the law's default
/// load steps for the 12 mm tool.
pub fn exponential_liver() -> &'static Liver {
    static LIVER: OnceLock<Liver> = OnceLock::new();
    LIVER.get_or_init(|| coarse_liver(Law::Exponential))
}

fn coarse_liver(law: Law) -> Liver {
    let settings = OrganSettings {
        resolution: 0.25,
        seed: 1,
        ..OrganSettings::default()
    };
    let mesh = generate(Organ::Liver, &settings).unwrap();
    let material = organ::material(Organ::Liver, law);
    let model = organ::clamped_model(mesh, material).unwrap();
    let source = OrganModel {
        source: "liver".into(),
        model: &model,
        clamped_region: region::CLAMPED.into(),
        accessible_region: region::ACCESSIBLE.into(),
    };
    let settings = BuildSettings {
        tool_tip_radius_m: TIP_RADIUS_M,
        local_radius_m: 0.025,
        load_steps_m: default_load_steps_m(Some(Organ::Liver), TIP_RADIUS_M, law),
        ..BuildSettings::default()
    };
    let vademecum = build(&source, &settings, &Silent).unwrap().0;
    Liver {
        vademecum: Arc::new(vademecum),
        model,
    }
}

pub fn scene(safety: SafetySettings) -> HapticScene {
    let probe = Probe {
        tip_radius_m: TIP_RADIUS_M,
    };
    let organs = vec![("liver".into(), liver().vademecum.clone())];
    HapticScene {
        safety,
        ..HapticScene::pressing(organs, probe)
    }
}

/// Where the built-in demo presses the liver.
pub fn target() -> PressTarget {
    press_targets(&scene(SafetySettings::default()))[0]
}

/// A press-and-slide with the test tool.
pub fn press(motion: &PressMotion) -> Trajectory {
    let motion = PressMotion {
        tip_radius_m: TIP_RADIUS_M,
        ..*motion
    };
    press_and_slide(&[target()], &motion)
}

/// A haptic world over the liver served by `device`, keeping its force trace.
pub fn haptic(device: Box<dyn HapticDevice>, safety: SafetySettings) -> HapticLoop {
    let mut haptic = HapticLoop::new(&scene(safety), device).unwrap();
    haptic.keep_trace();
    haptic
}

pub fn scripted(trajectory: Trajectory) -> Box<dyn HapticDevice> {
    Box::new(Scripted::new("test script", trajectory))
}

/// Runs `ticks` simulated ticks and returns the force trace.
pub fn run(haptic: &mut HapticLoop, ticks: u64) -> ForceTrace {
    haptic.run_simulated(ticks);
    std::mem::take(&mut *haptic.hand_mut::<ForceTrace>(0).unwrap())
}

/// The tick (1 ms each) at time `s`.
pub fn tick_at(s: f64) -> u64 {
    (s * 1000.0).round() as u64
}

/// The mesh nodes and shares of full FEM's patch load at `point`, on the side of the surface
/// `facing` faces.
pub fn fem_patch(point: Point3<f64>, facing: &Vector3<f64>) -> Vec<(usize, f64)> {
    let mesh = liver().model.mesh();
    let radius = liver().vademecum.header.settings.tool_tip_radius_m;
    let kernel = PatchKernel::new(mesh, &Surface::extract(mesh), radius).unwrap();
    kernel.shares(point, facing).unwrap()
}

/// Full FEM's 3 × 3 compliance (m/N) from the patch load `loaded` to the patch `read`: the
/// displacement averaged over `read` under unit forces along each axis spread over `loaded`.
pub fn fem_response(loaded: &[(usize, f64)], read: &[(usize, f64)]) -> Matrix3<f64> {
    let mut c = Matrix3::zeros();
    for d in 0..3 {
        let unit = PatchForce {
            patch: loaded,
            force_n: Vector3::ith(d, 1.0),
        };
        let u = fem_displacement(&liver().model, &[unit]);
        c.set_column(d, &patch_average(&u, read));
    }
    c
}

/// A force spread over a patch of the FEM mesh by the patch's shares.
pub struct PatchForce<'a> {
    pub patch: &'a [(usize, f64)],
    pub force_n: Vector3<f64>,
}

/// Full FEM's displacement (m, three per node) of `model` under forces each spread over a
/// patch.
pub fn fem_displacement(model: &FemModel, forces: &[PatchForce<'_>]) -> Vec<f64> {
    let mut loads = Loads::new(model.mesh().node_count());
    for PatchForce { patch, force_n } in forces {
        for &(node, share) in *patch {
            let f = force_n * share;
            loads.add_nodal_force(node, [f.x, f.y, f.z]).unwrap();
        }
    }
    let solved = model.solve_static(&loads, &NewtonSettings::default());
    solved.unwrap().displacement_m
}

/// The displacement `u` averaged over a patch by its shares.
pub fn patch_average(u: &[f64], patch: &[(usize, f64)]) -> Vector3<f64> {
    patch.iter().fold(Vector3::zeros(), |acc, &(n, s)| {
        acc + Vector3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]) * s
    })
}
