//! One attempt at a scenario: its scene (organs, tool, device limit), its exercise inside
//! the haptic world, and the scorecard when every task has ended or the device's script has.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use nalgebra::Vector3;

use super::haptic::{
    ExerciseLink, ExerciseRun, HapticLoop, HapticScene, OrganBody, OrganCut, SceneAssistant,
    SceneBiliary, SceneHand, SceneScope, SettleCuts, TickClock, view_record,
};
use super::scene::{Detail, SceneOrgan, scene_files, scene_of, scene_vademecums, tie_organs};
use crate::contact::{ContactSurface, CouplingSettings};
use crate::devices::{HapticDevice, Instrument, ScopeHandle, TICK_S, Workspace, stop_requested};
use crate::mesh::organs::Organ;
use crate::scenario::tasks::RadialKeratotomy;
use crate::scenario::{
    self, Assistant, CutMade, Exercise, Keratometer, LaparoscopeEntry, Nodule, NoduleSite,
    OrganEntry, Port, RegionSite, Scenario, Scorecard, Sites, Task, Tool, score,
};
use crate::store::{OnStale, OrganSource, VademecumSpec};

/// The scene a scenario asks for, its vademecums from `dir`.
pub fn scenario_scene(
    scenario: &Scenario,
    dir: &Path,
    detail: Detail,
    on_stale: OnStale,
) -> Result<HapticScene, String> {
    let organs = scenario_organs(scenario)?;
    let tip = scenario.tip_radius_m();
    let mut scene = scene_of(
        &organs,
        Some(tip),
        &coupling_of(scenario),
        dir,
        detail,
        on_stale,
    )?;
    scene.safety.max_force_n = scenario.device.max_force_n.0;
    let workspace = Workspace {
        scale: scenario.device.workspace_scale.0,
    };
    scene.hands = (scenario.hands().iter())
        .map(|instruments| SceneHand {
            instruments: instruments.iter().map(instrument).collect(),
            workspace,
        })
        .collect();
    scene.assistant = (scenario.assistant.as_ref())
        .map(scene_assistant)
        .transpose()?;
    scene.scope = scenario.laparoscope.as_ref().and_then(scene_scope);
    if let (Some(cutting), Some(blade)) = (&mut scene.cutting, scenario.blade()) {
        cutting.blade = blade;
    }
    for attachment in &scenario.attachments {
        tie_organs(&mut scene, attachment)?;
    }
    if let Some(entry) = &scenario.biliary {
        scene.biliary = Some(SceneBiliary {
            tree: entry.tree().map_err(|e| format!("biliary tree: {e}"))?,
            rule: entry.critical_view,
        });
    }
    Ok(scene)
}

/// The scenario's assistant as the haptic loop moves it.
fn scene_assistant(assistant: &Assistant) -> Result<SceneAssistant, String> {
    let script = (assistant.trajectory())
        .ok_or("the assistant's script: a tip out of its instrument's reach")?;
    Ok(SceneAssistant {
        port: assistant.port.fulcrum(),
        script,
    })
}

/// An instrument of the scenario's as the haptic loop holds it.
fn instrument((tool, port): &(Tool, Option<Port>)) -> Instrument {
    Instrument {
        action: tool.action(),
        port: port.as_ref().map(Port::fulcrum),
    }
}

/// The files [`scenario_scene`] reads from `dir` (see [`scene_files`]).
pub fn scenario_files(
    scenario: &Scenario,
    dir: &Path,
    detail: Detail,
) -> Result<Vec<PathBuf>, String> {
    let organs = scenario_organs(scenario)?;
    let tip = Some(scenario.tip_radius_m());
    Ok(scene_files(
        &organs,
        tip,
        &coupling_of(scenario),
        dir,
        detail,
    ))
}

/// The vademecums [`scenario_scene`] loads from `dir`, one per organ in the scenario's order
/// (see [`scene_vademecums`]).
pub fn scenario_vademecums(
    scenario: &Scenario,
    dir: &Path,
    detail: Detail,
) -> Result<Vec<VademecumSpec>, String> {
    let organs = scenario_organs(scenario)?;
    let tip = Some(scenario.tip_radius_m());
    Ok(scene_vademecums(&organs, tip, dir, detail))
}

fn scenario_organs(scenario: &Scenario) -> Result<Vec<SceneOrgan>, String> {
    scenario
        .organs
        .iter()
        .map(|entry| scene_organ(scenario, entry))
        .collect()
}

