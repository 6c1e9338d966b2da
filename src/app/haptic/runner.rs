//! The haptic world and its schedule, and the simulated-clock run behind `--headless`.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

// The browser's clock in a web page (std's has none there), the OS's elsewhere.
use bevy::platform::time::Instant;

use bevy::ecs::component::Mutable;
use bevy::prelude::*;

use super::biliary::{Biliary, SceneBiliary};
use super::cautery::{HookWork, OrganBurns};
use super::components::{
    HandTouches, OrganBody, OrganDeformation, OrganIndex, OrganMotion, organ_with_law,
};
use super::cutting::{OrganCut, SettleCuts};
use super::hand::{
    Device, DeviceForce, FaultLog, ForceTrace, GraspForce, HandIndex, MAX_HANDS, Safety,
    TRAINEE_HANDS, Tool,
};
use super::report::{FaultSummary, ForceSummary, HeadlessReport, RangeSummary};
use super::resources::{OrganBeds, OrganCoupling, SceneScope, Scope, TickClock};
use super::snapshot::{
    BedView, BiliaryView, BurnsView, HandSnapshot, HapticSnapshot, OrganSnapshot, SnapshotPublisher,
};
use crate::contact::{ContactError, ContactSurface, Coupling, Probe};
use crate::cutting::{Blade, CutError, CutWorker, LatestCut, Scalpel};
use crate::devices::{
    Action, Fulcrum, HapticDevice, Histogram, Instrument, Rack, SafetyFilter, SafetySettings,
    Scripted, TICK_S, Trajectory, Workspace, stop_requested,
};
use crate::dissection::{TiedOrgans, TissueHeat, Wall, WallBurns};
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
    /// The trainee's hands, the right hand first: one, or two for bimanual work, each with
    /// its own device.
    pub hands: Vec<SceneHand>,
    pub safety: SafetySettings,
    /// Organ/organ contact and attachments (set up, at rest); `None` leaves the organs apart.
    pub coupling: Option<Arc<Coupling>>,
    /// Organs bound to others by connective tissue (the gallbladder in its bed), at rest;
    /// each needs the coupling.
    pub beds: Vec<TiedOrgans>,
    /// Organs that move, and the grasper that pulls them; `None`: every organ quasi-static and
    /// the tool a probe.
    pub dynamics: Option<SceneDynamics>,
    /// The organs the tool cuts, when it is a scalpel.
    pub cutting: Option<SceneCutting>,
    /// The laparoscope, if the trainee looks through one.
    pub scope: Option<SceneScope>,
    /// The cystic duct, the common duct and the cystic artery, if the scene has them.
    pub biliary: Option<SceneBiliary>,
    /// The nonlinear vademecums building in the background while their organs run linear
    /// tissue here: the window loads the scene again once they are built.
    pub meanwhile: Vec<PathBuf>,
    /// The assistant's instrument, which the scenario moves; none in most scenes.
    pub assistant: Option<SceneAssistant>,
}

/// The assistant's instrument: through its own port, on a scripted device of its own, a hand
/// after the trainee's that presses (its jaws stay shut) and that no score reads.
#[derive(Clone, Debug)]
pub struct SceneAssistant {
    pub port: Fulcrum,
    /// The device's handle, key by key.
    pub script: Trajectory,
}

impl HapticScene {
    /// `organs` pressed by `probe` in open surgery and nothing more: the organs apart, still
    /// and uncut, no laparoscope, the default workspace and safety.
    pub fn pressing(organs: Vec<(String, Arc<Vademecum>)>, probe: Probe) -> Self {
        Self {
            organs,
            probe,
            hands: vec![SceneHand::default()],
            safety: SafetySettings::default(),
            coupling: None,
            beds: Vec::new(),
            dynamics: None,
            cutting: None,
            scope: None,
            biliary: None,
            meanwhile: Vec::new(),
            assistant: None,
        }
    }

    /// A 6 mm probe over no organ: a loop that serves a device and nothing else.
    pub fn without_organs() -> Self {
        let probe = Probe {
            tip_radius_m: 0.006,
        };
        Self::pressing(Vec::new(), probe)
    }

