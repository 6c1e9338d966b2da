//! The default training scene: the four abdominal organs in their anatomical places (the
//! generator builds them in one frame), each with its vademecum from `vademecums/`.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use nalgebra::Vector3;

use super::haptic::{CutOrgan, HapticScene, SceneCutting, SceneDynamics, SceneHand};
use crate::contact::{
    AttachmentSpec, ContactSurface, Coupling, CouplingSettings, FieldOrigin, Probe,
};
use crate::cutting::keratotomy::{Cornea, REFERENCE_MESH};
use crate::cutting::{Blade, CutError};
use crate::devices::{
    Action, HapticDevice, Instrument, PressTarget, SafetySettings, VirtualDevice, VirtualHandle,
    Workspace,
};
use crate::dissection::{Bed, TiedOrgans};
use crate::dynamics::{DynamicModel, GraspSettings, TRAINER_MODES};
use crate::fem::{FemModel, Inclusion, Law};
use crate::mesh::TetMesh;
use crate::mesh::organs::{Organ, OrganSettings, region};
use crate::pgd::{BuildSettings, Vademecum};
use crate::scenario::{AttachmentEntry, Keratometer, default_law};
#[cfg(not(target_arch = "wasm32"))]
use crate::store::build_in_background;
use crate::store::{OnStale, OrganSource, VademecumSpec, ensure_vademecum, vademecum_file_name};

pub const SCENE_ORGANS: [Organ; 4] = Organ::ABDOMEN;

/// The mesh resolution of a coarse organ a scalpel cuts. The coarse organs' elements are
/// about 15 mm across, and a cut enriches only the nodes whose every element it crosses
/// whole: at the depths a scalpel goes (10–20 mm) it would enrich none, and the cut would be
/// scored but not felt. At half the full resolution a 14 mm deep, 23 mm long incision on
/// the liver enriches eight nodes, as many as at full resolution.
pub const CUT_COARSE_RESOLUTION: f64 = 0.5;

/// The mesh resolution and layers of a cornea a scalpel cuts: a cut's depth counts in
/// elements through the thickness, so a keratotomy needs more than the two layers that
/// pressing does (`docs/cutting.md`). Full: the reference cornea's mesh; coarse: half its
/// depth resolution, to build in seconds. A keratotomy's correction is predicted on the
/// reference cornea at either detail.
pub const CUT_CORNEA_FULL: (f64, usize) = REFERENCE_MESH;
pub const CUT_CORNEA_COARSE: (f64, usize) = (0.3, 4);

/// How finely the scene's organs are meshed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Detail {
    /// The papers' meshes and each organ's own tool (linear vademecums build in about 3
    /// minutes, nonlinear ones in tens of minutes each).
    #[default]
    Full,
    /// A quarter of the nodes and, on the abdominal organs, a 12 mm tool, whose patch must
    /// span the coarser edges: the linear vademecums build in seconds and the three
    /// exponential ones in about 3 minutes, for a quick look on a slow machine and for tests.
    /// The coarse cornea's edges are still shorter than its own 0.5 mm spatula, which it
    /// keeps.
    Coarse,
}

impl Detail {
    /// The tool tip radius (m) the abdominal organs' vademecums at this detail are built for.
    pub fn tip_radius_m(self) -> f64 {
        self.smallest_tip_m(None)
    }

    /// The smallest tool tip (m) whose patch spans `organ`'s edges at this detail (`None`: a
    /// mesh file, taken as abdominal).
    fn smallest_tip_m(self, organ: Option<Organ>) -> f64 {
        match (self, organ) {
            (Detail::Coarse, Some(Organ::Cornea)) | (Detail::Full, _) => {
                BuildSettings::for_organ(organ).tool_tip_radius_m
            }
            (Detail::Coarse, _) => 0.012,
        }
    }

    /// The vademecum of `organ` at this detail, kept under `dir`.
    pub fn vademecum(self, dir: &Path, organ: Organ) -> VademecumSpec {
        self.applied(VademecumSpec::default_in(dir, organ, Law::Linear))
    }