/// The scenario's laparoscope, aimed at its focus (a scenario that loaded has been checked
/// to aim).
fn scene_scope(entry: &LaparoscopeEntry) -> Option<SceneScope> {
    Some(SceneScope {
        scope: entry.laparoscope(),
        pose: Arc::new(ScopeHandle::new(entry.start()?)),
        keep_in_view_m: entry.keep_in_view_mm.map(scenario::metres),
        script: entry.script(),
    })
}

/// The contact a scenario asks for, the defaults where it says nothing.
fn coupling_of(scenario: &Scenario) -> CouplingSettings {
    let mut settings = CouplingSettings {
        pointshell: scenario.contact.pointshell,
        ..CouplingSettings::default()
    };
    if let Some(master) = &scenario.contact.master {
        settings.master = master.clone();
    }
    if let Some(spacing) = scenario.contact.lattice_mm {
        settings.distance.spacing_m = spacing.metres();
    }
    settings
}

/// The scene's organ a scenario's entry describes, with its nodules in its tissue.
fn scene_organ(scenario: &Scenario, entry: &OrganEntry) -> Result<SceneOrgan, String> {
    let name = &entry.name;
    let source = match entry.mesh_file() {
        Some(file) => OrganSource::File(file),
        None => OrganSource::Generated(
            Organ::from_name(name).ok_or_else(|| format!("there is no organ `{name}`"))?,
        ),
    };
    Ok(SceneOrgan {
        name: name.clone(),
        source,
        young_pa: entry.young_pa.map(|e| e.0),
        poisson: entry.poisson_ratio.map(|nu| nu.0),
        max_modes: entry.max_modes.map(|n| n.0),
        law: scenario.law_of(entry),
        stiffening: entry.stiffening.map(|b| b.0),
        dynamic: scenario.moves(entry),
        cut_toughness_j_per_m2: scenario.cut_toughness_j_per_m2(entry),
        inclusions: scenario
            .nodules
            .iter()
            .filter(|nodule| &nodule.organ == name)
            .map(Nodule::inclusion)
            .collect(),
    })
}

/// What an attempt at a scenario leaves: the scorecard and the force against time (100 Hz).
#[derive(Clone, Debug)]
pub struct Outcome {
    pub card: Scorecard,
    pub force_trace: Vec<(f64, f64)>,
}

/// Runs `scenario` on a simulated clock with `device` until every task has ended or
/// `max_ticks` have run (the script's end), then scores it.
pub fn run_simulated(
    scenario: Scenario,
    scene: &HapticScene,
    devices: Vec<Box<dyn HapticDevice>>,
    max_ticks: u64,
) -> Result<Outcome, String> {
    run_observed(scenario, scene, devices, max_ticks, |_, _| {})
}

/// [`run_simulated`], handing `observe` the loop and its compute time after every tick.
pub fn run_observed(
    scenario: Scenario,
    scene: &HapticScene,
    devices: Vec<Box<dyn HapticDevice>>,
    max_ticks: u64,
    observe: impl FnMut(&HapticLoop, Duration),
) -> Result<Outcome, String> {
    let haptic = HapticLoop::with_devices(scene, devices).map_err(|e| e.to_string())?;
    observe_attempt(scenario, scene, haptic, max_ticks, observe).map(|(outcome, _)| outcome)
}

/// [`run_observed`] in a world already built (one that has taken another's device), handing
/// the world back when the attempt has been scored.
pub fn observe_attempt(
    scenario: Scenario,
    scene: &HapticScene,
    mut haptic: HapticLoop,
    max_ticks: u64,
    mut observe: impl FnMut(&HapticLoop, Duration),
) -> Result<(Outcome, HapticLoop), String> {
    haptic.world_mut().insert_resource(SettleCuts);
    let sites = sites_on(scene, &scenario);
    prepare(&mut haptic, Exercise::new(scenario, sites)).start();
    for tick in 0..max_ticks {
        if stop_requested() {
            break;
        }
        let compute = haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        observe(&haptic, compute);
        if haptic.world().resource::<ExerciseRun>().exercise.is_none() {
            break;
        }
    }
    let outcome = end(&mut haptic).ok_or("the exercise was never begun")?;
    Ok((outcome, haptic))
}

/// Puts `exercise` into the haptic world; it is scored from the tick after the link returned
/// is started.
pub fn prepare(haptic: &mut HapticLoop, exercise: Exercise) -> Arc<ExerciseLink> {
    let link = Arc::new(ExerciseLink::default());
    link.offer(exercise);
    haptic
        .world_mut()
        .insert_resource(ExerciseRun::new(link.clone()));
    link
}