    /// The ports of the instruments that go through one, every hand's.
    pub fn ports(&self) -> impl Iterator<Item = Fulcrum> + '_ {
        let instruments = self.hands.iter().flat_map(|h| &h.instruments);
        instruments.filter_map(|i| i.port)
    }

    /// Whether an instrument of either hand is an electrocautery hook.
    pub fn has_hook(&self) -> bool {
        let instruments = self.hands.iter().flat_map(|h| &h.instruments);
        instruments
            .into_iter()
            .any(|i| matches!(i.action, Action::Cauterize(_)))
    }

    /// The right hand (the only one of a one-hand scene).
    pub fn right_hand_mut(&mut self) -> &mut SceneHand {
        &mut self.hands[0]
    }
}

/// A hand of the scene: its instruments, and how its device's motion maps onto the scene.
#[derive(Clone, Debug)]
pub struct SceneHand {
    /// The instruments, the first in hand at the start: through a port the device moves its
    /// handle (laparoscopy); otherwise its tip (open surgery).
    pub instruments: Vec<Instrument>,
    pub workspace: Workspace,
}

impl Default for SceneHand {
    /// A probe in open surgery, the device's motion one to one.
    fn default() -> Self {
        Self {
            instruments: vec![Instrument::default()],
            workspace: Workspace::default(),
        }
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
    /// A device for each of the trainee's hands, no more and no fewer.
    #[error(
        "the scene has {hands} hand(s) and {devices} device(s) were opened for it: \
         one device a hand (at most {TRAINEE_HANDS} hands)"
    )]
    Hands { hands: usize, devices: usize },
}

/// Hand `index` of the scene, `hand`, into `world`, without its device.
fn spawn_hand(world: &mut World, probe: Probe, index: usize, hand: &SceneHand) -> Entity {
    let tool = Tool {
        probe,
        workspace: hand.workspace,
        rack: Rack::new(&hand.instruments),
        hand: None,
        pose: None,
        sample: None,
    };
    let parts = (HandIndex(index), tool, DeviceForce::default());
    world
        .spawn((
            parts,
            GraspForce::default(),
            FaultLog::default(),
            HookWork::default(),
        ))
        .id()
}

/// The assistant's hand, `index`, into `world`, holding its scripted device from the start.
fn spawn_assistant(
    world: &mut World,
    scene: &HapticScene,
    index: usize,
    assistant: &SceneAssistant,
) -> Entity {
    let hand = SceneHand {
        instruments: vec![Instrument {
            action: Action::Press,
            port: Some(assistant.port),
        }],
        workspace: Workspace::default(),
    };
    let entity = spawn_hand(world, scene.probe, index, &hand);
    let device = Scripted::new("the assistant's script", assistant.script.clone());
    let safety = Safety(SafetyFilter::new(scene.safety, device.limits()));
    let device = Device(Box::new(device));
    world.entity_mut(entity).insert((device, safety));
    entity
}

/// The safety settings of a loop that has no device yet.
#[derive(Resource, Clone, Copy)]
struct Parked(SafetySettings);

/// A haptic `World` of organ and hand entities and the schedule that ticks it.
pub struct HapticLoop {
    world: World,
    schedule: Schedule,
    /// The trainee's hand entities, by hand index.
    hands: Vec<Entity>,
    /// The assistant's hand, after the trainee's.
    assistant: Option<Entity>,
}

impl HapticLoop {
    /// The loop of a one-hand scene on `device`.
    pub fn new(scene: &HapticScene, device: Box<dyn HapticDevice>) -> Result<Self, SceneError> {
        Self::with_devices(scene, vec![device])
    }

    /// The loop of `scene` on `devices`, one a hand, the right hand's first.
    pub fn with_devices(
        scene: &HapticScene,
        devices: Vec<Box<dyn HapticDevice>>,
    ) -> Result<Self, SceneError> {
        if devices.len() != scene.hands.len() {
            let (hands, devices) = (scene.hands.len(), devices.len());
            return Err(SceneError::Hands { hands, devices });
        }
        let mut haptic = Self::parked(scene)?;
        haptic.world.remove_resource::<Parked>();
        for (hand, device) in devices.into_iter().enumerate() {
            haptic.hold(hand, device, scene.safety);
        }
        Ok(haptic)
    }

