//! The scenario file, `scenarios/<name>.scenario.ron`, as types: every field an educator may
//! write, its unit in its name, its default where it may be left out. Unknown fields are
//! refused (a misspelt field would otherwise be silently ignored). `docs/scenarios.md` is the
//! reference page for this file.

use serde::Deserialize;

use crate::contact::PointshellDensity;
use crate::devices::DeviceSpec;
use crate::dissection::{Cautery, CauteryMode};
use crate::fem::Law;
use crate::mesh::organs::Organ;

use super::attachment::AttachmentEntry;
use super::biliary::BiliaryEntry;
use super::global::Benchmark;
use super::operation::OperationRubric;
use super::scene::{Nodule, OrganEntry, metres, organ_list};
use super::task::Task;
use super::units::{
    EdgeLength, FieldOfView, JawLength, Millimetres, Newtons, Scale, ScopeAngle, Watts,
};

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    pub title: String,
    /// What the trainee reads before starting.
    pub briefing: String,
    #[serde(default)]
    pub difficulty: Difficulty,
    /// The organs in the scene: a generated one by name (liver, gallbladder, pancreas,
    /// duodenum), or `Organ(…)` for a mesh file or a tissue or vademecum of its own.
    #[serde(deserialize_with = "organ_list")]
    pub organs: Vec<OrganEntry>,
    /// The instrument in the trainee's hand (a 6 mm probe when left out).
    #[serde(default)]
    pub tool: Option<Tool>,
    /// The port the instrument goes through (laparoscopy): the device then moves its handle,
    /// and the tip pivots about the port. None: the device moves the tip (open surgery).
    #[serde(default)]
    pub port: Option<Port>,
    /// Instead of `tool` and `port`: several instruments, each through its own port. The
    /// device drives one at a time, and its second button changes to the next (docs).
    #[serde(default)]
    pub instruments: Vec<Instrument>,
    /// A bimanual exercise: the instruments in the trainee's left hand, each through its own
    /// port, on a device of its own (`device.left_backend`, or `--left-device`); the hand
    /// above (`tool` and `port`, or `instruments`) is the right. Empty: one hand.
    #[serde(default)]
    pub left_hand: Vec<Instrument>,
    /// A third instrument, the assistant's: a grasper through its own port that the
    /// scenario moves (`Assistant(tool, port, script: [Tip(…)])`); none when left out.
    #[serde(default)]
    pub assistant: Option<Assistant>,
    /// The camera through its own port (laparoscopy); none: the desktop view of the open
    /// abdomen.
    #[serde(default)]
    pub laparoscope: Option<LaparoscopeEntry>,
    #[serde(default)]
    pub device: Device,
    /// Stiffer lumps hidden in the organs' tissue, such as tumours, for palpation. The
    /// organ's vademecum is built with them (the first run of the scenario builds it).
    #[serde(default)]
    pub nodules: Vec<Nodule>,
    /// How the organs touch each other.
    #[serde(default)]
    pub contact: Contact,
    /// Organs bound to others by connective tissue where their surfaces face each other
    /// (`Attachment(organ: "gallbladder", to: "liver")`), which the trainee frees.
    #[serde(default)]
    pub attachments: Vec<AttachmentEntry>,
    /// The cystic duct, the common duct and the cystic artery between the gallbladder, the
    /// liver and the duodenum, in the fat of the hepatocystic triangle (`Biliary(…)`; none
    /// when left out).
    #[serde(default)]
    pub biliary: Option<BiliaryEntry>,
    /// Done in order: each task starts when the one before is done or out of time.
    pub tasks: Vec<Task>,
    #[serde(default)]
    pub rubric: Rubric,
    /// An operation scored step by step and error by error, as surgical educators score it
    /// (`Operation(steps: […], errors: […])`): when present, the attempt's score is its.
    #[serde(default)]
    pub operation: Option<OperationRubric>,
    /// The proficiency benchmark the attempt's global measures are held to
    /// (`Benchmark(time_s: …, blood_lost_ml: …)`); none by default.
    #[serde(default)]
    pub benchmark: Option<Benchmark>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Difficulty {
    #[default]
    Beginner,
    Intermediate,
    Advanced,
}

