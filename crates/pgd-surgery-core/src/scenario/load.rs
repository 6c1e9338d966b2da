//! Reading a scenario file: RON syntax, field names and units while deserializing (ron knows
//! the line and column, serde_path_to_error the field path), then what only the whole
//! scenario can tell (an organ a task names but the scene lacks, a force band upside down),
//! located in the text by the field it is about. Every error names the file, the line and
//! column, the field path, the problem and a hint.

use std::fmt;
use std::path::{Path, PathBuf};

use super::format::{LaparoscopeEntry, OrganEntry, Scenario, Task, metres};
use super::keratotomy::MIN_INCISION_M;
use crate::contact::PointshellDensity;
use crate::devices::{DeviceSpec, MAX_INSTRUMENTS};
use crate::fem::Law;
use crate::mesh::Surface;
use crate::mesh::organs::{Organ, OrganSettings, region};
use parry3d::query::PointQuery;

/// Where every reference of the scenario format is explained.
const REFERENCE: &str = "docs/scenarios.md";

#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioError {
    pub file: PathBuf,
    /// 1-based, as editors count.
    pub line: usize,
    pub column: usize,
    /// The field path, e.g. `tasks[1].max_force_n` (empty for the file as a whole).
    pub field: String,
    pub message: String,
    pub hint: String,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}: ", self.file.display(), self.line, self.column)?;
        if !self.field.is_empty() {
            write!(f, "{}: ", self.field)?;
        }
        write!(f, "{}\n  hint: {}", self.message, self.hint)
    }
}

impl std::error::Error for ScenarioError {}

impl ScenarioError {
    /// `file` could not be read as text, for the reason `why`.
    pub fn unreadable(file: &Path, why: impl fmt::Display) -> Self {
        Self {
            file: file.to_owned(),
            line: 1,
            column: 1,
            field: String::new(),
            message: format!("cannot read it: {why}"),
            hint: "check the path; shipped scenarios are in scenarios/".into(),
        }
    }
}

/// Reads and checks the scenario in `file`.
pub fn load(file: &Path) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(file).map_err(|e| ScenarioError::unreadable(file, e))?;
    parse(file, &text)
}

/// Parses and checks scenario text; `file` names it in errors.
pub fn parse(file: &Path, text: &str) -> Result<Scenario, ScenarioError> {
    let syntax = |e: ron::error::SpannedError, field: String| {
        let hint = hint_for(&e.code);
        ScenarioError {
            file: file.to_owned(),
            line: e.span.start.line,
            column: e.span.start.col,
            field,
            message: e.code.to_string(),
            hint,
        }
    };
    // Optional fields are written as their value, without `Some(…)`.
    let options =
        ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    let mut de = ron::Deserializer::from_str_with_options(text, &options)
        .map_err(|e| syntax(e, String::new()))?;
    let mut scenario: Scenario = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // serde_path_to_error writes `?` for a step it cannot name and `.` for the root.
        let field = e.path().to_string().replace('?', "");
        let field = field.trim_matches('.').to_owned();
        syntax(de.span_error(e.into_inner()), field)
    })?;
    de.end()
        .map_err(|e| syntax(de.span_error(e), String::new()))?;
    // Mesh files are written relative to the scenario's folder.
    let folder = file.parent().unwrap_or(Path::new(""));
    for mesh in scenario.organs.iter_mut().filter_map(|o| o.mesh.as_mut()) {
        *mesh = folder.join(&*mesh);
    }
    let problems = check(&scenario);
    match problems.into_iter().next() {
        None => Ok(scenario),
        Some(problem) => Err(problem.locate(file, text)),
    }
}

fn hint_for(code: &ron::Error) -> String {
    use ron::Error as E;
    match code {
        E::NoSuchStructField { expected, .. } => {
            format!("the fields here are: {}", expected.join(", "))
        }
        E::MissingStructField { field, .. } => format!("add `{field}: …` ({REFERENCE})"),
        E::NoSuchEnumVariant { expected, .. } => {
            format!("one of: {}", expected.join(", "))
        }
        E::Message(_) => format!("units and ranges are listed in {REFERENCE}"),
        _ => format!(
            "RON syntax: `Name(field: value, …)`, lists in `[…]`, text in \"…\" ({REFERENCE})"
        ),
    }
}

