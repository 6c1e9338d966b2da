//! The scenario file, `scenarios/<name>.scenario.ron`, as types: every field an educator may
//! write, its unit in its name, its default where it may be left out. Unknown fields are
//! refused (a misspelt field would otherwise be silently ignored). `docs/scenarios.md` is the
//! reference page for this file.

use std::path::PathBuf;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};

use crate::contact::PointshellDensity;
use crate::devices::DeviceSpec;
use crate::fem::Law;
use crate::mesh::organs::Organ;

use super::units::{
    DepthFraction, Dioptres, EdgeLength, FieldOfView, IncisionCount, Millimetres, ModeCount,
    Newtons, Pascals, PoissonRatio, Ratio, Scale, ScopeAngle, Seconds, Stiffening, Toughness,
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
    /// Done in order: each task starts when the one before is done or out of time.
    pub tasks: Vec<Task>,
    #[serde(default)]
    pub rubric: Rubric,
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
}

impl Default for Tool {
    fn default() -> Self {
        Tool::Probe {
            tip_radius_mm: Millimetres(6.0),
        }
    }
}

impl Tool {
    pub fn tip_radius_m(&self) -> f64 {
        match self {
            Tool::Probe { tip_radius_mm }
            | Tool::Grasper { tip_radius_mm }
            | Tool::Scalpel { tip_radius_mm, .. } => tip_radius_mm.metres(),
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
}

impl Default for Device {
    fn default() -> Self {
        Self {
            max_force_n: default_device_force(),
            workspace_scale: default_workspace_scale(),
            backend: None,
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

/// A point in the scene's frame (millimetres; x to the patient's left, y anterior, z to the
/// head), with a radius around it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spot {
    /// What the trainee is told it is.
    #[serde(default)]
    pub name: String,
    pub at_mm: (f64, f64, f64),
    pub radius_mm: Millimetres,
}

/// A point written in millimetres, in metres.
pub fn metres(at_mm: (f64, f64, f64)) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(at_mm.0, at_mm.1, at_mm.2) * 1e-3
}

impl Spot {
    pub fn centre_m(&self) -> nalgebra::Vector3<f64> {
        metres(self.at_mm)
    }

    /// Whether the tool tip at `tip_m` is within the spot.
    pub fn contains(&self, tip_m: &nalgebra::Vector3<f64>) -> bool {
        (tip_m - self.centre_m()).norm() <= self.radius_mm.metres()
    }
}

/// An organ of the scene, written `Organ(name: …, …)`, or its name alone for a generated organ
/// with its own tissue. Its vademecum is built for what is given here (the first run of the
/// scenario builds it).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Organ", deny_unknown_fields)]
pub struct OrganEntry {
    /// What tasks and nodules call it; a generated organ's name unless `mesh` is given.
    pub name: String,
    /// A tetrahedral mesh file (.msh, .vtk, .vtu, in metres) with a node set `clamped` (held
    /// fixed) and a surface `accessible` (where the tool may touch), written relative to the
    /// scenario's folder (read as such: the path here is resolved).
    #[serde(default)]
    pub mesh: Option<PathBuf>,
    /// Its tissue's Young's modulus, when not the organ's own (for a mesh file: the liver's).
    #[serde(default)]
    pub young_pa: Option<Pascals>,
    /// Its tissue's Poisson's ratio, when not the organs' 0.48.
    #[serde(default)]
    pub poisson_ratio: Option<PoissonRatio>,
    /// At most this many separated modes in its vademecum, when not the builder's default.
    #[serde(default)]
    pub max_modes: Option<ModeCount>,
    /// Its tissue's law (`Linear`, `NeoHookean`, `Exponential`, `KirchhoffSaintVenant`), when
    /// not the default ([`default_law`]: exponential where pressed, linear where cut or moved).
    #[serde(default)]
    pub law: Option<Law>,
    /// The exponential law's stiffening b, when not its default (`law: Exponential` only).
    #[serde(default)]
    pub stiffening: Option<Stiffening>,
    /// Whether it moves (reduced dynamics, and the grasper can pull it) or stays
    /// quasi-static; by default it moves when the tool is a grasper.
    #[serde(default)]
    pub dynamic: Option<bool>,
    /// Its tissue's fracture toughness under a blade, when not the organ's own (the liver's
    /// and the cornea's are known; another organ is cut by a scalpel only when given one).
    #[serde(default)]
    pub toughness_j_per_m2: Option<Toughness>,
}

impl OrganEntry {
    /// Its tissue's toughness under a blade (J/m²): the scenario's, or the organ's own where
    /// it is known (a generated liver or cornea).
    pub fn toughness_j_per_m2(&self) -> Option<f64> {
        let own = match (Organ::from_name(&self.name), &self.mesh) {
            (Some(Organ::Liver), None) => Some(crate::cutting::LIVER_TOUGHNESS_J_PER_M2),
            (Some(Organ::Cornea), None) => Some(crate::cutting::CORNEA_TOUGHNESS_J_PER_M2),
            _ => None,
        };
        self.toughness_j_per_m2.map(|t| t.0).or(own)
    }

    /// A generated organ with its own tissue and default vademecum.
    pub fn named(name: &str) -> Self {
        Self {
            name: name.to_owned(),
            mesh: None,
            young_pa: None,
            poisson_ratio: None,
            max_modes: None,
            law: None,
            stiffening: None,
            dynamic: None,
            toughness_j_per_m2: None,
        }
    }
}

/// The `organs` list: each entry a name or an `Organ(…)`.
fn organ_list<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<OrganEntry>, D::Error> {
    Vec::<OrganItem>::deserialize(deserializer)
        .map(|items| items.into_iter().map(|i| i.0).collect())
}

/// One entry of `organs`, as a name or in full.
struct OrganItem(OrganEntry);

impl<'de> Deserialize<'de> for OrganItem {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(OrganVisitor).map(OrganItem)
    }
}

struct OrganVisitor;

impl<'de> Visitor<'de> for OrganVisitor {
    type Value = OrganEntry;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an organ's name such as \"liver\", or Organ(name: …, mesh: …)")
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<OrganEntry, E> {
        Ok(OrganEntry::named(name))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<OrganEntry, A::Error> {
        OrganEntry::deserialize(de::value::MapAccessDeserializer::new(map))
    }
}

/// A sphere of stiffer tissue inside an organ.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Nodule {
    pub organ: String,
    /// Its centre, in the scene's frame (mm).
    pub at_mm: (f64, f64, f64),
    pub radius_mm: Millimetres,
    /// Its Young's modulus over the organ's (tumours are several times stiffer).
    pub stiffness_ratio: Ratio,
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

    /// The tip (m) every instrument presses with: the first's (a loaded scenario's
    /// instruments all have its radius).
    pub fn tip_radius_m(&self) -> f64 {
        self.instruments_in_hand()[0].0.tip_radius_m()
    }

    /// The blade of the first instrument that cuts, if one does.
    pub fn blade(&self) -> Option<crate::cutting::Blade> {
        let instruments = self.instruments_in_hand();
        instruments.iter().find_map(|(tool, _)| tool.blade())
    }

    /// Whether an instrument grasps (and so the organs move by default).
    pub fn grasps(&self) -> bool {
        self.instruments_in_hand()
            .iter()
            .any(|(tool, _)| tool.grasps())
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

impl Nodule {
    pub fn centre_m(&self) -> nalgebra::Vector3<f64> {
        metres(self.at_mm)
    }

    /// The nodule as the finite-element model takes it.
    pub fn inclusion(&self) -> crate::fem::Inclusion {
        crate::fem::Inclusion {
            centre_m: self.centre_m().into(),
            radius_m: self.radius_mm.metres(),
            stiffness_ratio: self.stiffness_ratio.0,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Task {
    /// Press the organ and hold the force within a band for a while.
    ForceControl {
        organ: String,
        min_force_n: Newtons,
        max_force_n: Newtons,
        hold_s: Seconds,
        time_limit_s: Seconds,
    },
    /// Reach the targets in order, without entering a forbidden zone or pressing harder
    /// than the limit.
    SafeNavigation {
        targets: Vec<Spot>,
        #[serde(default)]
        forbidden: Vec<Spot>,
        max_force_n: Newtons,
        time_limit_s: Seconds,
    },
    /// Find the organ's hidden nodule by feel and mark it with the device's button (one
    /// mark: the task ends with it). Found when the mark is within `found_within_mm` of the
    /// nodule, measured across the surface (depth does not count).
    Palpation {
        organ: String,
        found_within_mm: Millimetres,
        max_force_n: Newtons,
        time_limit_s: Seconds,
    },
    /// Move the organ with the tool to expose what lies behind it: push its `region` (the
    /// surface nearest `at_mm`) at least `move_mm` along `towards` and keep it there for
    /// `hold_s`, without pressing harder than `max_force_n`, and without loading the
    /// surrounding organs (through the retracted organ or by touching them) beyond
    /// `max_surrounding_force_n`.
    Retraction {
        organ: String,
        /// What the trainee is told the region is (e.g. "the fundus").
        region: String,
        at_mm: (f64, f64, f64),
        /// The direction to move the region in (any length; the scene's frame).
        towards: (f64, f64, f64),
        move_mm: Millimetres,
        hold_s: Seconds,
        max_force_n: Newtons,
        max_surrounding_force_n: Newtons,
        time_limit_s: Seconds,
    },
    /// Take hold of the organ with the grasper and pull it: close the jaws on its `region`
    /// (the surface nearest `at_mm`), draw it at least `move_mm` along `towards`, keep it
    /// there for `hold_s`, then open the jaws, pulling no harder than `max_force_n`. Damaging
    /// the tissue (pulling it harder or further than it bears) fails the task.
    Grasp {
        organ: String,
        region: String,
        at_mm: (f64, f64, f64),
        towards: (f64, f64, f64),
        move_mm: Millimetres,
        hold_s: Seconds,
        max_force_n: Newtons,
        time_limit_s: Seconds,
    },
    /// Cut along the line marked on the organ's surface from `from_mm` to `to_mm`,
    /// `depth_mm` deep, with the scalpel. Done when the cut covers nine tenths of the line
    /// within `tolerance_mm` of it and the blade is lifted. Scored on the deviation from the
    /// line, the depth against `depth_mm`, the strokes it took, the force and the time.
    Incision {
        organ: String,
        from_mm: (f64, f64, f64),
        to_mm: (f64, f64, f64),
        depth_mm: Millimetres,
        tolerance_mm: Millimetres,
        max_force_n: Newtons,
        time_limit_s: Seconds,
    },
    /// Radial keratotomy on the cornea: `incisions` radial cuts, evenly spaced round its
    /// axis, each from the edge of the central optical zone (`optical_zone_mm` across, left
    /// uncut) out towards the limbus, `depth_fraction` of the thickness deep, to flatten the
    /// cornea by `target_correction_d` dioptres (the myopia corrected). Done when as many
    /// incisions are made and the blade is lifted. Scored on symmetry, the optical zone
    /// respected, depth, and the correction the cut cornea is predicted to give against the
    /// target (within `correction_tolerance_d`, 1 D when left out); a cut through the whole
    /// thickness perforates the eye and fails the attempt.
    RadialKeratotomy {
        organ: String,
        incisions: IncisionCount,
        optical_zone_mm: Millimetres,
        depth_fraction: DepthFraction,
        target_correction_d: Dioptres,
        #[serde(default = "default_correction_tolerance")]
        correction_tolerance_d: Dioptres,
        max_force_n: Newtons,
        time_limit_s: Seconds,
    },
}

fn default_correction_tolerance() -> Dioptres {
    Dioptres(1.0)
}

/// The region a retraction or grasp task watches: its organ, the point nearest which it
/// lies (mm) and the direction it is to move in.
pub struct Watched<'a> {
    pub organ: &'a str,
    pub at_mm: (f64, f64, f64),
    pub towards: (f64, f64, f64),
}

/// What kind a task is, for its metrics and its score.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum TaskKind {
    #[default]
    #[serde(rename = "force control")]
    ForceControl,
    #[serde(rename = "safe navigation")]
    SafeNavigation,
    #[serde(rename = "palpation")]
    Palpation,
    #[serde(rename = "retraction")]
    Retraction,
    #[serde(rename = "grasp")]
    Grasp,
    #[serde(rename = "incision")]
    Incision,
    #[serde(rename = "radial keratotomy")]
    RadialKeratotomy,
}

impl std::fmt::Display for TaskKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TaskKind::ForceControl => "force control",
            TaskKind::SafeNavigation => "safe navigation",
            TaskKind::Palpation => "palpation",
            TaskKind::Retraction => "retraction",
            TaskKind::Grasp => "grasp",
            TaskKind::Incision => "incision",
            TaskKind::RadialKeratotomy => "radial keratotomy",
        })
    }
}

impl Task {
    /// The region a retraction or grasp task watches.
    pub fn watched(&self) -> Option<Watched<'_>> {
        match self {
            Task::Retraction {
                organ,
                at_mm,
                towards,
                ..
            }
            | Task::Grasp {
                organ,
                at_mm,
                towards,
                ..
            } => Some(Watched {
                organ,
                at_mm: *at_mm,
                towards: *towards,
            }),
            _ => None,
        }
    }