    /// Gives hand `hand` `device`, behind a safety filter of `settings`.
    fn hold(&mut self, hand: usize, device: Box<dyn HapticDevice>, settings: SafetySettings) {
        let safety = Safety(SafetyFilter::new(settings, device.limits()));
        (self.world.entity_mut(self.hands[hand])).insert((Device(device), safety));
    }

    /// Gives a parked loop's hand `hand` a device of its own, for a hand the running loop it
    /// will take over has none for (a bimanual scene taking over a one-hand one: its left
    /// hand on the mouse); one the running loop has replaces it then. Nothing for a loop not
    /// parked, or a hand the scene lacks.
    pub fn give_device(&mut self, hand: usize, device: Box<dyn HapticDevice>) {
        let Some(Parked(settings)) = self.world.get_resource::<Parked>().copied() else {
            return;
        };
        if hand < self.hands.len() {
            self.hold(hand, device, settings);
        }
    }

    /// A world for `scene` without a device, to be built away from the haptic thread (its
    /// contact surfaces take milliseconds) and then take over a running loop's device with
    /// [`HapticLoop::take_devices`]. Ticked without them, its hands read and send nothing.
    pub fn parked(scene: &HapticScene) -> Result<Self, SceneError> {
        scene.safety.check().map_err(SceneError::Safety)?;
        let trainee_hands = scene.hands.len();
        if !(1..=TRAINEE_HANDS).contains(&trainee_hands) {
            let hands = trainee_hands;
            return Err(SceneError::Hands { hands, devices: 0 });
        }
        // The assistant's hand is always the third, whether the trainee uses one hand or two.
        let hands = if scene.assistant.is_some() {
            MAX_HANDS
        } else {
            trainee_hands
        };
        let mut world = World::new();
        for (index, (name, vademecum)) in scene.organs.iter().enumerate() {
            let mut organ = world.spawn((
                OrganBody {
                    name: name.clone(),
                    surface: Arc::new(ContactSurface::new(vademecum)?),
                    vademecum: vademecum.clone(),
                },
                OrganIndex(index),
                HandTouches::reserved(vademecum, hands),
                OrganDeformation(Deformation::new(vademecum, hands)),
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
                let positions = vademecum.positions.len();
                organ.insert(OrganCut::new(scalpel, worker, positions, hands));
            }
        }
        let hands = (scene.hands.iter().enumerate())
            .map(|(index, hand)| spawn_hand(&mut world, scene.probe, index, hand))
            .collect();
        let assistant = (scene.assistant.as_ref())
            .map(|a| spawn_assistant(&mut world, scene, TRAINEE_HANDS, a));
        world.insert_resource(TickClock::default());
        world.insert_resource(Parked(scene.safety));
        if let Some(coupling) = &scene.coupling {
            let coupling = coupling.clone_reserved(&scene.organs);
            let mut deformations = world.query::<&mut OrganDeformation>();
            for mut deformation in deformations.iter_mut(&mut world) {
                coupling.reserve_output(&mut deformation.0);
            }
            world.insert_resource(OrganCoupling(coupling));
            if !scene.beds.is_empty() {
                world.insert_resource(OrganBeds(scene.beds.clone()));
            }
        }
        if let Some(scope) = &scene.scope {
            world.insert_resource(Scope::new(scope.clone()));
        }
        if let Some(biliary) = &scene.biliary {
            world.insert_resource(Biliary::new(biliary, &scene.organs));
        }
        if scene.has_hook() {
            let walls = (scene.organs.iter()).map(|(name, _)| Wall::of_name(name));
            let burns = WallBurns::new(walls.collect(), TissueHeat::SOFT_TISSUE);
            world.insert_resource(OrganBurns(burns));
        }
        Ok(Self {
            world,
            schedule: super::haptic_schedule(),
            hands,
            assistant,
        })
    }

    /// Takes `running`'s devices and their safety filters (retuned to this scene's settings),
    /// hand by hand, so that the force each hand feels carries over the change of scene at
    /// the allowed rate. Does nothing if this loop has its devices already; a hand `running`
    /// has no device for keeps the one [`HapticLoop::give_device`] gave it, or stays without
    /// one (and a device of a hand this scene lacks stays with `running`, which closes it
    /// when dropped).
    pub fn take_devices(&mut self, running: &mut HapticLoop) {
        let Some(Parked(settings)) = self.world.get_resource::<Parked>().copied() else {
            return;
        };
        self.world.remove_resource::<Parked>();
        for (&mine, &theirs) in self.hands.iter().zip(&running.hands) {
            let mut theirs = running.world.entity_mut(theirs);
            let (Some(device), Some(mut safety)) =
                (theirs.take::<Device>(), theirs.take::<Safety>())
            else {
                continue;
            };
            safety.0.retune(settings, device.0.limits());
            self.world.entity_mut(mine).insert((device, safety));
        }
    }

    /// Keeps every tick's forces of every hand in its [`ForceTrace`].
    pub fn keep_trace(&mut self) {
        for &hand in &self.hands {
            self.world.entity_mut(hand).insert(ForceTrace::default());
        }
    }

    /// How many hands the scene has.
    pub fn hands(&self) -> usize {
        self.hands.len()
    }

    /// Hand `index`'s component `T` (its [`Tool`], [`DeviceForce`], [`FaultLog`], …), if it
    /// has one.
    pub fn hand<T: Component>(&self, index: usize) -> Option<&T> {
        self.world.get::<T>(*self.hands.get(index)?)
    }

    /// The assistant's hand's component `T`, if the scene has an assistant.
    pub fn assistant<T: Component>(&self) -> Option<&T> {
        self.world.get::<T>(self.assistant?)
    }

    /// Hand `index`'s component `T`, to change.
    pub fn hand_mut<T: Component<Mutability = Mutable>>(
        &mut self,
        index: usize,
    ) -> Option<Mut<'_, T>> {
        self.world.get_mut::<T>(*self.hands.get(index)?)
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
        let beds = self
            .world
            .get_resource::<OrganBeds>()
            .map_or(&[][..], |b| &b.0[..]);
        let template = HapticSnapshot {
            hands: vec![HandSnapshot::default(); self.hands.len()],
            assistant: self.assistant.map(|_| HandSnapshot::default()),
            organs: organs.into_iter().map(|(_, organ)| organ).collect(),
            beds: beds.iter().map(BedView::at_rest).collect(),
            burns: BurnsView::with_room(),
            biliary: self.world.get_resource::<Biliary>().map(BiliaryView::of),
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
        let mut forces = vec![ForceSummary::default(); self.hands.len()];
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
            self.record_tick(&mut forces, &mut range);
        }
        let (device, organs) = (self.device_name(), self.organ_names());
        let faults = self.faults();
        HeadlessReport::new(device, organs, faults, ran, forces, range, &compute)
    }