    /// `full`, the vademecum at full detail, at this detail (a generated organ's mesh
    /// coarsened; the coarse tool and near field for the abdominal organs and mesh files).
    fn applied(self, full: VademecumSpec) -> VademecumSpec {
        let cornea = full.source.organ() == Some(Organ::Cornea);
        match self {
            Detail::Full => full,
            Detail::Coarse => VademecumSpec {
                mesh: OrganSettings {
                    resolution: 0.25,
                    ..full.mesh
                },
                build: match cornea {
                    true => full.build,
                    false => BuildSettings {
                        tool_tip_radius_m: self.tip_radius_m(),
                        local_radius_m: 0.025,
                        ..full.build
                    },
                },
                file: full.file.with_extension("coarse.vdm"),
                ..full
            },
        }
    }

    /// The mesh of a generated organ a scalpel cuts, at this detail: finer than a pressed
    /// one's where the coarse elements would be too large for a cut to enrich any node.
    fn cut_mesh(self, organ: Organ, mesh: &mut OrganSettings) {
        match (self, organ) {
            (_, Organ::Cornea) => {
                let (resolution, layers) = match self {
                    Detail::Full => CUT_CORNEA_FULL,
                    Detail::Coarse => CUT_CORNEA_COARSE,
                };
                (mesh.resolution, mesh.cornea_layers) = (resolution, layers);
            }
            (Detail::Coarse, _) => mesh.resolution = CUT_COARSE_RESOLUTION,
            (Detail::Full, _) => {}
        }
    }
}

/// The default scene at `detail`, its vademecums loaded from `dir` (rebuilt first if missing
/// or stale, unless `on_stale` refuses); the tool is the one they were built for.
pub fn default_scene(dir: &Path, detail: Detail, on_stale: OnStale) -> Result<HapticScene, String> {
    let organs = SCENE_ORGANS.map(SceneOrgan::from);
    let coupling = CouplingSettings::default();
    scene_of(&organs, None, &coupling, dir, detail, on_stale)
}

/// Binds `attachment.organ` to the organ it lies on in `scene` by a bed of cohesive ties
/// where their surfaces face each other within its gap (setting up an organ coupling if the
/// scene has none). Refused, naming both organs, where the surfaces do not face each other.
pub fn tie_organs(scene: &mut HapticScene, attachment: &AttachmentEntry) -> Result<(), String> {
    let place = format!("attachment of {} to {}", attachment.organ, attachment.to);
    let find = |name: &str| {
        (scene.organs.iter().position(|(n, _)| n == name))
            .map(|index| (index, scene.organs[index].1.clone()))
            .ok_or_else(|| format!("{place}: `{name}` is not in the scene"))
    };
    let (freed, base) = (find(&attachment.organ)?, find(&attachment.to)?);
    let law = attachment.law().map_err(|e| format!("{place}: {e}"))?;
    let surface = ContactSurface::new(&base.1).map_err(|e| format!("{place}: {e}"))?;
    let bed = Bed::on(law, &freed.1, &surface, attachment.gap_m())
        .map_err(|e| format!("{place}: {e}"))?;
    if scene.coupling.is_none() {
        let apart = CouplingSettings {
            master: String::new(),
            ..CouplingSettings::default()
        };
        let (coupling, _) =
            Coupling::new(&scene.organs, &[], &apart, None).map_err(|e| e.to_string())?;
        scene.coupling = Some(Arc::new(coupling));
    }
    let freed_index = freed.0;
    let mut tied = TiedOrgans::new(bed, freed.clone(), base);
    if let Some(model) = (scene.dynamics.as_ref()).and_then(|d| d.model(freed_index)) {
        tied.restrain_kept_modes(&model.basis, &freed.1);
    }
    scene.beds.push(tied);
    Ok(())
}

