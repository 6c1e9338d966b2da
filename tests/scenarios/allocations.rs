//! Every shipped scenario's competent and careless runs, once each: they score as they should,
//! and what the 1 kHz tick allocates once warm is counted — the counting allocator counts the
//! allocations made on the thread that ticks, while it ticks, through presses, slides,
//! palpation, grasps, cuts, organ contact, instrument changes, the laparoscope, force limits
//! passed and scoring. Each allocation is traced to the place in the project's code that made
//! it; every place must be one of the named kinds below, and a run may not allocate more than
//! once every [`TICKS_PER_ALLOCATION`] ticks on average.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;

use pgd_surgery::app::attempt::{Outcome, end, prepare, scenario_scene, sites_on};
use pgd_surgery::app::haptic::{ExerciseRun, HapticLoop, SettleCuts, TickClock};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::app::shipped::SHIPPED_RUNS;
use pgd_surgery::devices::{Scripted, TICK_S, Trajectory};
use pgd_surgery::scenario::{Exercise, parse};
use pgd_surgery::store::OnStale;

use crate::counting;
use crate::vademecums;

thread_local! {
    /// Each allocating place in the project's code (the innermost frame under the trainer's or
    /// the core's `src/`), and how many allocations it made.
    static SITES: RefCell<BTreeMap<String, u64>> = const { RefCell::new(BTreeMap::new()) };
}

fn trace() {
    let trace = std::backtrace::Backtrace::force_capture().to_string();
    let lines: Vec<&str> = trace.lines().collect();
    let site = (1..lines.len())
        .find(|&k| {
            let line = lines[k].trim_start();
            line.starts_with("at ./src/") || line.starts_with("at ./crates/pgd-surgery-core/src/")
        })
        .map_or_else(
            || "outside the project's code".to_owned(),
            |k| format!("{} {}", lines[k - 1].trim(), lines[k].trim()),
        );
    SITES.with(|sites| *sites.borrow_mut().entry(site).or_default() += 1);
}

/// What the tick may still allocate once warm, by where, and why.
const NAMED: &[(&str, &str)] = &[
    (
        "src/scenario/",
        "scoring an event: an error's message, a task's end and its metrics (once an event)",
    ),
    (
        "src/cutting/",
        "the scalpel: a cut step sent to the cut worker, its answer taken (once a step, 30–95 ms \
         apart)",
    ),
    ("src/app/haptic/cutting.rs", "the scalpel, as above"),
    (
        "src/dynamics/",
        "closing the grasper's jaws: the grasp point on the patch (once a grasp)",
    ),
    ("take_hold", "closing the grasper's jaws, as above"),
    (
        "src/contact/",
        "organ contact's and the tool hold's work lists, grown to the largest contact set seen \
         (doubling: a few times an attempt); not yet reserved up front",
    ),
    (
        "src/pgd/deformation.rs",
        "a grasped organ's load, copied from the grasp's shares (grown as above)",
    ),
];

/// A run may allocate at most once this many ticks, on average.
const TICKS_PER_ALLOCATION: u64 = 25;

/// Ticks counted as warm-up: each stage's first tick, the first contact's buffers.
const WARM_UP_TICKS: u64 = 200;

/// One run's outcome, its ticks, and the allocations on this thread while it ran its ticks
/// after warm-up.
fn counted_run(file: &str, text: &str, script: &str) -> (Outcome, u64, u64) {
    let scenario = parse(Path::new(file), text).unwrap();
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let trajectory = Trajectory::read(Path::new(file), script.as_bytes()).unwrap();
    let ticks = ((trajectory.duration_s() + 0.1) / TICK_S).ceil() as u64;
    let device = Box::new(Scripted::new("counted", trajectory));
    let mut haptic = HapticLoop::new(&scene, device).unwrap();
    haptic.world_mut().insert_resource(SettleCuts);
    let sites = sites_on(&scene, &scenario);
    prepare(&mut haptic, Exercise::new(scenario, sites)).start();
    counting::arm();
    counting::pause();
    for tick in 0..ticks {
        if tick >= WARM_UP_TICKS {
            counting::resume();
        }
        haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        counting::pause();
        if haptic.world().resource::<ExerciseRun>().exercise.is_none() {
            break;
        }
    }
    let outcome = end(&mut haptic).expect("an exercise ran");
    let ticked = haptic.world().resource::<TickClock>().tick + 1;
    (outcome, ticked, counting::allocated().count)
}

/// A scoring that cannot tell a competent run from a careless one is broken; a tick that
/// allocates can be late.
#[test]
fn shipped_runs_score_as_they_should_and_their_ticks_allocate_only_what_is_named() {
    counting::on_allocation(Some(trace));
    let mut counts = Vec::new();
    for run in SHIPPED_RUNS {
        let name = run.file;
        let (competent, ticks, in_competent) = counted_run(name, run.scenario, run.competent);
        counts.push((format!("{name} (competent)"), ticks, in_competent));
        let (careless, ticks, in_careless) = counted_run(name, run.scenario, run.careless);
        counts.push((format!("{name} (careless)"), ticks, in_careless));
        let (competent, careless) = (competent.card, careless.card);
        assert!(
            competent.passed,
            "{name}: the competent run failed: {competent:#?}"
        );
        assert!(
            !careless.passed,
            "{name}: the careless run passed: {careless:#?}"
        );
        assert!(
            competent.score > careless.score + 20.0,
            "{name}: {} vs {}",
            competent.score,
            careless.score
        );
        assert!(
            !careless.feedback.is_empty(),
            "{name}: a failure must say why"
        );
    }
    counting::on_allocation(None);
    for (run, ticks, count) in &counts {
        eprintln!("{count:>6} allocations in {ticks:>6} ticks: {run}");
    }
    let sites = SITES.with(|sites| sites.borrow().clone());
    let mut unnamed = Vec::new();
    for (site, count) in &sites {
        match NAMED.iter().find(|(place, _)| site.contains(place)) {
            Some((_, why)) => eprintln!("{count:>6} at {site}: {why}"),
            None => unnamed.push(format!("{count} at {site}")),
        }
    }
    assert!(
        unnamed.is_empty(),
        "the tick allocated where nothing is named: {unnamed:#?}"
    );
    let over: Vec<_> = counts
        .iter()
        .filter(|(_, ticks, count)| count * TICKS_PER_ALLOCATION > *ticks)
        .collect();
    assert!(
        over.is_empty(),
        "more than one allocation every {TICKS_PER_ALLOCATION} ticks: {over:?}"
    );
}