/// A problem found after parsing: the field path, and what to look for in the text to put
/// the cursor on it (each key or quoted value in turn, from the start of the file; the same
/// anchor twice in a row, the next occurrence).
struct Problem {
    field: String,
    anchors: Vec<String>,
    message: String,
    hint: String,
}

impl Problem {
    fn locate(self, file: &Path, text: &str) -> ScenarioError {
        let mut at = 0;
        let mut previous: Option<&String> = None;
        for anchor in &self.anchors {
            // An anchor repeated finds the next occurrence (the k-th item of a list).
            let from = at + previous.filter(|p| *p == anchor).map_or(0, |p| p.len());
            if let Some(found) = text.get(from..).and_then(|rest| rest.find(anchor.as_str())) {
                at = from + found;
            }
            previous = Some(anchor);
        }
        let line = text[..at].matches('\n').count() + 1;
        let column = at - text[..at].rfind('\n').map_or(0, |n| n + 1) + 1;
        ScenarioError {
            file: file.to_owned(),
            line,
            column,
            field: self.field,
            message: self.message,
            hint: self.hint,
        }
    }
}

/// What is wrong with a scenario as a whole, in file order.
fn check(scenario: &Scenario) -> Vec<Problem> {
    let mut problems = Vec::new();
    if scenario.organs.is_empty() {
        problems.push(Problem {
            field: "organs".into(),
            anchors: vec!["organs".into()],
            message: "the scene has no organs".into(),
            hint: format!("name at least one of: {}", generated_organs()),
        });
    }
    for (k, organ) in scenario.organs.iter().enumerate() {
        problems.extend(check_organ(k, organ));
        problems.extend(check_stiffening(k, organ, scenario.law_of(organ)));
        if scenario.organs[..k].iter().any(|o| o.name == organ.name) {
            problems.push(Problem {
                field: format!("organs[{k}]"),
                anchors: vec!["organs".into(), format!("\"{}\"", organ.name)],
                message: format!("`{}` is named twice", organ.name),
                hint: "name each organ once".into(),
            });
        }
    }
    for (k, nodule) in scenario.nodules.iter().enumerate() {
        let field = format!("nodules[{k}].organ");
        problems.extend(not_in_scene(scenario, &nodule.organ, field, "nodules"));
    }
    if let Some(master) = &scenario.contact.master {
        problems.extend(not_in_scene(
            scenario,
            master,
            "contact.master".into(),
            "contact",
        ));
    }
    if let Err(message) = scenario.contact.pointshell.check() {
        let (variant, hint) = match scenario.contact.pointshell {
            PointshellDensity::Sparse(_) => (
                "Sparse",
                "`Nodes` tests every surface node; `Sparse(mm)` keeps them at least `mm` apart",
            ),
            _ => (
                "Subdivided",
                "a coarser pointshell: `Nodes` tests the surface nodes, `Dense` adds the triangles' centres",
            ),
        };
        problems.push(Problem {
            field: "contact.pointshell".into(),
            anchors: vec!["contact".into(), variant.into()],
            message,
            hint: hint.into(),
        });
    }
    if scenario.tasks.is_empty() {
        problems.push(Problem {
            field: "tasks".into(),
            anchors: vec!["tasks".into()],
            message: "the scenario has no tasks".into(),
            hint: format!(
                "add a ForceControl(…), SafeNavigation(…), Palpation(…), Retraction(…) or Grasp(…) task ({REFERENCE})"
            ),
        });
    }
    for (k, task) in scenario.tasks.iter().enumerate() {
        check_task(scenario, k, task, &mut problems);
    }
    check_rubric(scenario, &mut problems);
    check_laparoscope(scenario, &mut problems);
    check_instruments(scenario, &mut problems);
    check_backend(scenario, &mut problems);
    problems
}