    pub fn kind(&self) -> TaskKind {
        match self {
            Task::ForceControl { .. } => TaskKind::ForceControl,
            Task::SafeNavigation { .. } => TaskKind::SafeNavigation,
            Task::Palpation { .. } => TaskKind::Palpation,
            Task::Retraction { .. } => TaskKind::Retraction,
            Task::Grasp { .. } => TaskKind::Grasp,
            Task::Incision { .. } => TaskKind::Incision,
            Task::RadialKeratotomy { .. } => TaskKind::RadialKeratotomy,
        }
    }

    /// What the task asks, in words, for the trainee.
    pub fn description(&self) -> String {
        match self {
            Task::ForceControl {
                organ,
                min_force_n,
                max_force_n,
                hold_s,
                ..
            } => format!(
                "hold {min_force_n} to {max_force_n} N on the {organ} for {} s",
                hold_s.0
            ),
            Task::SafeNavigation {
                targets,
                forbidden,
                max_force_n,
                ..
            } => format!(
                "reach {} in order, avoiding {}, under {max_force_n} N",
                names(targets),
                names(forbidden),
            ),
            Task::Palpation {
                organ, max_force_n, ..
            } => {
                format!("find the nodule in the {organ} by feel and mark it, under {max_force_n} N")
            }
            Task::Retraction {
                organ,
                region,
                move_mm,
                hold_s,
                max_force_n,
                max_surrounding_force_n,
                ..
            } => format!(
                "move {region} of the {organ} {:.0} mm and hold it {} s, under {max_force_n} N, \
                 loading the organs around under {max_surrounding_force_n} N",
                move_mm.0, hold_s.0
            ),
            Task::Grasp {
                organ,
                region,
                move_mm,
                hold_s,
                max_force_n,
                ..
            } => format!(
                "grasp {region} of the {organ}, draw it {:.0} mm, hold it {} s and let go, \
                 under {max_force_n} N and without tearing it",
                move_mm.0, hold_s.0
            ),
            Task::Incision {
                organ,
                from_mm,
                to_mm,
                depth_mm,
                max_force_n,
                ..
            } => format!(
                "cut the marked line on the {organ}, {:.0} mm long and {:.0} mm deep, under {max_force_n} N",
                (metres(*to_mm) - metres(*from_mm)).norm() * 1e3,
                depth_mm.0,
            ),
            Task::RadialKeratotomy {
                organ,
                incisions,
                optical_zone_mm,
                depth_fraction,
                target_correction_d,
                max_force_n,
                ..
            } => format!(
                "make {} radial incisions in the {organ} outside a {:.1} mm optical zone, {:.0} % \
                 deep, for {:.1} D of correction, under {max_force_n} N",
                incisions.0,
                optical_zone_mm.0,
                100.0 * depth_fraction.0,
                target_correction_d.0,
            ),
        }
    }

