//! Reading a scenario file: RON syntax, field names and units while deserializing (ron knows
//! the line and column, serde_path_to_error the field path), then what only the whole
//! scenario can tell (an organ a task names but the scene lacks, a force band upside down),
//! located in the text by the field it is about. Every error names the file, the line and
//! column, the field path, the problem and a hint.

use std::path::Path;

use super::attachment::{AttachmentEntry, facing};
use super::format::{LaparoscopeEntry, Scenario, Tool};
use super::global::Benchmark;
use super::operation::{Event, OperationRubric};
use super::phases::phase_out_of_order;
use super::problem::{Problem, REFERENCE, ScenarioError};
use super::scene::{OrganEntry, metres};
use super::task::{BandEnd, Countertraction, Hand, SceneFacts, Task, TaskCheck};
use super::tasks::registered_names;
use crate::contact::PointshellDensity;
use crate::devices::{DeviceSpec, MAX_INSTRUMENTS};
use crate::fem::Law;
use crate::mesh::organs::{Organ, region};

/// Reads and checks the scenario in `file`.
pub fn load(file: &Path) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(file).map_err(|e| ScenarioError::unreadable(file, e))?;
    parse(file, &text)
}

/// Parses and checks scenario text; `file` names it in errors.
pub fn parse(file: &Path, text: &str) -> Result<Scenario, ScenarioError> {
    let mut scenario: Scenario = read_ron(file, text)?;
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

/// RON text as a `T`, an error naming the line, the column and the field path where it is
/// not one; `file` names it in errors.
pub(super) fn read_ron<T: serde::de::DeserializeOwned>(
    file: &Path,
    text: &str,
) -> Result<T, ScenarioError> {
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
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // serde_path_to_error writes `?` for a step it cannot name and `.` for the root.
        let field = e.path().to_string().replace('?', "");
        let field = field.trim_matches('.').to_owned();
        syntax(de.span_error(e.into_inner()), field)
    })?;
    de.end()
        .map_err(|e| syntax(de.span_error(e), String::new()))?;
    Ok(value)
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
    for (k, attachment) in scenario.attachments.iter().enumerate() {
        check_attachment(scenario, k, attachment, &mut problems);
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
                "add a task, one of: {} ({REFERENCE})",
                registered_names().join(", ")
            ),
        });
    }
    let scene = SceneFacts {
        organs: &scenario.organs,
        nodules: &scenario.nodules,
        blade: scenario.blade().is_some(),
        grasps: scenario.grasps(),
        hook: scenario.hook(),
        clips: scenario.holds(|t| matches!(t, Tool::ClipApplier { .. })),
        divides: scenario.holds(|t| matches!(t, Tool::Scissors { .. })),
        biliary: scenario.biliary.is_some(),
        attachments: &scenario.attachments,
        device_max_force_n: scenario.device.max_force_n.0,
    };
    for (k, task) in scenario.tasks.iter().enumerate() {
        check_task(scenario, scene, k, task, &mut problems);
    }
    super::biliary::check(scenario.biliary.as_ref(), &scene, &mut problems);
    check_rubric(scenario, &mut problems);
    if let Some(operation) = &scenario.operation {
        check_operation(scenario, operation, &mut problems);
    }
    if let Some(benchmark) = &scenario.benchmark {
        check_benchmark(benchmark, &mut problems);
    }
    if let Some((k, name, between)) = phase_out_of_order(scenario) {
        problems.push(Problem {
            field: format!("tasks[{k}].phase"),
            anchors: vec!["tasks".into(), format!("\"{name}\""), format!("\"{name}\"")],
            message: format!("the phase `{name}` again, after `{between}`"),
            hint: "a phase's tasks follow one another; give this task its own phase, or move it"
                .into(),
        });
    }
    check_laparoscope(scenario, &mut problems);
    check_instruments(scenario, &mut problems);
    check_backend(scenario, &mut problems);
    check_left_hand(scenario, &mut problems);
    if let Some(assistant) = &scenario.assistant {
        super::assistant::check(assistant, scenario.tip_radius_m(), &mut problems);
    }
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
    let device = &scenario.device;
    for (name, backend) in [
        ("backend", &device.backend),
        ("left_backend", &device.left_backend),
    ] {
        let Some(Err(message)) = backend.as_ref().map(|b| b.parse::<DeviceSpec>()) else {
            continue;
        };
        problems.push(Problem {
            field: format!("device.{name}"),
            anchors: vec!["device".into(), format!("{name}:")],
            message,
            hint: "`trainer devices` lists the devices and which this machine has".into(),
        });
    }
    if device.left_backend.is_some() && !scenario.bimanual() {
        problems.push(Problem {
            field: "device.left_backend".into(),
            anchors: vec!["device".into(), "left_backend:".into()],
            message: "a left-hand device, and no instrument in the left hand".into(),
            hint: "give the left hand its instruments with `left_hand: [Instrument(…)]`, or drop `left_backend`".into(),
        });
    }
}