impl Difficulty {
    pub fn name(self) -> &'static str {
        match self {
            Difficulty::Beginner => "beginner",
            Difficulty::Intermediate => "intermediate",
            Difficulty::Advanced => "advanced",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Tool {
    /// A round-tipped probe.
    Probe { tip_radius_mm: Millimetres },
    /// A grasper: its closed jaws press like a probe of this radius; the device's button
    /// closes them on the tissue under them, which then follows the hand (`docs/dynamics.md`).
    Grasper { tip_radius_mm: Millimetres },
    /// A scalpel: it presses like a probe of this radius, and where it presses an organ
    /// harder than the tissue's toughness times `edge_mm` (the length of edge pressed in,
    /// 5 mm when left out; a diamond knife's point is a few micrometres) the tissue parts
    /// and the blade cuts along its edge as deep as it is pressed (`docs/cutting.md`).
    Scalpel {
        tip_radius_mm: Millimetres,
        #[serde(default)]
        edge_mm: Option<EdgeLength>,
    },
    /// An L-hook on electrocautery: it presses like a probe of this radius, and while the
    /// device's first button is held it delivers `power_w` in `mode` (`Cut`: a 1 mm zone,
    /// `Coagulate`: 3 mm), dividing the connective tissue it reaches or burning the wall it
    /// touches (`docs/dissection.md`).
    Hook {
        tip_radius_mm: Millimetres,
        power_w: Watts,
        #[serde(default = "default_cautery_mode")]
        mode: CauteryMode,
    },
    /// A clip applier: its closed jaws press like a probe of this radius; the device's first
    /// button closes them, leaving a clip across the duct or artery between them, `jaw_mm`
    /// long (9 when left out: a medium-large clip) (`docs/biliary.md`).
    ClipApplier {
        tip_radius_mm: Millimetres,
        #[serde(default)]
        jaw_mm: Option<JawLength>,
    },
    /// Laparoscopic scissors: they press like a probe of this radius; the device's first
    /// button closes the blades, `blade_mm` long (15 when left out), dividing the duct or
    /// artery between them (`docs/biliary.md`).
    Scissors {
        tip_radius_mm: Millimetres,
        #[serde(default)]
        blade_mm: Option<JawLength>,
    },
}

/// A clip applier's jaws and scissors' blades when the scenario does not say (mm).
pub const DEFAULT_JAW_MM: f64 = 9.0;
pub const DEFAULT_BLADE_MM: f64 = 15.0;

fn default_cautery_mode() -> CauteryMode {
    CauteryMode::Cut
}

impl Default for Tool {
    fn default() -> Self {
        Tool::Probe {
            tip_radius_mm: Millimetres(6.0),
        }
    }
}

impl Tool {
    /// The kind of instrument in words, as a task's `instruments` names it.
    pub fn kind(&self) -> &'static str {
        match self {
            Tool::Probe { .. } => "probe",
            Tool::Grasper { .. } => "grasper",
            Tool::Scalpel { .. } => "scalpel",
            Tool::Hook { .. } => "hook",
            Tool::ClipApplier { .. } => "clip applier",
            Tool::Scissors { .. } => "scissors",
        }
    }

    pub fn tip_radius_m(&self) -> f64 {
        match self {
            Tool::Probe { tip_radius_mm }
            | Tool::Grasper { tip_radius_mm }
            | Tool::Scalpel { tip_radius_mm, .. }
            | Tool::Hook { tip_radius_mm, .. }
            | Tool::ClipApplier { tip_radius_mm, .. }
            | Tool::Scissors { tip_radius_mm, .. } => tip_radius_mm.metres(),
        }
    }

    /// The blade, if the tool cuts. Its cut advances in steps of a third of its tip's
    /// radius, from 0.5 mm (the cornea's few-millimetre incisions) to 2 mm.
    pub fn blade(&self) -> Option<crate::cutting::Blade> {
        let Tool::Scalpel {
            edge_mm,
            tip_radius_mm,
        } = self
        else {
            return None;
        };
        let blade = crate::cutting::Blade::default();
        Some(crate::cutting::Blade {
            edge_m: edge_mm.map_or(blade.edge_m, EdgeLength::metres),
            step_m: (tip_radius_mm.metres() / 3.0).clamp(0.5e-3, blade.step_m),
            ..blade
        })
    }

    /// Whether the tool grasps (and so the organs move by default).
    pub fn grasps(&self) -> bool {
        matches!(self, Tool::Grasper { .. })
    }

    /// What the tool does besides pressing, as the haptic loop takes it.
    pub fn action(&self) -> crate::devices::Action {
        match self {
            Tool::Probe { .. } => crate::devices::Action::Press,
            Tool::Grasper { .. } => crate::devices::Action::Grasp,
            Tool::Scalpel { .. } => crate::devices::Action::Cut,
            Tool::Hook { power_w, mode, .. } => crate::devices::Action::Cauterize(Cautery {
                mode: *mode,
                power_w: power_w.0,
            }),
            Tool::ClipApplier { jaw_mm, .. } => crate::devices::Action::Clip {
                jaw_m: jaw_mm.map_or(DEFAULT_JAW_MM, |j| j.0) * 1e-3,
            },
            Tool::Scissors { blade_mm, .. } => crate::devices::Action::Divide {
                blade_m: blade_mm.map_or(DEFAULT_BLADE_MM, |b| b.0) * 1e-3,
            },
        }
    }
}

/// An instrument through its port, one of a scenario's `instruments`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Instrument {
    pub tool: Tool,
    pub port: Port,
}

