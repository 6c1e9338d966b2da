//! Scenarios: every shipped file validates; each has a competent and a careless scripted run
//! (`scenarios/runs/<name>.competent.csv`, `.careless.csv`, written for the coarse organs: the
//! abdominal ones with their 12 mm tool, the cornea with its 0.5 mm knife) — the competent one passes, the careless one fails, and the score orders
//! them; broken files each give their expected error at the right line and field; and the
//! `trainer` binary validates, runs and reports.

mod allocations;
mod bed;
#[path = "../../crates/pgd-surgery-core/tests/support/cache.rs"]
mod cache;
mod clip_and_cut;
#[path = "../../crates/pgd-surgery-core/tests/support/counting.rs"]
mod counting;
mod curriculum;
mod cutting;
#[path = "../../crates/pgd-surgery-core/tests/support/fuzz.rs"]
mod fuzz;
mod fuzz_files;
mod glyphs;
mod history;
mod motion;
mod operation;
mod postgres_server;
mod script;
mod shared_history;
mod soak;
mod stiffening;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use pgd_surgery::app::attempt::{Outcome, run_simulated, scenario_scene, scenario_vademecums};
use pgd_surgery::app::scene::{Detail, default_scene};
use pgd_surgery::cutting::Front;
use pgd_surgery::cutting::keratotomy::Cornea;
use pgd_surgery::devices::{HapticDevice, Scripted, TICK_S, Trajectory};
use pgd_surgery::fem::Law;
use pgd_surgery::mesh::io::write_vtu;
use pgd_surgery::mesh::organs::{Organ, OrganSettings, generate};
use pgd_surgery::mesh::{Regions, TetMesh};
use pgd_surgery::pgd::BuildSettings;
use pgd_surgery::report::write_report;
use pgd_surgery::scenario::tasks::{
    Incision, IncisionResult, PalpationResult, RadialKeratotomyResult, RetractionResult,
};
use pgd_surgery::scenario::{Scenario, ScenarioError, Scorecard, TaskMetrics, load, parse};
use pgd_surgery::store::{OnStale, VademecumSpec, ensure_vademecum};

const TRAINER: &str = env!("CARGO_BIN_EXE_trainer");

/// Counts the haptic thread's allocations (`allocations.rs`) and a reader's (`fuzz.rs`); the
/// system allocator otherwise.
#[global_allocator]
static ALLOCATOR: counting::Counting = counting::Counting;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The coarse vademecums of the four organs, and of the organs with nodules the shipped
/// scenarios ask for, built once for all tests here.
fn vademecums() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = cache::vademecum_cache().to_owned();
        default_scene(&dir, Detail::Coarse, OnStale::Rebuild).unwrap();
        for name in SHIPPED {
            let scenario = shipped(name);
            scenario_scene(&scenario, &dir, Detail::Coarse, OnStale::Rebuild).unwrap();
        }
        dir
    })
}

/// The shipped scenario `scenarios/<name>.scenario.ron`.
fn shipped(name: &str) -> Scenario {
    load(&root().join(format!("scenarios/{name}.scenario.ron"))).unwrap()
}

/// Runs a shipped scenario on the coarse organs with one of its scripts.
fn run(name: &str, script: &str) -> Outcome {
    let scenario = shipped(name);
    run_scenario(scenario, name, script)
}

/// [`run`] with the organs' tissue plain: no nodules.
fn run_without_nodules(name: &str, script: &str) -> Outcome {
    let mut scenario = shipped(name);
    scenario.nodules.clear();
    run_scenario(scenario, name, script)
}

fn run_scenario(scenario: Scenario, name: &str, script: &str) -> Outcome {
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let path = root().join(format!("scenarios/runs/{name}.{script}.csv"));
    let hands = Trajectory::load_hands(&path).unwrap();
    let ticks = ((hands[0].duration_s() + 0.1) / TICK_S).ceil() as u64;
    let devices = (hands.into_iter())
        .map(|hand| Box::new(Scripted::new("test", hand)) as Box<dyn HapticDevice>)
        .collect();
    run_simulated(scenario, &scene, devices, ticks).unwrap()
}

const SHIPPED: [&str; 17] = [
    "liver-steady-press",
    "pancreas-palpation",
    "gallbladder-gentle-press",
    "pancreas-tour",
    "duodenum-navigation",
    "abdomen-tour",
    "gallbladder-retraction",
    "gallbladder-grasp-retract",
    "liver-capsule-incision",
    "liver-laparoscopic-press",
    "gallbladder-liver-two-ports",
    "cornea-radial-keratotomy",
    "bimanual-traction-countertraction",
    "bimanual-liver-lift",
    "gallbladder-liver-bed-dissection",
    "lap-chole-clip-and-cut",
    "lap-chole-full",
];

#[test]
fn every_shipped_scenario_validates() {
    let mut found = 0;
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.to_string_lossy().ends_with(".scenario.ron") {
            load(&path).unwrap_or_else(|e| panic!("{e}"));
            found += 1;
        }
    }
    assert!(found >= SHIPPED.len(), "{found} scenarios");
}

/// The bimanual runs are scored on both hands. Competent: the left hand keeps its hold within
/// the band through the right hand's whole task, never letting go, and holds still while the
/// right hand works (under 1 mm of drift), both hands on tissue together at least as long as
/// the right hand's hold (2 s and 3 s).
/// Careless: the left hand lets go during the right hand's task (one error, saying which
/// hand and organ), the hold out of its band most of the time, and the right hand presses
/// over its limit.
#[test]
fn bimanual_runs_are_scored_on_both_hands() {
    for (name, organ) in [
        ("bimanual-traction-countertraction", "gallbladder"),
        ("bimanual-liver-lift", "liver"),
    ] {
        let competent = &run(name, "competent").card.tasks[1].metrics;
        let hold = competent.countertraction.as_ref().unwrap();
        assert!(competent.completed, "{name}: {competent:?}");
        assert!(
            hold.in_band_share() > 0.95 && hold.let_go == 0,
            "{name}: {hold:?}"
        );
        let hands = competent.hands.as_ref().unwrap();
        assert!(hands.left.path_length_mm < 1.0, "{name}: {hands:?}");
        assert!(hands.right.path_length_mm > 10.0, "{name}: {hands:?}");
        assert!(hands.both_working_s > 2.0, "{name}: {hands:?}");
        let careless = &run(name, "careless").card.tasks[1].metrics;
        let hold = careless.countertraction.as_ref().unwrap();
        assert_eq!(hold.let_go, 1, "{name}: {hold:?}");
        assert!(hold.in_band_share() < 0.5, "{name}: {hold:?}");
        let let_go = format!("the left hand let go of the {organ}");
        let errors = &careless.errors;
        assert_eq!(
            errors.iter().filter(|e| e.contains(&let_go)).count(),
            1,
            "{errors:?}"
        );
        assert!(careless.time_over_limit_s > 1.0, "{name}: {careless:?}");
    }
}