/// An organ of a scene: its mesh, its tissue (with any stiffer or softer regions in it) and
/// its vademecum's settings where not the defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneOrgan {
    pub name: String,
    pub source: OrganSource,
    /// Young's modulus (Pa) of its tissue when not the organ's own.
    pub young_pa: Option<f64>,
    /// Poisson's ratio of its tissue when not the organs' own.
    pub poisson: Option<f64>,
    /// The vademecum's cap on modes when not the builder's.
    pub max_modes: Option<usize>,
    pub inclusions: Vec<Inclusion>,
    /// The tissue's law, which its vademecum is built under.
    pub law: Law,
    /// The exponential law's stiffening when not its default.
    pub stiffening: Option<f64>,
    /// Whether it moves (reduced dynamics; the grasper pulls it) rather than staying
    /// quasi-static.
    pub dynamic: bool,
    /// Its tissue's toughness under a blade (J/m²) when the scene's scalpel cuts it.
    pub cut_toughness_j_per_m2: Option<f64>,
}

impl From<Organ> for SceneOrgan {
    fn from(organ: Organ) -> Self {
        Self {
            name: organ.name().to_owned(),
            source: OrganSource::Generated(organ),
            young_pa: None,
            poisson: None,
            max_modes: None,
            inclusions: Vec::new(),
            law: default_law(Some(organ), false, false),
            stiffening: None,
            dynamic: false,
            cut_toughness_j_per_m2: None,
        }
    }
}

impl SceneOrgan {
    /// Its vademecum at `detail` for a tool tip of `tip_m`, kept under `dir` in a file named
    /// after what differs from the defaults.
    fn vademecum(&self, dir: &Path, detail: Detail, tip_m: f64) -> VademecumSpec {
        let stem = match &self.source {
            OrganSource::Generated(_) => self.name.clone(),
            OrganSource::File(file) => {
                let stem = file.path.file_stem().unwrap_or_default().to_string_lossy();
                format!("{}.mesh-{stem}", self.name)
            }
        };
        let file = dir.join(vademecum_file_name(&stem, self.law));
        let spec = VademecumSpec::new(&self.name, self.source.clone(), self.law, file);
        let mut spec = detail.applied(spec);
        if let (Some(_), OrganSource::Generated(organ)) =
            (self.cut_toughness_j_per_m2, &self.source)
        {
            let uncut = spec.mesh;
            detail.cut_mesh(*organ, &mut spec.mesh);
            if spec.mesh != uncut {
                spec.file = spec.file.with_extension("cut.vdm");
            }
        }
        let mut tag = |part: String| spec.file = spec.file.with_extension(format!("{part}.vdm"));
        if tip_m != spec.build.tool_tip_radius_m {
            tag(format!("tip{}mm", tip_m * 1e3));
        }
        if let Some(young_pa) = self.young_pa {
            tag(format!("young-{young_pa}pa"));
        }
        if let Some(poisson) = self.poisson {
            tag(format!("poisson-{poisson}"));
        }
        if let Some(stiffening) = self.stiffening {
            tag(format!("stiffening-{stiffening}"));
        }
        if let Some(max_modes) = self.max_modes {
            tag(format!("modes-{max_modes}"));
        }
        if !self.inclusions.is_empty() {
            tag(format!("inclusions-{}", inclusions_tag(&self.inclusions)));
        }
        spec.build.tool_tip_radius_m = tip_m;
        spec.young_pa = self.young_pa;
        spec.poisson = self.poisson;
        spec.stiffening = self.stiffening;
        spec.build.pgd.max_modes = self.max_modes.unwrap_or(spec.build.pgd.max_modes);
        spec.inclusions = self.inclusions.clone();
        spec
    }
}

/// The files [`scene_of`] reads for the same arguments: each organ's vademecum, and the
/// distance field of the organ the others touch (which it builds when missing). A web page
/// fetches them first.
pub fn scene_files(
    organs: &[SceneOrgan],
    tip_radius_m: Option<f64>,
    coupling: &CouplingSettings,
    dir: &Path,
    detail: Detail,
) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for (organ, spec) in organs
        .iter()
        .zip(scene_vademecums(organs, tip_radius_m, dir, detail))
    {
        if organ.name == coupling.master {
            files.push(spec.field_file());
        }
        files.push(spec.file);
    }
    files
}

/// The vademecums [`scene_of`] loads for the same arguments, one per organ in order: what
/// each is built from and with, and where it is kept.
pub fn scene_vademecums(
    organs: &[SceneOrgan],
    tip_radius_m: Option<f64>,
    dir: &Path,
    detail: Detail,
) -> Vec<VademecumSpec> {
    let tip = scene_tip_m(organs, tip_radius_m, detail);
    organs
        .iter()
        .map(|organ| organ.vademecum(dir, detail, tip))
        .collect()
}