/// A port (trocar) in the abdominal wall and the instrument through it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Port {
    /// Where the shaft crosses the wall, in the scene's frame (mm).
    pub at_mm: (f64, f64, f64),
    /// The instrument's length from handle to tip (mm; a laparoscopic instrument's is about
    /// 300 to 450).
    pub shaft_mm: Millimetres,
}

impl Port {
    /// The port as the haptic loop takes it.
    pub fn fulcrum(&self) -> crate::devices::Fulcrum {
        crate::devices::Fulcrum {
            port_m: metres(self.at_mm),
            shaft_m: self.shaft_mm.metres(),
        }
    }
}

/// The laparoscope: where its optic enters, what it looks at first, and its optics. The
/// trainee steers it from there; the instrument's time out of its view is measured.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Laparoscope", deny_unknown_fields)]
pub struct LaparoscopeEntry {
    /// Where the optic crosses the abdominal wall (mm, the scene's frame).
    pub port_mm: (f64, f64, f64),
    /// The point the view is centred on at the start (mm): the focus of the exercise.
    pub look_at_mm: (f64, f64, f64),
    /// How far the lens is from that point at the start (mm).
    #[serde(default = "default_scope_distance")]
    pub distance_mm: Millimetres,
    /// The optic's viewing angle to its shaft (degrees; 0 or 30 usually).
    #[serde(default = "default_scope_angle")]
    pub angle_deg: ScopeAngle,
    /// The side an angled optic looks towards at the start, about its shaft (degrees; 0
    /// towards the head).
    #[serde(default)]
    pub roll_deg: f64,
    /// The field of view across the round image (degrees).
    #[serde(default = "default_field_of_view")]
    pub fov_deg: FieldOfView,
    /// A point the trainee must keep in view while steering the camera (mm); its time out
    /// of view is measured. None: only the instrument's is.
    #[serde(default)]
    pub keep_in_view_mm: Option<(f64, f64, f64)>,
    /// The camera moved by the scenario, key by key, instead of by the trainee (a guided
    /// view). Empty: the trainee steers it.
    #[serde(default)]
    pub script: Vec<ScopeKey>,
}

/// A key of a scripted camera: at `at_s` seconds from the exercise's start, the view is
/// centred on `look_at_mm` from `distance_mm` away.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Look", deny_unknown_fields)]
pub struct ScopeKey {
    pub at_s: f64,
    pub look_at_mm: (f64, f64, f64),
    pub distance_mm: Millimetres,
}

fn default_scope_distance() -> Millimetres {
    Millimetres(80.0)
}
fn default_scope_angle() -> ScopeAngle {
    ScopeAngle(30.0)
}
fn default_field_of_view() -> FieldOfView {
    FieldOfView(70.0)
}