/// The careless liver press is scored on what it did: pressed too hard, more than once, and
/// never held the band; the competent one held it and finished early.
#[test]
fn metrics_say_what_went_wrong() {
    let competent = &run("liver-steady-press", "competent").card.tasks[0].metrics;
    assert!(competent.completed);
    assert!(competent.time_s < 5.0, "{}", competent.time_s);
    assert!(competent.errors.is_empty(), "{:?}", competent.errors);
    assert!((0.15..=0.35).contains(&competent.mean_force_n));
    // The press is one movement in and a hold: a few centimetres of path, mostly idle.
    let motion = &competent.motion;
    assert!(
        motion.path_length_mm > 5.0 && motion.movements >= 1,
        "{motion:?}"
    );
    assert!(motion.idle_s > 0.5 * competent.time_s, "{motion:?}");
    let careless = &run("liver-steady-press", "careless").card.tasks[0].metrics;
    assert!(!careless.completed);
    assert!(careless.peak_force_n > 0.35);
    assert!(careless.time_over_limit_s > 1.0);
    assert!(careless.errors.len() >= 2, "{:?}", careless.errors);
    let vessels = &run("pancreas-tour", "careless").card.tasks[0].metrics;
    assert!(
        vessels.errors.iter().any(|e| e.contains("splenic vessels")),
        "{:?}",
        vessels.errors
    );
}