    /// The organ the task works on (none for navigation, which works among them all).
    pub fn organ(&self) -> Option<&str> {
        match self {
            Task::ForceControl { organ, .. }
            | Task::Palpation { organ, .. }
            | Task::Retraction { organ, .. }
            | Task::Grasp { organ, .. }
            | Task::Incision { organ, .. }
            | Task::RadialKeratotomy { organ, .. } => Some(organ),
            Task::SafeNavigation { .. } => None,
        }
    }

    pub fn time_limit_s(&self) -> f64 {
        match self {
            Task::ForceControl { time_limit_s, .. }
            | Task::SafeNavigation { time_limit_s, .. }
            | Task::Palpation { time_limit_s, .. }
            | Task::Retraction { time_limit_s, .. }
            | Task::Grasp { time_limit_s, .. }
            | Task::Incision { time_limit_s, .. }
            | Task::RadialKeratotomy { time_limit_s, .. } => time_limit_s.0,
        }
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
            error_penalty: default_error_penalty(),
            pass_mark: default_pass_mark(),
            all_tasks_required: true,
        }
    }
}

pub(super) fn spot_name(spot: &Spot, k: usize) -> String {
    match spot.name.is_empty() {
        true => format!("zone {}", k + 1),
        false => spot.name.clone(),
    }
}

fn names(spots: &[Spot]) -> String {
    match spots.len() {
        0 => "nothing".into(),
        _ => spots
            .iter()
            .enumerate()
            .map(|(k, s)| spot_name(s, k))
            .collect::<Vec<_>>()
            .join(", "),
    }
}