/// A scripted camera's keys run forward in time from 0, each at a point the optic can look at.
fn check_script(scope: &LaparoscopeEntry) -> Option<Problem> {
    let optic = scope.laparoscope();
    scope.script.iter().enumerate().find_map(|(k, key)| {
        let earlier = k.checked_sub(1).map_or(0.0, |j| scope.script[j].at_s);
        let message = if !(key.at_s.is_finite() && key.at_s >= earlier) {
            format!("the key at {} s comes before the one at {earlier} s", key.at_s)
        } else if optic
            .aim(&metres(key.look_at_mm), key.distance_mm.metres(), 0.0)
            .is_none()
        {
            "the optic cannot look at this point from its port: the port is too near it".into()
        } else {
            return None;
        };
        Some(Problem {
            field: format!("laparoscope.script[{k}]"),
            anchors: vec!["laparoscope".into(), "script".into(), "Look".into()]
                .into_iter()
                .chain(std::iter::repeat_n("Look".to_owned(), k))
                .collect(),
            message,
            hint: "keys in time order from 0 s, each looking at a point farther from the port than distance_mm".into(),
        })
    })
}

/// The laparoscope must be able to look at its focus from where it enters, and a rubric that
/// weighs the view needs a camera to have one.
fn check_laparoscope(scenario: &Scenario, problems: &mut Vec<Problem>) {
    match &scenario.laparoscope {
        // A scripted camera starts at its first key, which `check_script` places the error on.
        Some(scope) if scope.script.is_empty() && scope.start().is_none() => problems.push(Problem {
            field: "laparoscope.look_at_mm".into(),
            anchors: vec!["laparoscope".into(), "look_at_mm".into()],
            message: format!(
                "the optic cannot look at ({}, {}, {}) from {} mm away: the port is too near it",
                scope.look_at_mm.0, scope.look_at_mm.1, scope.look_at_mm.2, scope.distance_mm.0
            ),
            hint: "put the port farther from the point looked at, or shorten distance_mm".into(),
        }),
        Some(scope) => problems.extend(check_script(scope)),
        None if scenario.rubric.view > 0.0 => problems.push(Problem {
            field: "rubric.view".into(),
            anchors: vec!["rubric".into(), "view".into()],
            message: "the rubric weighs the view, but the scenario has no laparoscope".into(),
            hint: "add `laparoscope: Laparoscope(port_mm: …, look_at_mm: …)`, or drop `view`"
                .into(),
        }),
        _ => {}
    }
}

/// A list of instruments replaces `tool` and `port`, holds at most [`MAX_INSTRUMENTS`], and
/// presses with one tip: the organs' vademecums are built for one tool radius.
fn check_instruments(scenario: &Scenario, problems: &mut Vec<Problem>) {
    let Some(first) = scenario.instruments.first() else {
        return;
    };
    let problem = |field: String, anchors: Vec<String>, message: String, hint: &str| Problem {
        field,
        anchors,
        message,
        hint: hint.into(),
    };
    for (name, given) in [
        ("tool", scenario.tool.is_some()),
        ("port", scenario.port.is_some()),
    ] {
        if given {
            problems.push(problem(
                name.into(),
                vec![format!("{name}:")],
                format!("`{name}` and `instruments` both say what the trainee holds"),
                "give each instrument its tool and port inside `instruments`, and drop `tool` and `port`",
            ));
        }
    }
    if scenario.instruments.len() > MAX_INSTRUMENTS {
        problems.push(problem(
            "instruments".into(),
            vec!["instruments".into()],
            format!(
                "{} instruments: the trainee can change between {MAX_INSTRUMENTS} at most",
                scenario.instruments.len()
            ),
            "keep the instruments the exercise needs",
        ));
    }
    let tip_m = first.tool.tip_radius_m();
    for (k, instrument) in scenario.instruments.iter().enumerate().skip(1) {
        let other_m = instrument.tool.tip_radius_m();
        if (other_m - tip_m).abs() > 1e-9 {
            // The k-th instrument's tip: the anchor repeated steps through the list.
            let mut anchors = vec!["instruments".to_owned()];
            anchors.extend(std::iter::repeat_n("Instrument(".to_owned(), k + 1));
            anchors.push("tip_radius_mm".into());
            problems.push(problem(
                format!("instruments[{k}].tool.tip_radius_mm"),
                anchors,
                format!(
                    "its tip is {} mm, the first instrument's {} mm: the organs are built for one tip",
                    other_m * 1e3,
                    tip_m * 1e3
                ),
                "give every instrument the first one's tip_radius_mm",
            ));
        }
    }
}

/// A device the scenario names must be one the trainer knows.
fn check_backend(scenario: &Scenario, problems: &mut Vec<Problem>) {
    let Some(backend) = &scenario.device.backend else {
        return;
    };
    if let Err(message) = backend.parse::<DeviceSpec>() {
        problems.push(Problem {
            field: "device.backend".into(),
            anchors: vec!["device".into(), "backend".into()],
            message,
            hint: "`trainer devices` lists the devices and which this machine has".into(),
        });
    }
}