#[test]
fn the_report_is_written_as_json_text_and_plot() {
    let outcome = run("abdomen-tour", "competent");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenario-report");
    let files = write_report(&dir, "tour", &outcome.card, &outcome.force_trace).unwrap();
    let (json, text, png) = (files.json, files.summary, files.plot);
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert_eq!(value["passed"], true);
    assert_eq!(value["tasks"].as_array().unwrap().len(), 2);
    let summary = std::fs::read_to_string(text).unwrap();
    assert!(
        summary.contains("PASSED") && summary.contains("safe navigation"),
        "{summary}"
    );
    assert_eq!(&std::fs::read(png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
}

/// Radial keratotomy: the competent run's four incisions are evenly spaced outside the
/// optical zone, as deep as asked within a tenth, and the correction the score weighs is the
/// reference solver's for those incisions (solved again here), within the scenario's
/// tolerance of its target; the careless run cuts through the cornea, which ends and fails
/// the attempt, and the debrief says so. Both reports draw the incisions.
#[test]
fn a_keratotomy_is_scored_on_its_incisions_and_a_perforation_fails_it() {
    let competent = run("cornea-radial-keratotomy", "competent");
    let rk = (competent.card.tasks[0]
        .metrics
        .result::<RadialKeratotomyResult>())
    .unwrap()
    .keratotomy
    .clone();
    assert_eq!(rk.incisions.len(), 4, "{rk:?}");
    assert!(rk.spacing_error_deg < 2.0, "{rk:?}");
    assert_eq!(rk.zone_intrusion_mm, 0.0);
    assert!((rk.mean_depth_fraction - rk.target_depth_fraction).abs() < 0.1);
    assert!(!rk.perforated);
    let predicted = rk.predicted_correction_d.expect("a correction");
    let faces = rk.faces().unwrap();
    let reference = Cornea::reference().unwrap();
    let solved = -reference.power_change_d(&faces, Front::Inward).unwrap();
    assert!((predicted - solved).abs() < 1e-9, "{predicted} vs {solved}");
    assert!(
        (predicted - rk.target_correction_d).abs() <= rk.correction_tolerance_d,
        "{predicted} D"
    );
    let said = |card: &Scorecard, words: &[&str]| {
        card.feedback
            .iter()
            .any(|line| words.iter().all(|w| line.contains(w)))
    };
    assert!(said(&competent.card, &["predicted correction"]));

    let careless = run("cornea-radial-keratotomy", "careless");
    let m = &careless.card.tasks[0].metrics;
    assert!(
        m.result::<RadialKeratotomyResult>()
            .unwrap()
            .keratotomy
            .perforated
    );
    assert!(m.complication.is_some() && !m.completed);
    assert!(!careless.card.passed);
    assert!(said(&careless.card, &["perforation", "the attempt fails"]));

    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenario-report");
    for (stem, outcome) in [("rk-competent", &competent), ("rk-careless", &careless)] {
        let png = write_report(&dir, stem, &outcome.card, &outcome.force_trace)
            .unwrap()
            .plot;
        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
        assert_eq!(decoder.read_info().unwrap().info().height, 900, "{stem}");
    }
}

/// An incision's report draws the cuts over the marked line under the force plot: the line's
/// ends are the scenario's, and the plot has the panel (it is taller than a plot without).
#[test]
fn the_incision_report_draws_the_cuts_over_the_line() {
    let outcome = run("liver-capsule-incision", "competent");
    let scenario = load(&root().join("scenarios/liver-capsule-incision.scenario.ron")).unwrap();
    let Some(Incision { from_mm, to_mm, .. }) = scenario.tasks[0].get::<Incision>() else {
        panic!("not an incision");
    };
    let metrics = &outcome.card.tasks[0].metrics;
    let incision = &metrics.result::<IncisionResult>().unwrap().incision;
    assert_eq!(incision.from_mm, [from_mm.0, from_mm.1, from_mm.2]);
    assert_eq!(incision.to_mm, [to_mm.0, to_mm.1, to_mm.2]);
    assert!(!outcome.card.cuts.is_empty());
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenario-report");
    let height = |stem: &str, outcome: &Outcome| {
        let png = write_report(&dir, stem, &outcome.card, &outcome.force_trace)
            .unwrap()
            .plot;
        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
        decoder.read_info().unwrap().info().height
    };
    let plain = run("liver-steady-press", "competent");
    assert!(height("incision", &outcome) > height("press", &plain));
}

/// Each broken file gives its error at the line and field it is about, with a hint.
#[test]
fn broken_scenarios_are_refused_with_file_line_field_and_hint() {
    let cases = [
        (
            "unknown-field",
            8,
            "rubrik",
            "Unexpected field named `rubrik`",
        ),
        (
            "metres-for-millimetres",
            5,
            "tip_radius_mm",
            "in millimetres",
        ),
        ("missing-tasks", 5, "", "missing field named `tasks`"),
        (
            "attachment-gap-out-of-range",
            6,
            "attachments[0].gap_mm",
            "not a gap that connective tissue bridges",
        ),
        (
            "attachment-fracture-energy-out-of-range",
            9,
            "attachments[0].fracture_energy_j_per_m2",
            "not the fracture energy of connective tissue",
        ),
        (
            "attachment-brittle",
            12,
            "attachments[1].fracture_energy_j_per_m2",
            "fails before the peak traction",
        ),
        (
            "attachment-not-facing",
            6,
            "attachments[0].to",
            "do not face each other within 3.0 mm",
        ),
        (
            "hook-power-out-of-range",
            5,
            "tool.Hook.power_w",
            "not a power the hook delivers",
        ),
        (
            "attachment-organ-not-in-scene",
            6,
            "attachments[0].organ",
            "`pancreas` is not in this scenario",
        ),
        ("unknown-organ", 4, "organs[1]", "no organ `spleen`"),
        (
            "organ-not-in-scene",
            6,
            "tasks[0].organ",
            "`pancreas` is not in this scenario",
        ),
        (
            "band-upside-down",
            8,
            "tasks[0].min_force_n",
            "the band is empty",
        ),
        ("syntax", 6, "tasks[0]", "Expected comma"),
        (
            "unknown-task",
            6,
            "tasks[0]",
            "Unexpected variant named `Palpate`",
        ),
        (
            "too-much-force",
            8,
            "max_force_n",
            "forces here are in newtons",
        ),
        ("bad-pass-mark", 8, "rubric.pass_mark", "not a score"),
        (
            "palpation-without-nodule",
            6,
            "tasks[0].organ",
            "the pancreas has no nodule to find",
        ),
        (
            "softer-nodule",
            7,
            "nodules[0].stiffness_ratio",
            "must be more than 1",
        ),
        (
            "retraction-without-direction",
            10,
            "tasks[0].towards",
            "has no length",
        ),
        (
            "workspace-scale-zero",
            5,
            "workspace_scale",
            "not a workspace scale",
        ),
        ("unknown-device", 5, "device.backend", "phantom-omni"),
        (
            "organ-mesh-missing",
            6,
            "organs[0].mesh",
            "no-such-kidney.vtu",
        ),
        (
            "contact-master-not-in-scene",
            6,
            "contact.master",
            "`liver` is not in this scenario",
        ),
        (
            "incision-without-scalpel",
            7,
            "tasks[0].organ",
            "needs a scalpel",
        ),
        (
            "incision-uncuttable-organ",
            8,
            "tasks[0].organ",
            "toughness under a blade is not known",
        ),
        (
            "incision-off-the-organ",
            10,
            "tasks[0].to_mm",
            "40 mm off the liver's surface",
        ),
        (
            "toughness-out-of-range",
            4,
            "toughness_j_per_m2",
            "not a tissue's toughness",
        ),
        (
            "stiffening-without-exponential",
            4,
            "organs[0].stiffening",
            "the neo-hookean law has no stiffening",
        ),
        (
            "stiffening-out-of-range",
            4,
            "stiffening",
            "not a stiffening exponent",
        ),
        (
            "pointshell-cut-too-fine",
            6,
            "contact.pointshell",
            "cut 20 times along each edge",
        ),
        (
            "pointshell-too-sparse",
            6,
            "contact.pointshell",
            "kept 80 mm apart",
        ),
        (
            "organ-unknown-field",
            7,
            "organs[0].stiffness_pa",
            "stiffness_pa",
        ),
        (
            "unknown-law",
            7,
            "organs[0].law",
            "Unexpected variant named `Hookean`",
        ),
        (
            "grasp-without-grasper",
            8,
            "tasks[0].organ",
            "needs a grasper",
        ),
        (
            "instruments-different-tips",
            8,
            "instruments[1].tool.tip_radius_mm",
            "the organs are built for one tip",
        ),
        (
            "instruments-and-tool",
            5,
            "tool",
            "`tool` and `instruments` both say what the trainee holds",
        ),
        (
            "laparoscope-port-on-the-focus",
            7,
            "laparoscope.look_at_mm",
            "the port is too near it",
        ),
        (
            "laparoscope-angle-out-of-range",
            5,
            "angle_deg",
            "not a laparoscope's angle",
        ),
        (
            "task-instrument-not-in-hand",
            8,
            "tasks[0].instruments[1]",
            "`scissors` is not an instrument of the task's hand",
        ),
        (
            "assistant-out-of-reach",
            10,
            "assistant.script[1]",
            "out of reach of a 350 mm instrument",
        ),
        (
            "assistant-with-a-hook",
            6,
            "assistant.tool",
            "the assistant holds a grasper",
        ),
        (
            "laparoscope-script-backwards",
            11,
            "laparoscope.script[2]",
            "comes before the one at 5 s",
        ),
        (
            "view-without-laparoscope",
            8,
            "rubric.view",
            "no laparoscope",
        ),
        (
            "keratotomy-no-incisions",
            10,
            "RadialKeratotomy.incisions",
            "0 incisions: from 1 to 16",
        ),
        (
            "keratotomy-zone-too-wide",
            11,
            "tasks[0].optical_zone_mm",
            "leaves no room for incisions",
        ),
        (
            "keratotomy-through-and-through",
            12,
            "RadialKeratotomy.depth_fraction",
            "not a depth fraction",
        ),
        (
            "countertraction-one-hand",
            8,
            "tasks[0].countertraction",
            "no instrument in the left hand",
        ),
    ];
    for (name, line, field, message) in cases {
        let file = root().join(format!("tests/scenarios/broken/{name}.scenario.ron"));
        assert_refused(&file, &load(&file).unwrap_err(), (line, field, message));
    }
}

/// `error`, refusing `file`, is at `line`, names `field` and says `message`, with a hint,
/// and reads `file:line:…`.
fn assert_refused(file: &Path, error: &ScenarioError, (line, field, message): (usize, &str, &str)) {
    let shown = error.to_string();
    assert_eq!(error.line, line, "{shown}");
    assert!(
        error.field.contains(field),
        "{}: field `{}`",
        file.display(),
        error.field
    );
    assert!(error.message.contains(message), "{shown}");
    assert!(!error.hint.is_empty(), "{shown}");
    assert!(
        shown.starts_with(&format!("{}:{line}:", file.display())),
        "{shown}"
    );
}

#[test]
fn a_missing_file_is_named() {
    let error = load(Path::new("scenarios/nowhere.scenario.ron")).unwrap_err();
    assert!(
        error.to_string().contains("nowhere.scenario.ron"),
        "{error}"
    );
    assert!(parse(Path::new("inline"), "").is_err());
}

/// `trainer run` of the steady press, headless on the coarse organs with the scenario's
/// `script` (competent or careless), its report and history in `dir`, with `extra` options;
/// the scorecard as JSON on standard output.
fn run_steady_press(script: &str, dir: &Path, extra: &[&str]) -> std::process::Output {
    let trajectory = root().join(format!("scenarios/runs/liver-steady-press.{script}.csv"));
    Command::new(TRAINER)
        .args([
            "run",
            "scenarios/liver-steady-press.scenario.ron",
            "--headless",
            "--coarse",
            "--no-rebuild",
            "--json",
        ])
        .args(extra)
        .arg("--device")
        .arg(format!("scripted:{}", trajectory.display()))
        .arg("--vademecums")
        .arg(vademecums())
        .arg("--report-dir")
        .arg(dir)
        .args(history_unless_named(dir, extra))
        .current_dir(root())
        .output()
        .unwrap()
}

/// `--history DIR/history.sqlite`, unless `extra` names a history or a configuration.
fn history_unless_named(dir: &Path, extra: &[&str]) -> Vec<String> {
    match extra.iter().any(|a| *a == "--history" || *a == "--config") {
        true => Vec::new(),
        false => vec![
            "--history".into(),
            dir.join("history.sqlite").display().to_string(),
        ],
    }
}

#[test]
fn the_trainer_validates_runs_and_reports() {
    let broken = root().join("tests/scenarios/broken/unknown-organ.scenario.ron");
    let output = Command::new(TRAINER)
        .arg("validate")
        .arg(&broken)
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("unknown-organ.scenario.ron:4:") && stderr.contains("spleen"),
        "{stderr}"
    );

    let report_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scenario-cli-report");
    let output = run_steady_press("careless", &report_dir, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let card: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(card["passed"], false);
    assert!(
        report_dir.join("liver-steady-press.png").exists(),
        "{stderr}"
    );
}

/// Palpation is scored on where the mark was: the competent mark lies over the nodule, the
/// careless one on plain tissue after a press over the limit. The nodule is in the tissue the
/// trainee feels: the same press over it pushes back harder than on a pancreas without it.
#[test]
fn palpation_scores_the_mark_and_the_nodule_is_felt() {
    let competent = run("pancreas-palpation", "competent");
    let metrics = &competent.card.tasks[0].metrics;
    let mark_mm = |m: &TaskMetrics| m.result::<PalpationResult>().unwrap().localization_error_mm;
    let error_mm = mark_mm(metrics).expect("marked");
    assert!(metrics.completed && error_mm < 10.0, "{metrics:#?}");
    let careless = &run("pancreas-palpation", "careless").card.tasks[0].metrics;
    assert!(!careless.completed, "{careless:#?}");
    assert!(mark_mm(careless).expect("marked") > 20.0);
    assert!(careless.peak_force_n > 0.6 && !careless.errors.is_empty());

    let plain = run_without_nodules("pancreas-palpation", "competent");
    let pressing_over_nodule = |trace: &[(f64, f64)]| {
        trace
            .iter()
            .filter(|(t, _)| (7.6..8.5).contains(t))
            .map(|(_, f)| *f)
            .fold(0.0, f64::max)
    };
    let (with, without) = (
        pressing_over_nodule(&competent.force_trace),
        pressing_over_nodule(&plain.force_trace),
    );
    assert!(
        with > 1.2 * without,
        "over the nodule {with:.3} N, plain pancreas {without:.3} N"
    );
}

/// Retraction is scored on what the region did and what the organs around carried: the
/// competent push moved the fundus past the mark and held it while the liver carried almost
/// nothing; the careless run pressed the liver itself (an error for the organs around, with
/// its time above the limit), then jabbed the fundus too far and too hard: it holds the
/// fundus, which the probe grips sideways, but 19 mm out and over the force limit, and fails.
#[test]
fn retraction_measures_the_region_and_the_organs_around() {
    let retraction = |m: &TaskMetrics| m.result::<RetractionResult>().unwrap().clone();
    let metrics = &run("gallbladder-retraction", "competent").card.tasks[0].metrics;
    let competent = retraction(metrics);
    let (target_mm, limit_n) = (competent.region.move_target_mm, 0.05);
    assert!(metrics.completed, "{metrics:#?}");
    assert!(competent.region.moved_mm.unwrap() >= target_mm);
    assert!(competent.region.longest_hold_s >= competent.region.hold_s);
    assert!(competent.surrounding_peak_n < limit_n, "{metrics:#?}");
    assert_eq!(competent.surrounding_limit_n, limit_n);
    let careless_card = run("gallbladder-retraction", "careless").card;
    assert!(!careless_card.passed, "{careless_card:#?}");
    let careless = &careless_card.tasks[0].metrics;
    let around = retraction(careless);
    assert!(around.surrounding_peak_n > limit_n && around.surrounding_over_limit_s > 1.0);
    assert!(
        careless.errors.iter().any(|e| e.contains("organs around")),
        "{:?}",
        careless.errors
    );
    assert!(careless.peak_force_n > careless.force_limit_n && careless.time_over_limit_s > 1.0);
}

/// An organ's `young_pa` builds its vademecum for that tissue: the liver given twice
/// its Young's modulus pushes back twice as hard on the same scripted press (linear
/// elasticity at a fixed indentation: force ∝ E; tolerance 0.2 %, for the f32 storage and the
/// build's convergence tolerance; 2.000 measured), with no other organ in the scene to add
/// contact.
#[test]
fn a_stiffer_tissue_pushes_back_harder_in_proportion() {
    let file = Path::new("stiff-liver.scenario.ron");
    let young_pa = 2.0 * pgd_surgery::pgd::organ::young_pa(Organ::Liver);
    let stiff = parse(
        file,
        &one_organ_press(
            &format!("Organ(name: \"liver\", young_pa: {young_pa}, law: Linear)"),
            "liver",
        ),
    )
    .unwrap();
    let plain = parse(file, &one_organ_press(LINEAR_LIVER, "liver")).unwrap();
    let (stiff_n, plain_n) = (held_force_n(stiff), held_force_n(plain));
    let ratio = stiff_n / plain_n;
    eprintln!("held {stiff_n:.4} N on the stiff liver, {plain_n:.4} N on the plain one");
    assert!(plain_n > 0.1, "{plain_n} N");
    assert!(
        (ratio - 2.0).abs() < 0.004,
        "{stiff_n} N against {plain_n} N: ratio {ratio}"
    );
}

/// The liver with linear tissue, whose vademecum the shipped scenarios' tests build anyway:
/// the tests of what the law does not change run on it.
const LINEAR_LIVER: &str = r#"Organ(name: "liver", law: Linear)"#;

/// A scenario of one organ (`entry` in `organs`) pressed by the liver's steady-press task.
fn one_organ_press(entry: &str, organ: &str) -> String {
    format!(
        r#"Scenario(title: "Press", briefing: "Press.", organs: [{entry}],
            tasks: [ForceControl(organ: "{organ}", min_force_n: 0.15, max_force_n: 0.35,
                                 hold_s: 30.0, time_limit_s: 40.0)])"#
    )
}

/// The mean force (N) the competent steady-press script holds from 2 s to 4 s on `scenario`'s
/// scene (its vademecums built first if missing).
fn held_force_n(scenario: Scenario) -> f64 {
    scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Rebuild).unwrap();
    let trace = run_scenario(scenario, "liver-steady-press", "competent").force_trace;
    let held: Vec<f64> = trace
        .iter()
        .filter(|(t, _)| (2.0..4.0).contains(t))
        .map(|(_, f)| *f)
        .collect();
    held.iter().sum::<f64>() / held.len() as f64
}