/// A scene of `organs` felt through a tool tip of `tip_radius_m` (the organs' own when
/// `None`; on coarse organs no finer than their edges need).
pub fn scene_of(
    organs: &[SceneOrgan],
    tip_radius_m: Option<f64>,
    coupling: &CouplingSettings,
    dir: &Path,
    detail: Detail,
    on_stale: OnStale,
) -> Result<HapticScene, String> {
    let tip = scene_tip_m(organs, tip_radius_m, detail);
    let specs = scene_vademecums(organs, tip_radius_m, dir, detail);
    let mut field_file = None;
    let loaded = organs
        .iter()
        .zip(&specs)
        .map(|(organ, spec)| {
            let (vademecum, mesh) = match on_stale {
                #[cfg(not(target_arch = "wasm32"))]
                OnStale::Meanwhile if organ.law != Law::Linear => {
                    linear_meanwhile(organ, spec.clone(), dir, detail, tip)?
                }
                _ => ensure_vademecum(spec, on_stale)?,
            };
            if organ.name == coupling.master {
                field_file = Some(spec.field_file());
            }
            Ok((organ.name.clone(), Arc::new(vademecum), mesh))
        })
        .collect::<Result<Vec<_>, String>>()?;
    // The organs running linear tissue while their own law's vademecum builds.
    let meanwhile = organs
        .iter()
        .zip(&loaded)
        .zip(specs)
        .filter(|((organ, (_, vademecum, _)), _)| vademecum.header.material.law != organ.law)
        .map(|(_, spec)| spec.file)
        .collect();
    let dynamics = scene_dynamics(organs, &loaded)?;
    let cutting = scene_cutting(organs, &loaded)?;
    let attachments: Vec<AttachmentSpec> = loaded
        .iter()
        .flat_map(|(name, vademecum, mesh)| attachments_of(name, vademecum, mesh))
        .collect();
    let organs: Vec<(String, Arc<Vademecum>)> = loaded
        .into_iter()
        .map(|(name, vademecum, _)| (name, vademecum))
        .collect();
    let (coupling, origin) = Coupling::new(&organs, &attachments, coupling, field_file.as_deref())
        .map_err(|e| e.to_string())?;
    if let Some(origin @ FieldOrigin::Built { .. }) = origin {
        eprintln!("distance field: {origin}");
    }
    // One instrument, in the open: a scalpel where an organ is cut, a grasper where one
    // moves, a probe otherwise (a scenario sets its own).
    let action = match (&cutting, &dynamics) {
        (Some(_), _) => Action::Cut,
        (None, Some(_)) => Action::Grasp,
        (None, None) => Action::Press,
    };
    Ok(HapticScene {
        organs,
        probe: Probe { tip_radius_m: tip },
        hands: vec![SceneHand {
            instruments: vec![Instrument { action, port: None }],
            workspace: Workspace::default(),
        }],
        safety: SafetySettings::default(),
        coupling: (!coupling.is_empty()).then(|| Arc::new(coupling)),
        beds: Vec::new(),
        dynamics,
        cutting,
        scope: None,
        biliary: None,
        meanwhile,
        assistant: None,
    })
}

#[cfg(not(target_arch = "wasm32"))]
/// `spec`, the nonlinear vademecum of `organ`, if it is built; else the organ's linear one
/// (built now if need be), `spec` queued to build in the background.
fn linear_meanwhile(
    organ: &SceneOrgan,
    spec: VademecumSpec,
    dir: &Path,
    detail: Detail,
    tip_m: f64,
) -> Result<(Vademecum, TetMesh), String> {
    if let Ok(built) = ensure_vademecum(&spec, OnStale::Refuse) {
        return Ok(built);
    }
    eprintln!(
        "{}: linear tissue until its {} vademecum is built, in the background ({})",
        organ.name,
        organ.law.name(),
        spec.file.display()
    );
    build_in_background(spec);
    let linear = SceneOrgan {
        law: Law::Linear,
        stiffening: None,
        ..organ.clone()
    };
    ensure_vademecum(&linear.vademecum(dir, detail, tip_m), OnStale::Rebuild)
}