fn check_task(scenario: &Scenario, k: usize, task: &Task, problems: &mut Vec<Problem>) {
    let field = |name: &str| format!("tasks[{k}].{name}");
    let anchors = |name: &str| vec!["tasks".to_owned(), name.to_owned()];
    let device_limit = scenario.device.max_force_n.0;
    match task {
        Task::ForceControl {
            organ,
            min_force_n,
            max_force_n,
            hold_s,
            time_limit_s,
        } => {
            problems.extend(not_in_scene(scenario, organ, field("organ"), "tasks"));
            if min_force_n.0 >= max_force_n.0 {
                problems.push(Problem {
                    field: field("min_force_n"),
                    anchors: anchors("min_force_n"),
                    message: format!(
                        "the band is empty: {} N is not below max_force_n {} N",
                        min_force_n.0, max_force_n.0
                    ),
                    hint: "min_force_n must be below max_force_n".into(),
                });
            }
            if max_force_n.0 > device_limit {
                problems.push(Problem {
                    field: field("max_force_n"),
                    anchors: anchors("max_force_n"),
                    message: format!(
                        "{} N is above the device's limit of {device_limit} N: the band cannot be reached",
                        max_force_n.0
                    ),
                    hint: "lower it, or raise device.max_force_n".into(),
                });
            }
            problems.extend(hold_fits(hold_s.0, time_limit_s.0, field("hold_s")));
        }
        Task::Retraction {
            organ,
            towards,
            hold_s,
            time_limit_s,
            ..
        }
        | Task::Grasp {
            organ,
            towards,
            hold_s,
            time_limit_s,
            ..
        } => {
            problems.extend(not_in_scene(scenario, organ, field("organ"), "tasks"));
            if matches!(task, Task::Grasp { .. }) && !scenario.grasps() {
                problems.push(Problem {
                    field: field("organ"),
                    anchors: anchors("organ"),
                    message: "a Grasp task needs a grasper to grasp with".into(),
                    hint: "set tool: Grasper(tip_radius_mm: 6.0)".into(),
                });
            }
            let (x, y, z) = *towards;
            if !(x * x + y * y + z * z).is_normal() {
                problems.push(Problem {
                    field: field("towards"),
                    anchors: anchors("towards"),
                    message: "the direction to move the region in has no length".into(),
                    hint: "give a direction such as (0.0, 0.0, 1.0) (towards the head)".into(),
                });
            }
            problems.extend(hold_fits(hold_s.0, time_limit_s.0, field("hold_s")));
        }
        Task::Palpation { organ, .. } => {
            problems.extend(not_in_scene(scenario, organ, field("organ"), "tasks"));
            if !scenario.nodules.iter().any(|n| &n.organ == organ) {
                problems.push(Problem {
                    field: field("organ"),
                    anchors: vec!["tasks".into(), "Palpation".into(), format!("\"{organ}\"")],
                    message: format!("the {organ} has no nodule to find"),
                    hint: format!(
                        "add `nodules: [Nodule(organ: \"{organ}\", at_mm: (x, y, z), radius_mm: …, stiffness_ratio: …)]` ({REFERENCE})"
                    ),
                });
            }
        }
        Task::Incision {
            organ,
            from_mm,
            to_mm,
            depth_mm,
            max_force_n,
            ..
        } => {
            problems.extend(not_in_scene(scenario, organ, field("organ"), "tasks"));
            problems.extend(check_incision(
                scenario,
                organ,
                (from_mm, to_mm),
                depth_mm.0,
                &field,
            ));
            problems.extend(within_device(max_force_n.0, device_limit, &field));
        }
        Task::RadialKeratotomy {
            organ,
            optical_zone_mm,
            max_force_n,
            ..
        } => {
            problems.extend(not_in_scene(scenario, organ, field("organ"), "tasks"));
            problems.extend(check_keratotomy(scenario, organ, optical_zone_mm.0, &field));
            problems.extend(within_device(max_force_n.0, device_limit, &field));
        }
        Task::SafeNavigation { targets, .. } => {
            if targets.is_empty() {
                problems.push(Problem {
                    field: field("targets"),
                    anchors: anchors("targets"),
                    message: "there are no targets to reach".into(),
                    hint: "add Spot(name: …, at_mm: (x, y, z), radius_mm: …) targets".into(),
                });
            }
        }
    }
}

