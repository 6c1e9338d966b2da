//! A coarse liver (a quarter of the papers' node count, ~11 mm edges), its FEM model and its
//! linear vademecum for a 12 mm tool (a tool patch must be wider than the edges under it),
//! built once per test run; and scripted runs of a haptic world over it.

use std::sync::{Arc, OnceLock};

use pgd_surgery::app::haptic::{ForceTrace, HapticLoop, HapticScene};
use pgd_surgery::app::scene::press_targets;
use pgd_surgery::contact::Probe;
use pgd_surgery::devices::{
    HapticDevice, PressMotion, PressTarget, SafetySettings, Scripted, Trajectory, press_and_slide,
};
use pgd_surgery::fem::{FemModel, Law};
use pgd_surgery::mesh::organs::{Organ, OrganSettings, generate, region};
use pgd_surgery::pgd::{BuildSettings, OrganModel, Silent, Vademecum, build, organ};

pub const TIP_RADIUS_M: f64 = 0.012;

pub struct Liver {
    pub model: FemModel,
    pub vademecum: Arc<Vademecum>,
}

pub fn liver() -> &'static Liver {
    static LIVER: OnceLock<Liver> = OnceLock::new();
    LIVER.get_or_init(|| {
        let settings = OrganSettings {
            resolution: 0.25,
            seed: 1,
            ..OrganSettings::default()
        };
        let mesh = generate(Organ::Liver, &settings).unwrap();
        let material = organ::material(Organ::Liver, Law::Linear);
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
            ..BuildSettings::default()
        };
        let vademecum = build(&source, &settings, &Silent).unwrap().0;
        Liver {
            vademecum: Arc::new(vademecum),
            model,
        }
    })
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