    /// Records the tick's force of each hand, whether it holds an organ, and how far each
    /// tool pressed beyond its organ's range.
    fn record_tick(&mut self, forces: &mut [ForceSummary], range: &mut RangeSummary) {
        let mut organs = self.world.query::<(&OrganBody, &HandTouches)>();
        let mut moving = self.world.query::<&OrganMotion>();
        for (slot, summary) in forces.iter_mut().enumerate() {
            let holding = (moving.iter(&self.world)).any(|m| m.organ.holding() && m.hand == slot);
            let mut touching = false;
            for (body, touches) in organs.iter(&self.world) {
                let Some(contact) = &touches.0[slot].contact else {
                    continue;
                };
                touching = true;
                let valid_m = body.vademecum.valid_indentation_m();
                range.record(&body.name, contact.beyond_range_m, valid_m);
            }
            let force = self.world.get::<DeviceForce>(self.hands[slot]);
            summary.record(force.expect("every hand has its force"), touching, holding);
        }
    }

    /// Every hand's device, named, joined by " + " (the right hand's first).
    pub(super) fn device_name(&self) -> String {
        let names: Vec<&str> = (0..self.hands.len())
            .map(|index| {
                self.hand::<Device>(index)
                    .map_or("no device", |d| d.0.name())
            })
            .collect();
        names.join(" + ")
    }

    /// Every hand's faults, each named with its hand when there are two.
    pub(super) fn faults(&self) -> FaultSummary {
        let logs = (0..self.hands.len()).filter_map(|index| self.hand::<FaultLog>(index));
        let named = self.hands.len() > 1;
        FaultSummary::of(logs.enumerate().map(|(index, log)| {
            let hand = named.then(|| HandIndex(index).name());
            (hand, log)
        }))
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