/// An organ read from a mesh file runs as the generated organ written to that file: the
/// coarse liver saved as .vtu (with its regions), named relative to the scenario's folder, is
/// built from the file with the liver's tissue (a mesh file's default; both linear here) and
/// pushes back on the same press as the generated liver does. The file keeps coordinates to
/// 1e-9 relative or better, so the two vademecums are built on the same mesh; 1e-6 relative
/// allows for the rounding.
#[test]
fn an_organ_from_a_mesh_file_feels_as_the_organ_it_was_written_from() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mesh-organ");
    std::fs::create_dir_all(folder.join("meshes")).unwrap();
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let liver = generate(Organ::Liver, &settings).unwrap();
    write_vtu(&folder.join("meshes/my-liver.vtu"), &liver, &[]).unwrap();
    let file = folder.join("my-liver.scenario.ron");
    let entry = r#"Organ(name: "my-liver", mesh: "meshes/my-liver.vtu", law: Linear)"#;
    std::fs::write(&file, one_organ_press(entry, "my-liver")).unwrap();
    let from_file = load(&file).unwrap();
    assert_eq!(
        from_file.organs[0].mesh.as_deref(),
        Some(folder.join("meshes/my-liver.vtu").as_path())
    );
    let generated = parse(&file, &one_organ_press(LINEAR_LIVER, "liver")).unwrap();
    let (file_n, generated_n) = (held_force_n(from_file), held_force_n(generated));
    eprintln!(
        "held {file_n:.6} N on the liver from the file, {generated_n:.6} N on the generated one"
    );
    assert!(generated_n > 0.1, "{generated_n} N");
    assert!(
        ((file_n - generated_n) / generated_n).abs() < 1e-6,
        "{file_n} N against {generated_n} N"
    );
}