impl LaparoscopeEntry {
    /// The optic as the core takes it.
    pub fn laparoscope(&self) -> crate::devices::Laparoscope {
        crate::devices::Laparoscope {
            port_m: metres(self.port_mm),
            angle_rad: self.angle_deg.radians(),
            fov_rad: self.fov_deg.radians(),
        }
    }

    /// Where the optic starts: centred on `look_at_mm` from `distance_mm` away (or the
    /// script's first key); `None` when the port is too near that point for it.
    pub fn start(&self) -> Option<crate::devices::ScopePose> {
        match self.script() {
            Some(script) => script.pose_at(&self.laparoscope(), 0.0),
            None => self.laparoscope().aim(
                &metres(self.look_at_mm),
                self.distance_mm.metres(),
                self.roll_deg.to_radians(),
            ),
        }
    }

    /// The scripted camera, if the scenario moves it.
    pub fn script(&self) -> Option<crate::devices::ScopeScript> {
        (!self.script.is_empty()).then(|| crate::devices::ScopeScript {
            keys: self
                .script
                .iter()
                .map(|k| (k.at_s, metres(k.look_at_mm), k.distance_mm.metres()))
                .collect(),
            roll_rad: self.roll_deg.to_radians(),
        })
    }
}

/// `Assistant(tool: Grasper(…), port: Port(…), script: [Tip(…), …])`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Assistant {
    /// The assistant's instrument: a grasper, with the trainee's tip radius.
    pub tool: Tool,
    pub port: Port,
    /// Where the instrument's tip is, key by key from the exercise's start; between keys it
    /// moves in a straight line, and after the last it stays.
    pub script: Vec<TipKey>,
}

/// A key of the assistant's script: at `at_s` seconds the tip is at `tip_mm` (the scene's
/// frame).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Tip", deny_unknown_fields)]
pub struct TipKey {
    pub at_s: f64,
    pub tip_mm: (f64, f64, f64),
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Device {
    /// The largest force sent to the device (also capped by the device's own limit).
    #[serde(default = "default_device_force")]
    pub max_force_n: Newtons,
    /// The tool moves this many times as far as the device's handle (the felt stiffness
    /// scales with it: forces are not scaled).
    #[serde(default = "default_workspace_scale")]
    pub workspace_scale: Scale,
    /// The haptic device the exercise is meant for, named as `--device` names it
    /// (`openhaptics`, `openhaptics:NAME`, `forcedimension`, `virtual`); `--device` overrides
    /// it. None: the mouse in the window.
    #[serde(default)]
    pub backend: Option<String>,
    /// A bimanual exercise's left-hand device, named as `--left-device` names it; it
    /// overrides this. None: the mouse.
    #[serde(default)]
    pub left_backend: Option<String>,
}

fn default_workspace_scale() -> Scale {
    Scale(1.0)
}

fn default_device_force() -> Newtons {
    Newtons(3.3)
}

impl Device {
    /// The device the scenario names, if it names one that reads.
    pub fn spec(&self) -> Option<DeviceSpec> {
        self.backend.as_ref()?.parse().ok()
    }

    /// The left hand's device the scenario names, if it names one that reads.
    pub fn left_spec(&self) -> Option<DeviceSpec> {
        self.left_backend.as_ref()?.parse().ok()
    }
}

impl Default for Device {
    fn default() -> Self {
        Self {
            max_force_n: default_device_force(),
            workspace_scale: default_workspace_scale(),
            backend: None,
            left_backend: None,
        }
    }
}

/// Organ/organ contact: the master organ carries a distance field on a lattice around it,
/// against which the other organs' surface nodes are tested every tick.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// The organ carrying the distance field (the gallbladder when left out; with neither in
    /// the scene the organs do not touch).
    #[serde(default)]
    pub master: Option<String>,
    /// The lattice's spacing: about the depth a node may sink before it is pushed out (2 mm
    /// when left out; finer costs memory and set-up time).
    #[serde(default)]
    pub lattice_mm: Option<Millimetres>,
    /// Which points of the other organs are tested: `Nodes` (their surface nodes, the
    /// default), `Dense` (also their surface triangles' centres), `Subdivided(n)` (the
    /// centres of each surface triangle cut `n` times along each edge, `n` from 1 to 8) or
    /// `Sparse(mm)` (the surface nodes, kept at least `mm` millimetres apart, 1 to 50).
    #[serde(default)]
    pub pointshell: PointshellDensity,
}