/// Where `scenario`'s nodules and watched regions lie on `scene`'s organs.
pub fn sites_on(scene: &HapticScene, scenario: &Scenario) -> Sites {
    Sites {
        nodules: scenario
            .nodules
            .iter()
            .map(|nodule| nodule_site(scene, nodule))
            .collect(),
        regions: scenario
            .tasks
            .iter()
            .map(|task| region_site(scene, task))
            .collect(),
        keratometers: scenario
            .tasks
            .iter()
            .map(|task| keratometer(scene, scenario, task))
            .collect(),
        critical_view: (scene.biliary.as_ref())
            .map(|biliary| view_record(biliary, &scene.organs, &scene.beds)),
    }
}

/// The cut cornea's model a keratotomy `task` predicts its correction with (`None` for other
/// tasks, or a cornea the scene does not cut, which validation refuses).
fn keratometer(scene: &HapticScene, scenario: &Scenario, task: &Task) -> Option<Keratometer> {
    task.get::<RadialKeratotomy>()?;
    let organ = task.organ()?;
    let index = scenario.organs.iter().position(|o| o.name == organ)?;
    scene.cutting.as_ref()?.organ(index)?.keratometer.clone()
}

/// Where `nodule` lies under its organ's surface: the outward normal at the accessible point
/// nearest its centre (straight up when the organ is not in the scene, which validation
/// refuses).
fn nodule_site(scene: &HapticScene, nodule: &Nodule) -> NoduleSite {
    let centre_m = nodule.centre_m();
    let vademecum = scene.organs.iter().find(|(name, _)| name == &nodule.organ);
    let outward = vademecum
        .and_then(|(_, vademecum)| {
            let distance = |k: usize| {
                (Vector3::from(vademecum.position_coords_m[k].map(f64::from)) - centre_m).norm()
            };
            let nearest = (0..vademecum.positions.len())
                .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))?;
            Some(vademecum.rest_normals()[nearest])
        })
        .unwrap_or_else(Vector3::z);
    NoduleSite { centre_m, outward }
}

/// Where a retraction or grasp `task` watches its organ: the accessible surface point nearest the
/// scenario's point (`None` for other tasks, or an organ not in the scene, which validation
/// refuses).
fn region_site(scene: &HapticScene, task: &Task) -> Option<RegionSite> {
    let watched = task.watched()?;
    let index = scene
        .organs
        .iter()
        .position(|(name, _)| name == watched.organ)?;
    let surface = ContactSurface::new(&scene.organs[index].1).ok()?;
    let (x, y, z) = watched.towards;
    Some(RegionSite {
        organ: index,
        at: surface.closest(&scenario::metres(watched.at_mm))?.at,
        towards: Vector3::new(x, y, z).try_normalize(0.0)?,
    })
}

/// Takes the exercise out of the haptic world (or from the link, if it ended and nobody took
/// it), ends it and scores it; `None` if none ran or it was taken already.
pub fn end(haptic: &mut HapticLoop) -> Option<Outcome> {
    let run = haptic.world_mut().remove_resource::<ExerciseRun>()?;
    let mut outcome = run.into_exercise().map(outcome_of)?;
    outcome.card.cuts = cuts_made(haptic);
    Some(outcome)
}

/// The scalpel's strokes on every organ, in the scene's order.
pub fn cuts_made(haptic: &mut HapticLoop) -> Vec<CutMade> {
    let world = haptic.world_mut();
    let mut query = world.query::<(&OrganBody, &OrganCut)>();
    let mm = |v: [f64; 3]| v.map(|c| c * 1e3);
    query
        .iter(world)
        .flat_map(|(body, cut)| {
            cut.scalpel.strokes().iter().map(|stroke| CutMade {
                organ: body.name.clone(),
                start_mm: mm(stroke.start_m),
                end_mm: mm(stroke.end_m),
                length_mm: stroke.length_m * 1e3,
                max_depth_mm: stroke.max_depth_m * 1e3,
            })
        })
        .collect()
}

/// Ends `exercise` (unfinished tasks are not completed) and scores it.
pub fn outcome_of(exercise: Exercise) -> Outcome {
    let finished = exercise.finish();
    let mut card = score(&finished.scenario, finished.tasks);
    card.critical_view = finished.critical_view;
    Outcome {
        card,
        force_trace: finished.force_trace,
    }
}