/// The left hand holds at most [`MAX_INSTRUMENTS`], each with the right hand's first tip (the
/// organs' vademecums are built for one tool radius).
fn check_left_hand(scenario: &Scenario, problems: &mut Vec<Problem>) {
    let hand = &scenario.left_hand;
    if hand.len() > MAX_INSTRUMENTS {
        problems.push(Problem {
            field: "left_hand".into(),
            anchors: vec!["left_hand".into()],
            message: format!(
                "{} instruments in the left hand: a hand changes between {MAX_INSTRUMENTS} at most",
                hand.len()
            ),
            hint: "keep the instruments the exercise needs".into(),
        });
    }
    let tip_m = scenario.tip_radius_m();
    for (k, instrument) in hand.iter().enumerate() {
        let other_m = instrument.tool.tip_radius_m();
        if (other_m - tip_m).abs() > 1e-9 {
            let mut anchors = vec!["left_hand".to_owned()];
            anchors.extend(std::iter::repeat_n("Instrument(".to_owned(), k + 1));
            anchors.push("tip_radius_mm".into());
            problems.push(Problem {
                field: format!("left_hand[{k}].tool.tip_radius_mm"),
                anchors,
                message: format!(
                    "its tip is {} mm, the right hand's {} mm: the organs are built for one tip",
                    other_m * 1e3,
                    tip_m * 1e3
                ),
                hint: "give every instrument the right hand's first tip_radius_mm".into(),
            });
        }
    }
}

/// The `k`th task: its organ in the scene (every type that works on one), then what its type
/// checks of its own fields.
fn check_task(
    scenario: &Scenario,
    scene: SceneFacts<'_>,
    k: usize,
    task: &Task,
    problems: &mut Vec<Problem>,
) {
    if let Some(organ) = task.organ() {
        problems.extend(not_in_scene(
            scenario,
            organ,
            format!("tasks[{k}].organ"),
            "tasks",
        ));
    }
    let mut check = TaskCheck::new(scene, &task.shared, k, task.name());
    if task.hand() == Hand::Left && !scenario.bimanual() {
        check.problem(
            "hand",
            "a task for the left hand, and no instrument in the left hand",
            "give the left hand its instruments with `left_hand: [Instrument(…)]`, or drop `hand`",
        );
    }
    if let Some(countertraction) = &task.shared.countertraction {
        check_countertraction(scenario, countertraction, &mut check);
    }
    check_task_instruments(scenario, task, &mut check);
    task.check(&mut check);
    problems.extend(check.problems);
}

