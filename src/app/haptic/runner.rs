//! The haptic world and its schedule, and the simulated-clock run behind `--headless`.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

// The browser's clock in a web page (std's has none there), the OS's elsewhere.
use bevy::platform::time::Instant;

use bevy::prelude::*;

use super::components::{
    OrganBody, OrganDeformation, OrganIndex, OrganMotion, ToolTouch, organ_with_law,
};
use super::cutting::{OrganCut, SettleCuts};
use super::report::{ForceSummary, HeadlessReport, RangeSummary};
use super::resources::{
    Device, DeviceForce, FaultLog, ForceTrace, GraspForce, OrganCoupling, Safety, SceneScope,
    Scope, TickClock, Tool,
};
use super::snapshot::{HapticSnapshot, OrganSnapshot, SnapshotPublisher};
use crate::contact::{ContactError, ContactSurface, Coupling, Probe};
use crate::cutting::{Blade, CutError, CutWorker, LatestCut, Scalpel};
use crate::devices::{
    Fulcrum, HapticDevice, Histogram, Instrument, Rack, SafetyFilter, SafetySettings, TICK_S,
    Workspace, stop_requested,
};
use crate::dynamics::{DynamicModel, GraspSettings};
use crate::fem::FemModel;
use crate::pgd::{Deformation, Vademecum};
use crate::scenario::Keratometer;

/// What the haptic world is made of.
#[derive(Clone)]
pub struct HapticScene {
    /// Organ names and vademecums, in the scene's order.
    pub organs: Vec<(String, Arc<Vademecum>)>,
    pub probe: Probe,
    pub workspace: Workspace,
    pub safety: SafetySettings,
    /// Organ/organ contact and attachments (set up, at rest); `None` leaves the organs apart.
    pub coupling: Option<Arc<Coupling>>,
    /// Organs that move, and the grasper that pulls them; `None`: every organ quasi-static and
    /// the tool a probe.
    pub dynamics: Option<SceneDynamics>,
    /// The organs the tool cuts, when it is a scalpel.
    pub cutting: Option<SceneCutting>,
    /// The instruments, the first in hand at the start: through a port the device moves its
    /// handle (laparoscopy); otherwise its tip (open surgery).
    pub instruments: Vec<Instrument>,
    /// The laparoscope, if the trainee looks through one.
    pub scope: Option<SceneScope>,
    /// The nonlinear vademecums building in the background while their organs run linear
    /// tissue here: the window loads the scene again once they are built.
    pub meanwhile: Vec<PathBuf>,
}

impl HapticScene {
    /// `organs` pressed by `probe` in open surgery and nothing more: the organs apart, still
    /// and uncut, no laparoscope, the default workspace and safety.
    pub fn pressing(organs: Vec<(String, Arc<Vademecum>)>, probe: Probe) -> Self {
        Self {
            organs,
            probe,
            workspace: Workspace::default(),
            safety: SafetySettings::default(),
            coupling: None,
            dynamics: None,
            cutting: None,
            instruments: vec![Instrument::default()],
            scope: None,
            meanwhile: Vec::new(),
        }
    }

    /// A 6 mm probe over no organ: a loop that serves a device and nothing else.
    pub fn without_organs() -> Self {
        let probe = Probe {
            tip_radius_m: 0.006,
        };
        Self::pressing(Vec::new(), probe)
    }

    /// The ports of the instruments that go through one.
    pub fn ports(&self) -> impl Iterator<Item = Fulcrum> + '_ {
        self.instruments.iter().filter_map(|i| i.port)
    }
}

/// The scalpel's blade and the organs it cuts.
#[derive(Clone)]
pub struct SceneCutting {
    pub blade: Blade,
    pub organs: Vec<CutOrgan>,
}

/// An organ the scalpel cuts.
#[derive(Clone)]
pub struct CutOrgan {
    /// Its place among the scene's organs.
    pub index: usize,
    /// Its linear finite-element model, which its cut state is solved on.
    pub model: Arc<FemModel>,
    pub toughness_j_per_m2: f64,
    /// Its latest cut, for the window to draw (the haptic thread never touches it).
    pub drawn: Arc<LatestCut>,
    /// A cornea's model under the intraocular pressure, which predicts a keratotomy's
    /// correction.
    pub keratometer: Option<Keratometer>,
}