/// A task's force limit must be one the device can send.
fn within_device(
    max_force_n: f64,
    device_limit: f64,
    field: &dyn Fn(&str) -> String,
) -> Option<Problem> {
    (max_force_n > device_limit).then(|| Problem {
        field: field("max_force_n"),
        anchors: vec!["tasks".into(), "max_force_n".into()],
        message: format!("{max_force_n} N is above the device's limit of {device_limit} N"),
        hint: "lower it, or raise device.max_force_n".into(),
    })
}

/// A cutting task (`Incision`, `RadialKeratotomy`) needs a scalpel and an organ whose
/// toughness under a blade is known.
fn check_blade(
    scenario: &Scenario,
    organ: &str,
    task: &str,
    field: &dyn Fn(&str) -> String,
) -> Vec<Problem> {
    let anchors = || vec!["tasks".to_owned(), task.to_owned(), "organ".into()];
    let mut problems = Vec::new();
    if scenario.blade().is_none() {
        problems.push(Problem {
            field: field("organ"),
            anchors: anchors(),
            message: format!("an {task} task needs a scalpel to cut with"),
            hint: "set tool: Scalpel(tip_radius_mm: 6.0)".into(),
        });
    }
    if let Some(entry) = scenario.organ(organ)
        && entry.toughness_j_per_m2().is_none()
    {
        problems.push(Problem {
            field: field("organ"),
            anchors: anchors(),
            message: format!("the {organ}'s toughness under a blade is not known: it cannot be cut"),
            hint: format!(
                "give it one: Organ(name: \"{organ}\", toughness_j_per_m2: 190.0) (the liver's is known)"
            ),
        });
    }
    problems
}

/// A keratotomy cuts the generated cornea, with room for its incisions between the optical
/// zone and the limbus.
fn check_keratotomy(
    scenario: &Scenario,
    organ: &str,
    optical_zone_mm: f64,
    field: &dyn Fn(&str) -> String,
) -> Vec<Problem> {
    let mut problems = check_blade(scenario, organ, "RadialKeratotomy", field);
    let anchors = |name: &str| vec!["tasks".into(), "RadialKeratotomy".into(), name.to_owned()];
    let cornea = scenario
        .organ(organ)
        .is_some_and(|e| e.mesh.is_none() && Organ::from_name(&e.name) == Some(Organ::Cornea));
    if scenario.organ(organ).is_some() && !cornea {
        problems.push(Problem {
            field: field("organ"),
            anchors: anchors("organ"),
            message: format!("radial keratotomy cuts the cornea, not the {organ}"),
            hint: "put \"cornea\" in organs and name it here".into(),
        });
    }
    let outer_mm = crate::cutting::keratotomy::INCISION_END_M * 1e3;
    let room_mm = outer_mm - optical_zone_mm / 2.0;
    if room_mm < MIN_INCISION_M * 1e3 {
        problems.push(Problem {
            field: field("optical_zone_mm"),
            anchors: anchors("optical_zone_mm"),
            message: format!(
                "a {optical_zone_mm} mm optical zone leaves no room for incisions: they end \
                 {outer_mm:.2} mm off the axis, {:.1} mm inside the {:.1} mm cornea's limbus",
                crate::mesh::organs::CORNEA_RIM_M * 1e3 - outer_mm,
                2.0 * crate::mesh::organs::CORNEA_RIM_M * 1e3,
            ),
            hint: format!(
                "an optical zone is 3 to 4 mm across; at most {:.1} mm here",
                2.0 * (outer_mm - MIN_INCISION_M * 1e3)
            ),
        });
    }
    problems
}