/// `mesh`'s boundary as an ASCII STL in millimetres, each triangle facing out of its
/// tetrahedron: a surface as a segmentation tool exports it.
fn write_stl_mm(path: &Path, mesh: &TetMesh) {
    use std::collections::HashMap;
    let nodes = mesh.nodes();
    let mut faces: HashMap<[usize; 3], ([usize; 3], usize)> = HashMap::new();
    for tet in mesh.tets() {
        for skip in 0..4 {
            let face: Vec<usize> = (0..4).filter(|&c| c != skip).map(|c| tet[c]).collect();
            let mut key = [face[0], face[1], face[2]];
            key.sort_unstable();
            let entry = ([face[0], face[1], face[2]], tet[skip]);
            if faces.remove(&key).is_none() {
                faces.insert(key, entry);
            }
        }
    }
    let mut stl = String::from("solid liver\n");
    for ([a, b, c], opposite) in faces.into_values() {
        let (pa, pb, pc) = (nodes[a], nodes[b], nodes[c]);
        let normal = (pb - pa).cross(&(pc - pa));
        let outward = normal.dot(&(pa - nodes[opposite])) > 0.0;
        let corners = if outward { [pa, pb, pc] } else { [pa, pc, pb] };
        stl.push_str("facet normal 0 0 0\nouter loop\n");
        for p in corners {
            stl.push_str(&format!(
                "vertex {} {} {}\n",
                p.x * 1e3,
                p.y * 1e3,
                p.z * 1e3
            ));
        }
        stl.push_str("endloop\nendfacet\n");
    }
    stl.push_str("endsolid liver\n");
    std::fs::write(path, stl).unwrap();
}