impl Scenario {
    /// The organ called `name`, if the scene has it.
    pub fn organ(&self, name: &str) -> Option<&OrganEntry> {
        self.organs.iter().find(|o| o.name == name)
    }

    /// The scene's organs' names, as a list to read.
    pub fn organ_names(&self) -> String {
        let names: Vec<&str> = self.organs.iter().map(|o| o.name.as_str()).collect();
        names.join(", ")
    }

    /// The instruments the trainee works with, in the order the device's second button goes
    /// through them: the listed `instruments`, or else the one `tool` through its `port`
    /// (none: open surgery).
    pub fn instruments_in_hand(&self) -> Vec<(Tool, Option<Port>)> {
        if self.instruments.is_empty() {
            let tool = self.tool.clone().unwrap_or_default();
            return vec![(tool, self.port.clone())];
        }
        let listed = self.instruments.iter();
        listed
            .map(|i| (i.tool.clone(), Some(i.port.clone())))
            .collect()
    }

    /// Each hand's instruments, the right hand's first: one hand, or two in a bimanual
    /// exercise.
    pub fn hands(&self) -> Vec<Vec<(Tool, Option<Port>)>> {
        let mut hands = vec![self.instruments_in_hand()];
        if !self.left_hand.is_empty() {
            let left = self.left_hand.iter();
            hands.push(
                left.map(|i| (i.tool.clone(), Some(i.port.clone())))
                    .collect(),
            );
        }
        hands
    }

    /// Whether the exercise is for both hands.
    pub fn bimanual(&self) -> bool {
        !self.left_hand.is_empty()
    }

    /// The tip (m) every instrument presses with: the first's (a loaded scenario's
    /// instruments all have its radius).
    pub fn tip_radius_m(&self) -> f64 {
        self.instruments_in_hand()[0].0.tip_radius_m()
    }

    /// The blade of the first instrument that cuts, in either hand, if one does.
    pub fn blade(&self) -> Option<crate::cutting::Blade> {
        let hands = self.hands();
        hands.iter().flatten().find_map(|(tool, _)| tool.blade())
    }

    /// Whether an instrument in either hand grasps (and so the organs move by default).
    pub fn grasps(&self) -> bool {
        self.hands().iter().flatten().any(|(tool, _)| tool.grasps()) || self.assistant.is_some()
    }

    /// Whether an instrument in either hand is an electrocautery hook.
    pub fn hook(&self) -> bool {
        self.holds(|tool| matches!(tool, Tool::Hook { .. }))
    }

    /// Whether either hand has an instrument `is`.
    pub fn holds(&self, is: impl Fn(&Tool) -> bool) -> bool {
        (self.hands().iter().flatten()).any(|(tool, _)| is(tool))
    }

    /// Whether `organ` moves: as it says, else when an instrument grasps.
    pub fn moves(&self, organ: &OrganEntry) -> bool {
        organ.dynamic.unwrap_or(self.grasps())
    }

    /// The toughness (J/m²) of `organ`'s tissue when a blade cuts it (`None`: uncut).
    pub fn cut_toughness_j_per_m2(&self, organ: &OrganEntry) -> Option<f64> {
        self.blade().and_then(|_| organ.toughness_j_per_m2())
    }

    /// `organ`'s tissue law: as it says, else [`default_law`] for it in this scenario.
    pub fn law_of(&self, organ: &OrganEntry) -> Law {
        let generated = organ
            .mesh
            .is_none()
            .then(|| Organ::from_name(&organ.name))
            .flatten();
        let cut = self.cut_toughness_j_per_m2(organ).is_some();
        organ
            .law
            .unwrap_or_else(|| default_law(generated, cut, self.moves(organ)))
    }