/// The instruments a task is done with are kinds its hand holds.
fn check_task_instruments(scenario: &Scenario, task: &Task, check: &mut TaskCheck<'_>) {
    let hands = scenario.hands();
    let hand = match task.hand() {
        Hand::Right => hands.first(),
        Hand::Left => hands.get(1),
    };
    let kinds: Vec<&str> = hand.map_or(Vec::new(), |h| h.iter().map(|(t, _)| t.kind()).collect());
    for (j, name) in task.shared.instruments.iter().enumerate() {
        if kinds.contains(&name.as_str()) {
            continue;
        }
        let quoted = format!("\"{name}\"");
        check.problem_at(
            &format!("instruments[{j}]"),
            &["tasks", "instruments", &quoted],
            format!(
                "`{name}` is not an instrument of the task's hand, which holds: {}",
                kinds.join(", ")
            ),
            "name the kinds of the hand's instruments: probe, grasper, scalpel, hook, clip applier, scissors",
        );
    }
}

/// A task's counter-traction: in a bimanual exercise, on one of its organs, with a band the
/// device can send.
fn check_countertraction(
    scenario: &Scenario,
    countertraction: &Countertraction,
    check: &mut TaskCheck<'_>,
) {
    let field = "countertraction";
    if !scenario.bimanual() {
        check.problem(
            field,
            "counter-traction by the other hand, and no instrument in the left hand",
            "give the left hand its instruments with `left_hand: [Instrument(…)]`, or drop `countertraction`",
        );
    }
    let organ = &countertraction.organ;
    if !scenario.organs.iter().any(|o| &o.name == organ) {
        check.problem_at(
            "countertraction.organ",
            &["tasks", field, organ],
            format!("`{organ}` is not among the scenario's organs"),
            "name one of `organs`",
        );
    }
    let min = BandEnd {
        field: "countertraction.min_force_n",
        anchors: &["tasks", field, "min_force_n"],
        value_n: countertraction.min_force_n.0,
    };
    let max = BandEnd {
        field: "countertraction.max_force_n",
        anchors: &["tasks", field, "max_force_n"],
        value_n: countertraction.max_force_n.0,
    };
    check.force_band(min, max);
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
    let regions_hint = "name the fixed nodes `clamped` and the surface the tool may touch `accessible` (Gmsh physical groups, VTK point data), or pick them: clamp: [Box(…)], accessible: [Facing(…)]; `pgd mesh FILE` lists a mesh's regions";
    match crate::mesh::io::load(mesh, &organ.import()) {
        Err(e @ crate::mesh::io::ImportError::Selection { .. }) => Some(problem(
            e.to_string(),
            "selectors are in millimetres in the mesh's frame; `pgd mesh FILE --clamp … --accessible … --preview regions.png` shows what they pick",
        )),
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

/// An attachment binds two different organs of the scene, by a tissue whose fracture energy
/// reaches its peak traction.
fn check_attachment(
    scenario: &Scenario,
    k: usize,
    attachment: &AttachmentEntry,
    problems: &mut Vec<Problem>,
) {
    let field = |name: &str| format!("attachments[{k}].{name}");
    // The k-th `Attachment(` after `attachments:`, then the named field in it.
    let anchors = |name: &str| {
        let mut anchors = vec!["attachments".to_owned()];
        anchors.extend((0..=k).map(|_| "Attachment".to_owned()));
        anchors.push(name.to_owned());
        anchors
    };
    problems.extend(not_in_scene(
        scenario,
        &attachment.organ,
        field("organ"),
        "attachments",
    ));
    problems.extend(not_in_scene(
        scenario,
        &attachment.to,
        field("to"),
        "attachments",
    ));
    if attachment.organ == attachment.to {
        problems.push(Problem {
            field: field("to"),
            anchors: anchors("to"),
            message: format!("`{}` is attached to itself", attachment.organ),
            hint: "attach it to the organ it lies on".into(),
        });
    }
    let (freed, base) = (
        scenario.organ(&attachment.organ),
        scenario.organ(&attachment.to),
    );
    if let Some((freed, base)) = freed.zip(base).filter(|(f, b)| f.name != b.name)
        && let Some(Err(e)) = facing(freed, base, attachment.gap_m())
    {
        problems.push(Problem {
            field: field("to"),
            anchors: anchors("to"),
            message: format!("the {} and the {}: {e}", attachment.organ, attachment.to),
            hint: "attach organs that lie against each other, or widen gap_mm (up to 10)".into(),
        });
    }
    if let Err(e) = attachment.law() {
        problems.push(Problem {
            field: field("fracture_energy_j_per_m2"),
            anchors: anchors("fracture_energy_j_per_m2"),
            message: e.to_string(),
            hint: "the law must reach its peak before it fails: 2 G / T above T / K".into(),
        });
    }
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

/// The operation rubric: steps to score, points that are points, and events the scenario's
/// tasks can show.
fn check_operation(scenario: &Scenario, operation: &OperationRubric, problems: &mut Vec<Problem>) {
    if operation.steps.is_empty() {
        problems.push(Problem {
            field: "operation.steps".into(),
            anchors: vec!["operation".into(), "steps".into()],
            message: "the operation has no steps to score".into(),
            hint: "add `Step(name: \"…\", points: 5, done: Finished(1))` (docs/scenarios.md)"
                .into(),
        });
    }
    let steps = (operation.steps.iter().enumerate())
        .map(|(k, s)| ("steps", k, "Step", &s.name, s.points, s.done));
    let errors = (operation.errors.iter().enumerate())
        .map(|(k, e)| ("errors", k, "Error", &e.name, e.points, e.made));
    for (list, k, variant, name, points, event) in steps.chain(errors) {
        let field = format!("operation.{list}[{k}]");
        let anchors = || vec!["operation".into(), list.into(), format!("\"{name}\"")];
        if !(points.is_finite() && points > 0.0) {
            problems.push(Problem {
                field: format!("{field}.points"),
                anchors: [anchors(), vec!["points".into()]].concat(),
                message: format!("{points} points"),
                hint: format!("a {variant}'s points are more than 0"),
            });
        }
        if let Some(problem) = event_problem(scenario, event) {
            problems.push(Problem {
                field,
                anchors: anchors(),
                message: problem.0,
                hint: problem.1,
            });
        }
    }
}

/// A benchmark's values, each from 0 to the most it may be (a score 100, a share 1).
fn check_benchmark(benchmark: &Benchmark, problems: &mut Vec<Problem>) {
    for limit in benchmark.limits() {
        let Some(value) = limit.benchmark.filter(|v| !(0.0..=limit.most).contains(v)) else {
            continue;
        };
        let hint = match limit.most {
            f64::MAX => "a value of 0 or more".to_owned(),
            most => format!("a value from 0 to {most}"),
        };
        problems.push(Problem {
            field: format!("benchmark.{}", limit.field),
            anchors: vec!["benchmark".into(), limit.field.into()],
            message: format!("{value} is out of range"),
            hint,
        });
    }
}

/// What is wrong with `event` in `scenario`, and a hint.
fn event_problem(scenario: &Scenario, event: Event) -> Option<(String, String)> {
    let tasks = scenario.tasks.len();
    if let Event::Finished(n) = event {
        return (n == 0 || n > tasks).then(|| {
            (
                format!("`Finished({n})`: there is no task {n}; the scenario has {tasks}"),
                format!("tasks are numbered from 1 to {tasks}, in the order written"),
            )
        });
    }
    let amount_ok = match event {
        Event::Released(share) => (0.0..=1.0).contains(&share),
        Event::BloodLost(ml) => ml.is_finite() && ml >= 0.0,
        _ => true,
    };
    if !amount_ok {
        return Some((
            format!("{event:?}: not an amount"),
            "`Released` takes a share from 0 to 1, `BloodLost` millilitres, 0 or more".into(),
        ));
    }
    let needs = event.needs()?;
    (!scenario.tasks.iter().any(|t| t.name() == needs)).then(|| {
        (
            format!("{event:?} is read from a {needs} task, and the scenario has none"),
            format!("add a {needs} task, or score another event (docs/scenarios.md)"),
        )
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