/// From a segmentation to a rehearsal, as the README's three commands and the shipped example
/// scenario go: the coarse liver's surface written as an STL in millimetres (what a
/// segmentation exports), imported by `pgd mesh --scale 0.001 --clamp facing:0,-1,0,35` into
/// the example's mesh (as many nodes as the coarse liver has), and
/// `scenarios/examples/patient-liver.scenario.ron` run on it (its vademecum built) with the
/// steady press's competent script: the task is passed, and the press holds within 25 % of
/// what it holds on the coarse liver itself clamped by the same selector. That is the
/// remeshing tolerance: the surface is meshed anew by the tetrahedralizer, and on meshes this
/// coarse the new mesh is 23 % stiffer under the probe (measured; docs/geometry.md).
#[test]
fn the_patient_example_runs_from_a_segmentation_surface() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("patient-example");
    std::fs::create_dir_all(folder.join("meshes")).unwrap();
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let liver = generate(Organ::Liver, &settings).unwrap();
    let surface = folder.join("liver.stl");
    write_stl_mm(&surface, &liver);
    let mesh = folder.join("meshes/patient-liver.vtu");
    let _ = std::fs::remove_file(&mesh);
    let imported = Command::new(env!("CARGO_BIN_EXE_pgd"))
        .arg("mesh")
        .arg(&surface)
        .args(["--scale", "0.001", "--clamp", "facing:0,-1,0,35"])
        .args(["--nodes", &liver.nodes().len().to_string(), "--out"])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(
        imported.status.success(),
        "{}{}",
        String::from_utf8_lossy(&imported.stdout),
        String::from_utf8_lossy(&imported.stderr)
    );
    let shipped = root().join("scenarios/examples/patient-liver.scenario.ron");
    let file = folder.join("patient-liver.scenario.ron");
    std::fs::copy(&shipped, &file).unwrap();
    let scenario = load(&file).unwrap();
    scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Rebuild).unwrap();
    let outcome = run_scenario(scenario, "liver-steady-press", "competent");
    let held = |trace: &[(f64, f64)]| {
        let held: Vec<f64> = (trace.iter())
            .filter(|(t, _)| (2.0..4.0).contains(t))
            .map(|(_, f)| *f)
            .collect();
        held.iter().sum::<f64>() / held.len() as f64
    };
    let patient_n = held(&outcome.force_trace);
    write_vtu(&folder.join("meshes/coarse-liver.vtu"), &liver, &[]).unwrap();
    let same_clamp = r#"Organ(name: "coarse-liver", mesh: "meshes/coarse-liver.vtu", law: Linear,
                               clamp: [Facing(0, -1, 0, 35)])"#;
    let generated = parse(&file, &one_organ_press(same_clamp, "coarse-liver")).unwrap();
    let generated_n = held_force_n(generated);
    eprintln!(
        "held {patient_n:.4} N on the patient's liver, {generated_n:.4} N on the coarse one; \
         score {:.0}",
        outcome.card.score
    );
    assert!(outcome.card.passed, "{:#?}", outcome.card);
    assert!(
        ((patient_n - generated_n) / generated_n).abs() < 0.25,
        "{patient_n} N against {generated_n} N"
    );
}

/// A mesh file whose regions have other names (as a segmentation tool's would): the
/// scenario picks them with `clamp: [Region(…)]` and `accessible: [Region(…)]`, and the organ
/// pushes back as the generated liver whose regions they are, to 1e-6 relative. A selector
/// that picks nothing is refused where it is written, with the organ's extent.
#[test]
fn a_scenario_picks_a_mesh_files_regions_with_selectors() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mesh-selectors");
    std::fs::create_dir_all(folder.join("meshes")).unwrap();
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let liver = generate(Organ::Liver, &settings).unwrap();
    let regions = Regions {
        node_sets: [(
            "vena_cava".to_owned(),
            liver.node_set("clamped").unwrap().to_vec(),
        )]
        .into(),
        face_sets: [(
            "front".to_owned(),
            liver.face_set("accessible").unwrap().to_vec(),
        )]
        .into(),
    };
    let renamed = TetMesh::new(
        "segmented",
        liver.nodes().to_vec(),
        liver.tets().to_vec(),
        regions,
    )
    .unwrap();
    write_vtu(&folder.join("meshes/segmented.vtu"), &renamed, &[]).unwrap();
    let file = folder.join("segmented.scenario.ron");
    let entry = |clamp: &str| {
        format!(
            r#"Organ(name: "segmented", mesh: "meshes/segmented.vtu", law: Linear,
                clamp: [{clamp}], accessible: [Region("front")])"#
        )
    };
    std::fs::write(
        &file,
        one_organ_press(&entry(r#"Region("vena_cava")"#), "segmented"),
    )
    .unwrap();
    let picked = load(&file).unwrap();
    let generated = parse(&file, &one_organ_press(LINEAR_LIVER, "liver")).unwrap();
    let (picked_n, generated_n) = (held_force_n(picked), held_force_n(generated));
    eprintln!("held {picked_n:.6} N on the picked regions, {generated_n:.6} N on the liver's");
    assert!(generated_n > 0.1, "{generated_n} N");
    assert!(
        ((picked_n - generated_n) / generated_n).abs() < 1e-6,
        "{picked_n} N"
    );
    let nowhere = one_organ_press(&entry("Box(500, 500, 500, 600, 600, 600)"), "segmented");
    std::fs::write(&file, &nowhere).unwrap();
    let error = load(&file).unwrap_err();
    assert!(
        error.message.contains("picks nothing") && error.message.contains("spans x"),
        "{error}"
    );
    assert_eq!(error.field, "organs[0].mesh", "{error}");
}

/// A scenario's contact master carries the distance field the other organs are tested
/// against: with the liver chosen (on a coarse 8 mm lattice, quick to build), the scene's one contact pair tests the
/// gallbladder's nodes against the liver, where by default it is the other way round; a
/// dense pointshell tests more than twice as many of the liver's points, a sparse one fewer.
#[test]
fn the_scenario_chooses_the_contact_master() {
    let text = |contact: &str| {
        format!(
            r#"Scenario(title: "Press", briefing: "Press.", organs: ["liver", "gallbladder"], {contact}
                tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                                     hold_s: 1.0, time_limit_s: 5.0)])"#
        )
    };
    let file = Path::new("master.scenario.ron");
    let coupling = |contact: &str| {
        let scenario = parse(file, &text(contact)).unwrap();
        let scene =
            scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Rebuild).unwrap();
        let names: Vec<String> = scene.organs.iter().map(|o| o.0.clone()).collect();
        let coupling = scene.coupling.expect("two organs that touch are coupled");
        (names, coupling)
    };
    let pairs = |contact: &str| {
        let (names, coupling) = coupling(contact);
        let pairs: Vec<(String, String)> = coupling
            .pairs
            .iter()
            .map(|p| (names[p.master].clone(), names[p.shell].clone()))
            .collect();
        pairs
    };
    let liver = || "liver".to_owned();
    let gallbladder = || "gallbladder".to_owned();
    assert_eq!(pairs(""), [(gallbladder(), liver())]);
    assert_eq!(
        pairs(r#"contact: Contact(master: "liver", lattice_mm: 8.0),"#),
        [(liver(), gallbladder())]
    );
    let points = |contact: &str| coupling(contact).1.pairs[0].pointshell().len();
    let (nodes, dense) = (points(""), points("contact: Contact(pointshell: Dense),"));
    assert!(
        dense > 2 * nodes,
        "{dense} dense points against {nodes} nodes"
    );
    let sparse = points("contact: Contact(pointshell: Sparse(15)),");
    assert!(
        sparse > 0 && sparse < nodes,
        "{sparse} points 15 mm apart against {nodes} nodes"
    );
}