/// The dynamic models of the organs that move (their tissue under the KSV law, whose reduced
/// energy is exact, in [`TRAINER_MODES`] modes from their vademecums); `None` if none does.
fn scene_dynamics(
    organs: &[SceneOrgan],
    loaded: &[(String, Arc<Vademecum>, TetMesh)],
) -> Result<Option<SceneDynamics>, String> {
    let mut moving = Vec::new();
    for (index, (organ, (name, vademecum, mesh))) in organs.iter().zip(loaded).enumerate() {
        if !organ.dynamic {
            continue;
        }
        let model = organ_model(name, vademecum, mesh, Law::KirchhoffSaintVenant)?;
        let dynamic = DynamicModel::new(&model, vademecum, TRAINER_MODES)
            .map_err(|e| format!("{name}: dynamics: {e}"))?;
        let lowest_hz = dynamic.basis.omega2[0].sqrt() / (2.0 * std::f64::consts::PI);
        eprintln!(
            "{name} moves: {} modes from {lowest_hz:.2} Hz",
            dynamic.basis.len()
        );
        moving.push((index, Arc::new(dynamic)));
    }
    Ok((!moving.is_empty()).then(|| SceneDynamics {
        organs: moving,
        grasp: GraspSettings::default(),
    }))
}

/// The tool tip (m) of a scene of `organs` at `detail`: the one `asked` for (the organs' own
/// when `None`), on coarse organs no finer than their edges need.
fn scene_tip_m(organs: &[SceneOrgan], asked: Option<f64>, detail: Detail) -> f64 {
    let smallest = |detail: Detail| {
        let tips = organs
            .iter()
            .map(move |o| detail.smallest_tip_m(o.source.organ()));
        tips.fold(0.0, f64::max)
    };
    match detail {
        Detail::Full => asked.unwrap_or_else(|| smallest(Detail::Full)),
        Detail::Coarse => smallest(Detail::Coarse).max(asked.unwrap_or(0.0)),
    }
}

/// The organs a scalpel cuts, each with the linear model of its tissue that its cut state
/// is solved on (the default blade; a scenario sets its own); `None` if none is cut.
fn scene_cutting(
    organs: &[SceneOrgan],
    loaded: &[(String, Arc<Vademecum>, TetMesh)],
) -> Result<Option<SceneCutting>, String> {
    let mut cut = Vec::new();
    for (index, (organ, (name, vademecum, mesh))) in organs.iter().zip(loaded).enumerate() {
        let Some(toughness_j_per_m2) = organ.cut_toughness_j_per_m2 else {
            continue;
        };
        let model = organ_model(name, vademecum, mesh, Law::Linear)?;
        let keratometer = match organ.source == OrganSource::Generated(Organ::Cornea) {
            true => {
                let cornea = reference_cornea().map_err(|e| format!("{name}: {e}"))?;
                Some(Keratometer::new(cornea))
            }
            false => None,
        };
        cut.push(CutOrgan {
            index,
            model: Arc::new(model),
            toughness_j_per_m2,
            drawn: Arc::default(),
            keratometer,
        });
    }
    Ok((!cut.is_empty()).then(|| SceneCutting {
        blade: Blade::default(),
        organs: cut,
    }))
}

/// The reference cornea under the intraocular pressure, set up once (an assembly and a
/// solve of 16,000 nodes) for every scene that cuts a cornea.
fn reference_cornea() -> Result<Arc<Cornea>, CutError> {
    static REFERENCE: OnceLock<Arc<Cornea>> = OnceLock::new();
    if let Some(cornea) = REFERENCE.get() {
        return Ok(cornea.clone());
    }
    let cornea = Arc::new(Cornea::reference()?);
    Ok(REFERENCE.get_or_init(|| cornea).clone())
}