/// An incision needs a scalpel, an organ a scalpel can part, a line of some length and a
/// depth the organs' thickness allows.
fn check_incision(
    scenario: &Scenario,
    organ: &str,
    (from_mm, to_mm): (&(f64, f64, f64), &(f64, f64, f64)),
    depth_mm: f64,
    field: &dyn Fn(&str) -> String,
) -> Vec<Problem> {
    let anchors = |name: &str| vec!["tasks".to_owned(), "Incision".into(), name.to_owned()];
    let mut problems = check_blade(scenario, organ, "Incision", field);
    let length_mm = (metres(*to_mm) - metres(*from_mm)).norm() * 1e3;
    if length_mm < 5.0 {
        problems.push(Problem {
            field: field("to_mm"),
            anchors: anchors("to_mm"),
            message: format!("the line is {length_mm:.1} mm long: too short to cut and score"),
            hint: "mark a line at least 5 mm long, from_mm to to_mm in the scene's frame".into(),
        });
    }
    if let Some(entry) = scenario.organ(organ)
        && let Some((end, distance_mm)) = farthest_off_surface(entry, [from_mm, to_mm])
    {
        let name = ["from_mm", "to_mm"][end];
        problems.push(Problem {
            field: field(name),
            anchors: anchors(name),
            message: format!("the line's end is {distance_mm:.0} mm off the {organ}'s surface"),
            hint: format!(
                "mark the line on the {organ}'s surface (within {LINE_ON_SURFACE_MM} mm); \
                 `pgd mesh {organ} --out FILE.vtu` writes its mesh to look at"
            ),
        });
    }
    if depth_mm > MAX_INCISION_DEPTH_MM {
        problems.push(Problem {
            field: field("depth_mm"),
            anchors: anchors("depth_mm"),
            message: format!("{depth_mm} mm is deeper than a scalpel's incision goes here"),
            hint: format!("at most {MAX_INCISION_DEPTH_MM} mm"),
        });
    }
    problems
}

/// The deepest incision a task may ask for (mm).
const MAX_INCISION_DEPTH_MM: f64 = 30.0;

/// How far (mm) a line's end may lie from the organ's surface as the check meshes it (the
/// coarse organ, whose surface is within a few millimetres of the full one's).
const LINE_ON_SURFACE_MM: f64 = 5.0;

/// The end of `points_mm` farthest from the organ's surface (0 or 1) and its distance (mm), if
/// more than [`LINE_ON_SURFACE_MM`]; `None` also when the organ's mesh cannot be had (its own
/// check says why).
fn farthest_off_surface(
    entry: &OrganEntry,
    points_mm: [&(f64, f64, f64); 2],
) -> Option<(usize, f64)> {
    let mesh = match (&entry.mesh, Organ::from_name(&entry.name)) {
        (Some(path), _) => crate::mesh::io::load(path, &Default::default()).ok()?,
        (None, Some(organ)) => {
            let coarse = OrganSettings {
                resolution: 0.25,
                ..OrganSettings::default()
            };
            crate::mesh::organs::generate(organ, &coarse).ok()?
        }
        (None, None) => return None,
    };
    let surface = Surface::extract(&mesh);
    let positions: Vec<[f32; 3]> = mesh
        .nodes()
        .iter()
        .map(|p| p.cast::<f32>().into())
        .collect();
    let triangles: Vec<[u32; 3]> = surface
        .triangles
        .iter()
        .map(|t| t.map(|n| n as u32))
        .collect();
    let trimesh = crate::parry_interop::trimesh(&positions, &triangles)?;
    let distance_mm = |p: &(f64, f64, f64)| {
        let point = nalgebra::Point3::from(metres(*p));
        let query = crate::parry_interop::to_parry(&point);
        let projected = trimesh.project_local_point(query, false).point;
        (crate::parry_interop::from_parry(projected) - point).norm() * 1e3
    };
    let distances = points_mm.map(distance_mm);
    let end = usize::from(distances[1] > distances[0]);
    (distances[end] > LINE_ON_SURFACE_MM).then_some((end, distances[end]))
}

fn generated_organs() -> String {
    let names: Vec<&str> = Organ::ABDOMEN.iter().map(|o| o.name()).collect();
    names.join(", ")
}