/// `law` picks the tissue's law per organ: the liver's vademecum is to be built under the
/// neo-Hookean law with that law's default load steps, kept beside the linear one under the
/// law's name, and its build command says so; the gallbladder beside it stays linear as asked.
/// (What a load-stepped build gives is the `pgd` tests'; this asks nothing to be built.)
#[test]
fn the_scenario_picks_the_law_per_organ() {
    let text = r#"Scenario(title: "Press", briefing: "Press.",
        organs: [Organ(name: "liver", law: NeoHookean), Organ(name: "gallbladder", law: Linear)],
        tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                             hold_s: 1.0, time_limit_s: 5.0)])"#;
    let scenario = parse(Path::new("law.scenario.ron"), text).unwrap();
    let dir = Path::new("vademecums");
    let [liver, gallbladder] =
        <[_; 2]>::try_from(scenario_vademecums(&scenario, dir, Detail::Coarse).unwrap()).unwrap();
    assert_eq!((liver.law, gallbladder.law), (Law::NeoHookean, Law::Linear));
    let defaults = BuildSettings::for_organ_law(Some(Organ::Liver), Law::NeoHookean).load_steps_m;
    assert_eq!(liver.build.load_steps_m, defaults);
    assert_eq!(liver.file, dir.join("liver-neo-hookean.coarse.vdm"));
    assert_eq!(gallbladder.file, dir.join("gallbladder.coarse.vdm"));
    assert!(
        liver.build_command().contains(" --law neo-hookean"),
        "{}",
        liver.build_command()
    );
}

/// Where a scenario names no law, a pressed organ's tissue is exponential, and linear where a
/// scalpel cuts it (the liver: it has a toughness; the pancreas has none and is only
/// pressed), where a grasper moves it, and on the cornea and the gallbladder; a named law
/// stands. The web page's copy of a scenario is linear where it names none, and keeps a
/// named law.
#[test]
fn an_organ_without_a_law_is_exponential_where_pressed_and_linear_where_cut_or_moved() {
    use Law::{Exponential, Linear, NeoHookean};
    let scenario = |tool: &str, organs: &str| {
        let text = format!(
            r#"Scenario(title: "Law", briefing: "", organs: [{organs}], tool: {tool},
               tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                                    hold_s: 1.0, time_limit_s: 5.0)])"#
        );
        parse(Path::new("law.scenario.ron"), &text).unwrap()
    };
    let laws = |s: &Scenario| s.organs.iter().map(|o| s.law_of(o)).collect::<Vec<_>>();
    let probe = "Probe(tip_radius_mm: 6.0)";
    let two = r#""liver", "pancreas""#;
    assert_eq!(laws(&scenario(probe, two)), [Exponential, Exponential]);
    let scalpel = "Scalpel(tip_radius_mm: 6.0, edge_mm: 3.0)";
    assert_eq!(laws(&scenario(scalpel, two)), [Linear, Exponential]);
    let grasper = "Grasper(tip_radius_mm: 6.0)";
    assert_eq!(laws(&scenario(grasper, two)), [Linear, Linear]);
    let others = r#""liver", "duodenum", "cornea", "gallbladder""#;
    assert_eq!(
        laws(&scenario(probe, others)),
        [Exponential, Exponential, Linear, Linear]
    );
    let named = scenario(
        probe,
        r#"Organ(name: "liver", law: NeoHookean), "pancreas""#,
    );
    assert_eq!(laws(&named), [NeoHookean, Exponential]);
    assert_eq!(laws(&named.for_the_web()), [NeoHookean, Linear]);
}

/// `stiffening` sets the exponential law's b per organ: the liver's vademecum is to be built
/// with it, kept under a name that says so, and its build command passes it on.
#[test]
fn the_scenario_sets_the_exponential_stiffening_per_organ() {
    let text = r#"Scenario(title: "Press", briefing: "Press.",
        organs: [Organ(name: "liver", law: Exponential, stiffening: 3.5)],
        tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                             hold_s: 1.0, time_limit_s: 5.0)])"#;
    let scenario = parse(Path::new("stiffening.scenario.ron"), text).unwrap();
    let dir = Path::new("vademecums");
    let liver = &scenario_vademecums(&scenario, dir, Detail::Coarse).unwrap()[0];
    assert_eq!((liver.law, liver.stiffening), (Law::Exponential, Some(3.5)));
    assert_eq!(
        liver.file,
        dir.join("liver-exponential.coarse.stiffening-3.5.vdm")
    );
    let command = liver.build_command();
    assert!(
        command.contains(" --law exponential") && command.contains(" --stiffening 3.5"),
        "{command}"
    );
    // The vademecum the shipped scenarios press, of the default b, is not that tissue.
    let other = VademecumSpec {
        file: vademecums().join("liver-exponential.coarse.vdm"),
        ..liver.clone()
    };
    let refused = ensure_vademecum(&other, OnStale::Refuse).unwrap_err();
    assert!(refused.contains("stiffening: 3.5"), "{refused}");
}

/// A scenario may name the device it is meant for, as `--device` names it; the window opens
/// that one unless `--device` names another.
#[test]
fn a_scenario_names_its_device() {
    let text = |backend: &str| {
        format!(
            r#"Scenario(title: "Device", briefing: "", organs: ["liver"], device: Device({backend}),
               tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3, hold_s: 1.0, time_limit_s: 5.0)])"#
        )
    };
    let named = parse(
        Path::new("device.ron"),
        &text(r#"backend: "openhaptics:Left Touch""#),
    );
    assert_eq!(
        named.unwrap().device.spec(),
        Some(pgd_surgery::devices::DeviceSpec::OpenHaptics(Some(
            "Left Touch".into()
        )))
    );
    let unnamed = parse(Path::new("device.ron"), &text("max_force_n: 2.0")).unwrap();
    assert_eq!(unnamed.device.spec(), None);
}

/// A scripted laparoscope that turns away from the probe two seconds in: the competent press
/// is in view until then and out of it from the turn (about 0.1 s long) to the task's end, at
/// 3.9 s; with the camera left on the liver it never leaves the view.
#[test]
fn a_scripted_camera_looking_away_times_the_probe_out_of_view() {
    let name = "liver-laparoscopic-press";
    let file = root().join(format!("scenarios/{name}.scenario.ron"));
    let text = std::fs::read_to_string(&file).unwrap();
    let scripted = text.replace(
        "fov_deg: 70.0,",
        "fov_deg: 70.0,
        script: [
            Look(at_s: 0.0, look_at_mm: (36.0, 64.0, 0.0), distance_mm: 110.0),
            Look(at_s: 2.0, look_at_mm: (36.0, 64.0, 0.0), distance_mm: 110.0),
            Look(at_s: 2.1, look_at_mm: (-130.0, -5.0, -40.0), distance_mm: 110.0),
        ],",
    );
    assert_ne!(scripted, text);
    let away = parse(&file, &scripted).unwrap_or_else(|e| panic!("{e}"));
    let steady = run(name, "competent").card.tasks[0].metrics.clone();
    let turned = run_scenario(away, name, "competent").card.tasks[0]
        .metrics
        .clone();
    assert_eq!(steady.motion.out_of_view_s, Some(0.0));
    let out_s = turned.motion.out_of_view_s.unwrap();
    let after_turn_s = turned.time_s - 2.1;
    assert!(
        out_s > after_turn_s - 0.1 && out_s < after_turn_s + 0.1,
        "{out_s} s out of view; {after_turn_s} s after the turn"
    );
}