/// The organ's finite-element model under `law`: its mesh clamped, its tissue and stiffer
/// regions as its vademecum was built with.
fn organ_model(
    name: &str,
    vademecum: &Vademecum,
    mesh: &TetMesh,
    law: Law,
) -> Result<FemModel, String> {
    let header = &vademecum.header;
    let material = header.material.with_law(law);
    crate::pgd::organ::clamped_model(mesh.clone(), material)
        .and_then(|m| m.with_inclusions(&header.inclusions))
        .map_err(|e| format!("{name}: {e}"))
}

/// A short tag that tells one set of inclusions from another in a file name.
fn inclusions_tag(inclusions: &[Inclusion]) -> String {
    let hash = blake3::hash(format!("{inclusions:?}").as_bytes());
    hash.to_hex()[..8].to_owned()
}

/// The attachments `organ` carries: each `attached_<other>` node set of its mesh, as the free
/// load positions it covers (an organ clamped at its attachment hangs from it and carries
/// nothing there).
fn attachments_of(organ: &str, vademecum: &Vademecum, mesh: &TetMesh) -> Vec<AttachmentSpec> {
    let sets = &mesh.regions().node_sets;
    let clamped: BTreeSet<usize> = sets
        .get(region::CLAMPED)
        .into_iter()
        .flatten()
        .copied()
        .collect();
    sets.iter()
        .filter_map(|(name, nodes)| {
            let carried = name.strip_prefix(region::ATTACHED_PREFIX)?;
            let nodes: BTreeSet<usize> = nodes
                .iter()
                .filter(|n| !clamped.contains(n))
                .copied()
                .collect();
            let interface = (0..vademecum.positions.len())
                .filter(|&m| nodes.contains(&(vademecum.positions[m] as usize)))
                .collect();
            Some(AttachmentSpec {
                carrier: organ.to_owned(),
                carried: carried.to_owned(),
                interface,
            })
        })
        .collect()
}

/// The mouse's device for `scene`'s hand `hand`, its tool starting 3 cm in front of the first
/// organ's press target (the left hand's 4 cm to the left of the right's), and the handle the
/// window moves it by.
pub fn mouse_device(
    scene: &HapticScene,
    hand: usize,
) -> (Box<dyn HapticDevice>, Arc<VirtualHandle>) {
    let start = press_targets(scene)
        .first()
        .map_or_else(Vector3::zeros, |t| t.point_m + t.normal * 0.03);
    let start = start - Vector3::x() * (LEFT_HAND_APART_M * hand as f64);
    let workspace = scene.hands[hand].workspace;
    let (device, handle) = VirtualDevice::new(&workspace.to_device(&start));
    (Box::new(device), handle)
}

/// How far to the left of the right hand's tool the mouse's left hand starts (m).
const LEFT_HAND_APART_M: f64 = 0.04;

/// Each hand's device: the mouse's wherever no other is named.
pub struct HandDevices {
    /// One a hand, the right hand's first.
    pub devices: Vec<Box<dyn HapticDevice>>,
    /// The mouse's handle of each hand it drives, by hand.
    pub mice: Vec<Option<Arc<VirtualHandle>>>,
}

impl HandDevices {
    /// Every hand of `scene` on the mouse.
    pub fn mouse(scene: &HapticScene) -> Self {
        let mut devices = Self {
            devices: Vec::new(),
            mice: Vec::new(),
        };
        for hand in 0..scene.hands.len() {
            let (device, handle) = mouse_device(scene, hand);
            devices.devices.push(device);
            devices.mice.push(Some(handle));
        }
        devices
    }
}

/// Per organ, the accessible point that faces the surgeon most (the largest anterior
/// component of its normal): where the built-in demo presses.
pub fn press_targets(scene: &HapticScene) -> Vec<PressTarget> {
    scene
        .organs
        .iter()
        .filter_map(|(_, vademecum)| most_anterior(vademecum))
        .collect()
}

fn most_anterior(vademecum: &Vademecum) -> Option<PressTarget> {
    let normals = vademecum.rest_normals();
    let best = (0..normals.len()).max_by(|&a, &b| normals[a].y.total_cmp(&normals[b].y))?;
    Some(PressTarget {
        point_m: Vector3::from(vademecum.position_coords_m[best].map(f64::from)),
        normal: normals[best],
    })
}
