//! The 1 kHz tick allocates nothing once warm: the counting allocator counts the allocations
//! made on the thread that ticks, while it ticks, through every shipped scenario's competent
//! and careless runs — presses, slides, palpation, grasps, cuts, organ contact, instrument
//! changes, the laparoscope, faults over the force limit and scoring. `PGD_ALLOC_TRACE=1`
//! prints where the first allocations came from.

use std::cell::RefCell;
use std::path::Path;

use pgd_surgery::app::attempt::{end, prepare, scenario_scene, sites_on};
use pgd_surgery::app::haptic::{ExerciseRun, HapticLoop, SettleCuts, TickClock};
use pgd_surgery::app::scene::Detail;
use pgd_surgery::app::shipped::SHIPPED_RUNS;
use pgd_surgery::devices::{Scripted, TICK_S, Trajectory};
use pgd_surgery::scenario::{Exercise, parse};
use pgd_surgery::store::OnStale;

use crate::counting;
use crate::vademecums;

/// How many allocations are traced when `PGD_ALLOC_TRACE` is set.
const TRACED: usize = 8;

thread_local! {
    static TRACES: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

fn trace() {
    TRACES.with(|traces| {
        if traces.borrow().len() < TRACED {
            let trace = std::backtrace::Backtrace::force_capture().to_string();
            traces.borrow_mut().push(trace);
        }
    });
}

/// Ticks counted as warm-up: each stage's first tick, the first contact's buffers.
const WARM_UP_TICKS: u64 = 200;

/// Allocations on this thread while it ran the ticks after warm-up of one run.
fn allocations_while_ticking(file: &str, text: &str, script: &str) -> u64 {
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
    end(&mut haptic).expect("an exercise ran");
    counting::allocated().count
}

#[test]
fn the_haptic_tick_allocates_nothing_once_warm() {
    if std::env::var_os("PGD_ALLOC_TRACE").is_some() {
        counting::on_allocation(Some(trace));
    }
    let mut counts = Vec::new();
    for run in SHIPPED_RUNS {
        for (script, text) in [("competent", run.competent), ("careless", run.careless)] {
            let count = allocations_while_ticking(run.file, run.scenario, text);
            counts.push((format!("{} ({script})", run.file), count));
        }
    }
    counting::on_allocation(None);
    for (run, count) in &counts {
        eprintln!("{count:>6} allocations while ticking: {run}");
    }
    TRACES.with(|traces| {
        for trace in traces.borrow().iter() {
            eprintln!("--- an allocation on the haptic thread:\n{trace}");
        }
    });
    let allocating: Vec<_> = counts.iter().filter(|(_, count)| *count > 0).collect();
    assert!(
        allocating.is_empty(),
        "the tick allocated (PGD_ALLOC_TRACE=1 says where): {allocating:?}"
    );
}