/// A problem with the scene's `k`th organ: a generated one that does not exist, or a mesh file
/// that does not read or lacks the regions a vademecum needs.
fn check_organ(k: usize, organ: &OrganEntry) -> Option<Problem> {
    let name = &organ.name;
    let Some(mesh) = &organ.mesh else {
        return Organ::from_name(name).is_none().then(|| Problem {
            field: format!("organs[{k}]"),
            anchors: vec!["organs".into(), format!("\"{name}\"")],
            message: format!("there is no organ `{name}`"),
            hint: format!(
                "the generated organs are: {}; an organ of your own needs its mesh: Organ(name: \"{name}\", mesh: \"{name}.vtu\")",
                generated_organs()
            ),
        });
    };
    let problem = |message: String, hint: &str| Problem {
        field: format!("organs[{k}].mesh"),
        anchors: vec!["organs".into(), format!("\"{name}\""), "mesh".into()],
        message,
        hint: hint.into(),
    };
    let regions_hint = "name the fixed nodes `clamped` and the surface the tool may touch `accessible` (Gmsh physical groups, VTK point data); `pgd mesh FILE` lists a mesh's regions";
    match crate::mesh::io::load(mesh, &Default::default()) {
        Err(e) => Some(problem(
            e.to_string(),
            "a tetrahedral mesh in metres (.msh, .vtk or .vtu), its path relative to the scenario's folder",
        )),
        Ok(tets) => {
            let missing = if tets.node_set(region::CLAMPED).is_err() {
                Some(format!(
                    "no `{}` node set (the nodes held fixed)",
                    region::CLAMPED
                ))
            } else if tets.face_set(region::ACCESSIBLE).is_err() {
                Some(format!(
                    "no `{}` surface (where the tool may touch)",
                    region::ACCESSIBLE
                ))
            } else {
                None
            };
            missing.map(|what| problem(format!("{} has {what}", mesh.display()), regions_hint))
        }
    }
}

/// A problem if the `k`th organ sets a stiffening under its `law`, which has none.
fn check_stiffening(k: usize, organ: &OrganEntry, law: Law) -> Option<Problem> {
    (organ.stiffening.is_some() && law != Law::Exponential).then(|| Problem {
        field: format!("organs[{k}].stiffening"),
        anchors: vec![
            "organs".into(),
            format!("\"{}\"", organ.name),
            "stiffening".into(),
        ],
        message: format!("the {} law has no stiffening", law.name()),
        hint: "set `law: Exponential` with it, or leave it out".into(),
    })
}

/// A problem if holding for `hold_s` (at `field`) cannot fit in the task's time limit.
fn hold_fits(hold_s: f64, time_limit_s: f64, field: String) -> Option<Problem> {
    (hold_s >= time_limit_s).then(|| Problem {
        field,
        anchors: vec!["tasks".into(), "hold_s".into()],
        message: format!("holding {hold_s} s cannot fit in the time limit of {time_limit_s} s"),
        hint: "make time_limit_s longer than hold_s".into(),
    })
}

/// A problem if `organ`, named at `field` in the `section` of the file, is not in the scene.
fn not_in_scene(scenario: &Scenario, organ: &str, field: String, section: &str) -> Option<Problem> {
    scenario.organ(organ).is_none().then(|| Problem {
        field,
        anchors: vec![section.into(), format!("\"{organ}\"")],
        message: format!("`{organ}` is not in this scenario's organs"),
        hint: format!("the scene has: {}", scenario.organ_names()),
    })
}

fn check_rubric(scenario: &Scenario, problems: &mut Vec<Problem>) {
    let rubric = &scenario.rubric;
    let weights = [
        rubric.completion,
        rubric.speed,
        rubric.force,
        rubric.accuracy,
        rubric.motion,
        rubric.view,
    ];
    if weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) || weights.iter().sum::<f64>() <= 0.0 {
        problems.push(Problem {
            field: "rubric".into(),
            anchors: vec!["rubric".into()],
            message: format!("the weights {weights:?} are not usable"),
            hint:
                "completion, speed, force, accuracy, motion and view are weights of 0 or more, not all 0"
                    .into(),
        });
    }
    if !(0.0..=100.0).contains(&rubric.pass_mark) {
        problems.push(Problem {
            field: "rubric.pass_mark".into(),
            anchors: vec!["rubric".into(), "pass_mark".into()],
            message: format!("{} is not a score", rubric.pass_mark),
            hint: "scores run from 0 to 100".into(),
        });
    }
    if !(rubric.error_penalty.is_finite() && rubric.error_penalty >= 0.0) {
        problems.push(Problem {
            field: "rubric.error_penalty".into(),
            anchors: vec!["rubric".into(), "error_penalty".into()],
            message: format!("{} is not a penalty", rubric.error_penalty),
            hint: "points lost per error, 0 or more".into(),
        });
    }
}