/// The laparoscopic press with a second probe through a port 60 mm to the left: the
/// competent script, held still for its first second while the change button is pressed
/// twice (to the second probe and back), presses as the same script held still without the
/// button. The first probe is taken up again where it was put down, so the press is the same:
/// the same peak force, path and economy, a pass, and two changes in the task's motion
/// metrics (and its debrief). Only the time out of the laparoscope's view may differ: the
/// second probe's tip, just in from its port, is out of it.
#[test]
fn two_instruments_changed_and_changed_back_press_as_one() {
    use pgd_surgery::devices::{CHANGE_BUTTON, TrajectoryRow};
    use pgd_surgery::report::summary;
    use pgd_surgery::scenario::Instrument;

    let name = "liver-laparoscopic-press";
    let mut scenario = shipped(name);
    let port = scenario.port.take().expect("a laparoscopic scenario");
    let tool = scenario.tool.take().unwrap_or_default();
    let mut left = port.clone();
    left.at_mm.0 -= 60.0;
    scenario.instruments = vec![
        Instrument {
            tool: tool.clone(),
            port,
        },
        Instrument { tool, port: left },
    ];
    let script = root().join(format!("scenarios/runs/{name}.competent.csv"));
    let held_still = |presses: &[f64]| {
        let mut trajectory = Trajectory::load(&script).unwrap();
        let start = trajectory.rows[0];
        for row in &mut trajectory.rows {
            row.time_s += 1.0;
        }
        let mut held = vec![start];
        for &at_s in presses {
            for (t, buttons) in [(at_s, CHANGE_BUTTON), (at_s + 0.1, 0)] {
                held.push(TrajectoryRow {
                    time_s: t,
                    buttons,
                    ..start
                });
            }
        }
        held.append(&mut trajectory.rows);
        Trajectory { rows: held }
    };
    let run = |trajectory: Trajectory| {
        let scene =
            scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
        let ticks = ((trajectory.duration_s() + 0.1) / TICK_S).ceil() as u64;
        let device = Box::new(Scripted::new("test", trajectory));
        run_simulated(scenario.clone(), &scene, vec![device], ticks).unwrap()
    };
    let plain = run(held_still(&[])).card;
    let changed = run(held_still(&[0.2, 0.6])).card;
    let (p, c) = (&plain.tasks[0].metrics, &changed.tasks[0].metrics);
    eprintln!("{}", summary(&changed));
    assert!(changed.passed, "{changed:#?}");
    assert_eq!(c.motion.instrument_changes, Some(2));
    assert_eq!(p.motion.instrument_changes, None);
    assert!(
        (c.peak_force_n - p.peak_force_n).abs() < 1e-9,
        "{} N vs {} N",
        c.peak_force_n,
        p.peak_force_n
    );
    let (cm, pm) = (&c.motion, &p.motion);
    assert!((cm.path_length_mm - pm.path_length_mm).abs() < 1e-6);
    assert!((cm.economy.unwrap() - pm.economy.unwrap()).abs() < 1e-6);
    assert!(summary(&changed).contains("instruments changed 2 times"));
}

/// The gallbladder off its bed. Competent: the left hand holds the infundibulum drawn
/// laterally while the hook's energy goes to the connective tissue alone, until a third of
/// the bed is released: no burn, no energy on no tissue, passed. Careless: energy with the
/// hook on nothing, then held on the gallbladder's wall until it is burned through, a
/// perforation that spills bile and fails the attempt; the debrief says where.
#[test]
fn dissection_frees_the_bed_and_a_burn_through_the_wall_fails_it() {
    use pgd_surgery::scenario::tasks::DissectionResult;
    let name = "gallbladder-liver-bed-dissection";
    let competent = run(name, "competent").card;
    let metrics = &competent.tasks[1].metrics;
    let done = metrics.result::<DissectionResult>().unwrap();
    assert!(metrics.completed && competent.passed, "{competent:#?}");
    assert!(done.released_share >= 0.33, "{done:?}");
    assert!(done.ties_divided > 10, "{done:?}");
    assert!(
        done.burns.is_empty() && done.perforation.is_none(),
        "{done:?}"
    );
    assert_eq!(done.energy.in_air_j, 0.0);
    assert!((done.energy.on_ties_j - done.energy.total_j).abs() < 1e-9);
    let hold = metrics.countertraction.as_ref().unwrap();
    assert!(hold.in_band_share() > 0.95, "{hold:?}");
    eprintln!(
        "competent: {:.1} % released, {} ties divided, {:.0} J on the ties, {:.1} s, score {:.0}",
        100.0 * done.released_share,
        done.ties_divided,
        done.energy.on_ties_j,
        metrics.time_s,
        competent.score
    );

    let careless = run(name, "careless").card;
    let metrics = &careless.tasks[1].metrics;
    let done = metrics.result::<DissectionResult>().unwrap();
    assert!(!careless.passed && careless.score < competent.score);
    // 0.3 s at 30 W with the hook on nothing.
    assert!((done.energy.in_air_j - 9.0).abs() < 0.1, "{done:?}");
    let perforation = done.perforation.as_ref().expect("perforated");
    assert_eq!(perforation.organ, "gallbladder");
    assert_eq!(done.burns.len(), 1);
    // Through the 2 mm wall under the 1 mm cut zone: 2 mm × π (0.5 mm)² × 2.03 GJ/m³ ≈ 3.2 J.
    assert!((done.energy.on_walls_j - 3.19).abs() < 0.05, "{done:?}");
    assert!((perforation.time_s - done.burns[0].time_s - 0.106).abs() < 0.002);
    let debrief = careless.feedback.join("\n");
    for words in [
        "perforation, bile spilled",
        "burned the gallbladder at (",
        "on no tissue",
    ] {
        assert!(debrief.contains(words), "{debrief}");
    }
}