    /// The scenario as the web page runs it: linear tissue where it names no law. A scene's
    /// nonlinear vademecums are five to nine times the size of its linear ones, one load step
    /// a depth (the coarse liver's 20 MB against 2.3 MB), too much for a page to download.
    pub fn for_the_web(&self) -> Scenario {
        let mut scenario = self.clone();
        for organ in &mut scenario.organs {
            organ.law.get_or_insert(Law::Linear);
        }
        scenario
    }
}

/// The law an organ's tissue follows when its scenario does not say (`organ` is `None` for a
/// mesh file, whose tissue is the liver's): the exponential law, which firms up under the
/// tool as liver does, where the organ is pressed; the linear law where a scalpel cuts it
/// (the cut state is linear X-FEM), where it moves (its reduced dynamics run the KSV energy
/// on its linear vademecum's modes), on the cornea, which only the keratotomy's blade cuts,
/// and on the gallbladder: where trainees press its fundus its exponential vademecum is past
/// its range (which ends about a millinewton in), so it would only extrapolate there, at four
/// times the linear tick (`docs/fem.md`, "which law to pick").
pub fn default_law(organ: Option<Organ>, cut: bool, dynamic: bool) -> Law {
    let linear_organ = matches!(organ, Some(Organ::Cornea | Organ::Gallbladder));
    match linear_organ || cut || dynamic {
        true => Law::Linear,
        false => Law::Exponential,
    }
}

/// How a task's score (0–100) is made from its metrics, and what passes.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rubric {
    /// Weight of finishing the task at all.
    #[serde(default = "default_completion")]
    pub completion: f64,
    /// Weight of speed: the share of the time limit left.
    #[serde(default = "default_speed")]
    pub speed: f64,
    /// Weight of force control: the share of the time in contact spent within the task's
    /// force limits.
    #[serde(default = "default_force")]
    pub force: f64,
    /// Weight of accuracy, in palpation and incision only. Palpation: 1 for a mark on the
    /// nodule, falling to 0 at twice `found_within_mm` from it. Incision: the mean of the
    /// line's accuracy (1 on the line, 0 at twice `tolerance_mm` off it on average) and the
    /// depth's (1 at `depth_mm`, 0 at half or twice as deep).
    #[serde(default = "default_accuracy")]
    pub accuracy: f64,
    /// Weight of economy of motion: the shortest path the task needed over the path the tip
    /// took (1 with no wasted motion). None by default.
    #[serde(default)]
    pub motion: f64,
    /// Weight of the view (laparoscopy): the share of the task's time the instrument's tip,
    /// and the point to keep in view if there is one, are in the camera's view. None by
    /// default.
    #[serde(default)]
    pub view: f64,
    /// Weight of working with both hands (bimanual exercises): for a task with
    /// counter-traction, the share of its time the other hand held its organ within the band;
    /// otherwise the share of the time with tissue in hand during which both hands are on it.
    /// None by default.
    #[serde(default)]
    pub both_hands: f64,
    /// Points lost per error (a forbidden zone entered, a press over the limit).
    #[serde(default = "default_error_penalty")]
    pub error_penalty: f64,
    /// The attempt passes with this overall score (0–100) or more...
    #[serde(default = "default_pass_mark")]
    pub pass_mark: f64,
    /// ...and, if set, only with every task finished.
    #[serde(default = "default_true")]
    pub all_tasks_required: bool,
}

fn default_completion() -> f64 {
    0.4
}
fn default_speed() -> f64 {
    0.2
}
fn default_force() -> f64 {
    0.4
}
fn default_accuracy() -> f64 {
    0.4
}
fn default_error_penalty() -> f64 {
    10.0
}
fn default_pass_mark() -> f64 {
    70.0
}
fn default_true() -> bool {
    true
}

impl Default for Rubric {
    fn default() -> Self {
        Self {
            completion: default_completion(),
            speed: default_speed(),
            force: default_force(),
            accuracy: default_accuracy(),
            motion: 0.0,
            view: 0.0,
            both_hands: 0.0,
            error_penalty: default_error_penalty(),
            pass_mark: default_pass_mark(),
            all_tasks_required: true,
        }
    }
}