impl SceneCutting {
    /// Organ `index` (by the scene's order), if the scalpel cuts it.
    pub fn organ(&self, index: usize) -> Option<&CutOrgan> {
        self.organs.iter().find(|o| o.index == index)
    }
}

/// The moving organs of a scene (by index into its organs) and the grasper's settings.
#[derive(Clone)]
pub struct SceneDynamics {
    pub organs: Vec<(usize, Arc<DynamicModel>)>,
    pub grasp: GraspSettings,
}

impl SceneDynamics {
    /// The dynamic model of organ `index`, if it moves.
    pub fn model(&self, index: usize) -> Option<&Arc<DynamicModel>> {
        self.organs
            .iter()
            .find(|(i, _)| *i == index)
            .map(|(_, m)| m)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error(transparent)]
    Contact(#[from] ContactError),
    #[error(transparent)]
    Cut(#[from] CutError),
    /// Safety settings the filter cannot honour (a negative force limit would reverse the force).
    #[error("the scene's safety settings: {0}")]
    Safety(String),
}

/// The safety settings of a loop that has no device yet.
#[derive(Resource, Clone, Copy)]
struct Parked(SafetySettings);

/// A haptic `World` of organ entities and the schedule that ticks it.
pub struct HapticLoop {
    world: World,
    schedule: Schedule,
}

impl HapticLoop {
    pub fn new(scene: &HapticScene, device: Box<dyn HapticDevice>) -> Result<Self, SceneError> {
        let mut haptic = Self::parked(scene)?;
        haptic.world.remove_resource::<Parked>();
        let limits = device.limits();
        haptic.world.insert_resource(Device(device));
        haptic
            .world
            .insert_resource(Safety(SafetyFilter::new(scene.safety, limits)));
        Ok(haptic)
    }

    /// A world for `scene` without a device, to be built away from the haptic thread (its
    /// contact surfaces take milliseconds) and then take over a running loop's device with
    /// [`HapticLoop::take_device`]. Ticked without one, it would panic.
    pub fn parked(scene: &HapticScene) -> Result<Self, SceneError> {
        scene.safety.check().map_err(SceneError::Safety)?;
        let mut world = World::new();
        for (index, (name, vademecum)) in scene.organs.iter().enumerate() {
            let mut organ = world.spawn((
                OrganBody {
                    name: name.clone(),
                    surface: Arc::new(ContactSurface::new(vademecum)?),
                    vademecum: vademecum.clone(),
                },
                OrganIndex(index),
                ToolTouch::reserved(vademecum),
                OrganDeformation(Deformation::new(vademecum, 1)),
            ));
            if let Some(dynamics) = &scene.dynamics
                && let Some(model) = dynamics.model(index)
            {
                let positions = vademecum.positions.len();
                organ.insert(OrganMotion::new(model.clone(), dynamics.grasp, positions));
            }
            if let Some(cutting) = &scene.cutting
                && let Some(cut) = cutting.organ(index)
            {
                let scalpel = Scalpel::new(cutting.blade, cut.toughness_j_per_m2);
                let worker = CutWorker::spawn(cut.model.clone(), name, cut.drawn.clone())?;
                organ.insert(OrganCut::new(scalpel, worker, vademecum.positions.len()));
            }
        }
        world.insert_resource(GraspForce::default());
        world.insert_resource(Tool {
            probe: scene.probe,
            workspace: scene.workspace,
            rack: Rack::new(&scene.instruments),
            hand: None,
            pose: None,
            sample: None,
        });
        world.insert_resource(TickClock::default());
        world.insert_resource(DeviceForce::default());
        world.insert_resource(FaultLog::default());
        world.insert_resource(Parked(scene.safety));
        if let Some(coupling) = &scene.coupling {
            let coupling = coupling.clone_reserved(&scene.organs);
            let mut deformations = world.query::<&mut OrganDeformation>();
            for mut deformation in deformations.iter_mut(&mut world) {
                coupling.reserve_output(&mut deformation.0);
            }
            world.insert_resource(OrganCoupling(coupling));
        }
        if let Some(scope) = &scene.scope {
            world.insert_resource(Scope::new(scope.clone()));
        }
        Ok(Self {
            world,
            schedule: super::haptic_schedule(),
        })
    }

    /// Takes `running`'s device and its safety filter (retuned to this scene's settings), so
    /// that the force the hand feels carries over the change of scene at the allowed rate.
    /// Does nothing if this loop has a device already or `running` has none.
    pub fn take_device(&mut self, running: &mut HapticLoop) {
        let Some(Parked(settings)) = self.world.get_resource::<Parked>().copied() else {
            return;
        };
        let (Some(device), Some(mut safety)) = (
            running.world.remove_resource::<Device>(),
            running.world.remove_resource::<Safety>(),
        ) else {
            return;
        };
        safety.0.retune(settings, device.0.limits());
        self.world.remove_resource::<Parked>();
        self.world.insert_resource(device);
        self.world.insert_resource(safety);
    }

    /// Keeps every tick's forces in a [`ForceTrace`].
    pub fn keep_trace(&mut self) {
        self.world.insert_resource(ForceTrace::default());
    }

    /// Starts publishing a snapshot every tick; the returned end reads the latest, and until
    /// the first tick, the organs at rest.
    pub fn publish(&mut self) -> triple_buffer::Output<HapticSnapshot> {
        let mut organs: Vec<(usize, OrganSnapshot)> = self
            .world
            .query::<(&OrganIndex, &OrganDeformation)>()
            .iter(&self.world)
            .map(|(index, deformation)| {
                let organ = OrganSnapshot {
                    deformation: deformation.0.clone(),
                    contact: None,
                    motion: Vec::new(),
                    grasped: false,
                    strokes: Vec::new(),
                };
                (index.0, organ)
            })
            .collect();
        organs.sort_by_key(|(index, _)| *index);
        let template = HapticSnapshot {
            organs: organs.into_iter().map(|(_, organ)| organ).collect(),
            ..HapticSnapshot::default()
        };
        let (input, output) = triple_buffer::triple_buffer(&template);
        self.world.insert_resource(SnapshotPublisher(input));
        output
    }

    pub fn world(&self) -> &World {
        &self.world
    }

    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// Runs one tick at `clock`; returns its compute time.
    pub fn tick(&mut self, clock: TickClock) -> Duration {
        let started = Instant::now();
        *self.world.resource_mut::<TickClock>() = clock;
        self.schedule.run(&mut self.world);
        started.elapsed()
    }

    /// Runs `ticks` ticks on a simulated clock (tick k at k ms), as fast as they compute:
    /// deterministic, whatever the machine is doing. Overruns are counted, not fed to the
    /// safety filter, so that a slow machine does not change the forces.
    pub fn run_simulated(&mut self, ticks: u64) -> HeadlessReport {
        self.world.insert_resource(SettleCuts);
        let mut compute = Histogram::default();
        let mut forces = ForceSummary::default();
        let mut range = RangeSummary::default();
        let mut ran = 0;
        for tick in 0..ticks {
            if stop_requested() {
                break;
            }
            ran += 1;
            let time = self.tick(TickClock {
                tick,
                time_s: tick as f64 * TICK_S,
                overruns_in_a_row: 0,
            });
            compute.record(time);
            let force = *self.world.resource::<DeviceForce>();
            let mut touching = false;
            for (body, touch) in self
                .world
                .query::<(&OrganBody, &ToolTouch)>()
                .iter(&self.world)
            {
                let Some(contact) = &touch.contact else {
                    continue;
                };
                touching = true;
                let valid_m = body.vademecum.valid_indentation_m();
                range.record(&body.name, contact.beyond_range_m, valid_m);
            }
            forces.record(&force, touching);
        }
        let (device, organs) = (self.device_name(), self.organ_names());
        let log = self.world.resource::<FaultLog>();
        HeadlessReport::new(device, organs, log, ran, forces, range, &compute)
    }

    pub(super) fn device_name(&self) -> String {
        self.world.resource::<Device>().0.name().to_owned()
    }

    fn organ_names(&mut self) -> Vec<String> {
        let mut organs: Vec<(usize, String)> = self
            .world
            .query::<(&OrganIndex, &OrganBody)>()
            .iter(&self.world)
            .map(|(i, b)| (i.0, organ_with_law(&b.name, &b.vademecum)))
            .collect();
        organs.sort();
        organs.into_iter().map(|o| o.1).collect()
    }
}
