//! Every shipped scenario's competent and careless runs, once each: they score as they should,
//! their debriefs print in the shipped font, and the 1 kHz tick allocates nothing once warm — the counting allocator counts the
//! allocations made on the thread that ticks, while it ticks, through presses, slides,
//! palpation, grasps, cuts, organ contact, instrument changes, the laparoscope, force limits
//! passed and scoring. Each allocation is traced to the function in the project's code that
//! made it; the only ones allowed are those named in [`NAMED`], each at most its bound in any
//! one run (one attempt).

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;

use pgd_surgery::app::attempt::{Outcome, end, prepare, scenario_scene, sites_on};
use pgd_surgery::app::haptic::{ExerciseRun, HapticLoop, SettleCuts, TickClock};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::app::shipped::SHIPPED_RUNS;
use pgd_surgery::devices::{HapticDevice, Scripted, TICK_S, Trajectory};
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
            |k| format!("{} {}", function_name(lines[k - 1]), lines[k].trim()),
        );
    SITES.with(|sites| *sites.borrow_mut().entry(site).or_default() += 1);
}

/// A backtrace's frame line (`  12: crate::module::function`) down to the function's name.
fn function_name(frame: &str) -> &str {
    let path = frame
        .trim()
        .split_once(": ")
        .map_or(frame, |(_, path)| path);
    let path = path.split('<').next().unwrap_or(path);
    path.rsplit("::").next().unwrap_or(path)
}

/// The sites this thread has traced since the last call, emptied.
fn take_sites() -> BTreeMap<String, u64> {
    SITES.with(|sites| std::mem::take(&mut *sites.borrow_mut()))
}

/// What the tick may still allocate once warm: the function (its file and name as the trace
/// gives them), why, and how many allocations one run may make there at most.
const NAMED: &[(&str, &str, u64)] = &[(
    "next_answer at ./crates/pgd-surgery-core/src/cutting/worker/threaded.rs",
    "a simulated clock only (`SettleCuts`): waiting for the cut worker's answer registers the \
     ticking thread as a waiter on the answers' channel, whose list of waiters grows the first \
     times; the real-time tick polls instead and never waits",
    2,
)];

/// Ticks counted as warm-up: each stage's first tick, the first contact's buffers.
const WARM_UP_TICKS: u64 = 200;

/// One run's outcome, its ticks, and the allocations on this thread while it ran its ticks
/// after warm-up.
fn counted_run(file: &str, text: &str, script: &str) -> (Outcome, u64, u64) {
    let scenario = parse(Path::new(file), text).unwrap();
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let hands = Trajectory::read_hands(Path::new(file), script.as_bytes()).unwrap();
    let ticks = ((hands[0].duration_s() + 0.1) / TICK_S).ceil() as u64;
    let devices = (hands.into_iter())
        .map(|hand| Box::new(Scripted::new("counted", hand)) as Box<dyn HapticDevice>)
        .collect();
    let mut haptic = HapticLoop::with_devices(&scene, devices).unwrap();
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
/// A scoring that cannot tell a competent run from a careless one is broken; a tick that
/// allocates can be late.
#[test]
fn shipped_runs_score_as_they_should_and_their_ticks_allocate_only_what_is_named() {
    counting::on_allocation(Some(trace));
    let mut misplaced = Vec::new();
    for run in SHIPPED_RUNS {
        let name = run.file;
        let (competent, ticks, count) = counted_run(name, run.scenario, run.competent);
        misplaced.extend(report(&format!("{name} (competent)"), ticks, count));
        let (careless, ticks, count) = counted_run(name, run.scenario, run.careless);
        misplaced.extend(report(&format!("{name} (careless)"), ticks, count));
        let (competent, careless) = (competent.card, careless.card);
        for card in [&competent, &careless] {
            let debrief = pgd_surgery::report::summary(card);
            let missing = pgd_surgery::report::without_glyph(&debrief);
            assert!(
                missing.is_empty(),
                "{name}: no glyph for {missing:?} in {debrief}"
            );
        }
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
    assert!(
        misplaced.is_empty(),
        "the tick allocated where nothing is named, or more than named: {misplaced:#?}"
    );
}

/// Prints what one run allocated and where; what it allocated outside [`NAMED`] or past a
/// bound there.
fn report(run: &str, ticks: u64, count: u64) -> Vec<String> {
    eprintln!("{count:>6} allocations in {ticks:>6} ticks: {run}");
    let mut misplaced = Vec::new();
    for (site, count) in take_sites() {
        match NAMED
            .iter()
            .find(|(function, ..)| site.starts_with(function))
        {
            Some((_, why, bound)) if count <= *bound => {
                eprintln!("{count:>6} at {site}: {why} (at most {bound} a run)");
            }
            Some((_, _, bound)) => misplaced.push(format!("{run}: {count} > {bound} at {site}")),
            None => misplaced.push(format!("{run}: {count} at {site}")),
        }
    }
    misplaced
}

/// The gentle press on the gallbladder with the gallbladder tied to the liver by its bed: the
/// bed's ties, solved every tick, allocate nothing.
#[test]
fn a_tick_with_the_gallbladder_tied_to_its_bed_allocates_only_what_is_named() {
    let run = (SHIPPED_RUNS.iter())
        .find(|run| run.file.ends_with("gallbladder-gentle-press.scenario.ron"))
        .unwrap();
    let organs = r#"organs: ["liver", "gallbladder"],"#;
    let tied = run.scenario.replace(
        organs,
        &format!(r#"{organs} attachments: [Attachment(organ: "gallbladder", to: "liver")],"#),
    );
    assert_ne!(tied, run.scenario);
    counting::on_allocation(Some(trace));
    let (_, ticks, count) = counted_run(run.file, &tied, run.competent);
    let misplaced = report("gallbladder tied to its bed (competent)", ticks, count);
    counting::on_allocation(None);
    assert!(misplaced.is_empty(), "{misplaced:#?}");
}
