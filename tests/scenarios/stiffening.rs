//! The trainer's felt force over a scripted 30 mm press into the coarse liver: under the
//! exponential law it firms up as the tool goes deeper (the slope of force against depth
//! grows from one stretch of the press to the next) until the press leaves the range its load
//! steps answer, and beyond it goes on at the stiffness of the last load-step interval, the
//! report saying how far beyond the tool went. Under the linear law, pressed the same way, the
//! slope stays put.

use std::path::Path;

use pgd_surgery::app::attempt::{run_simulated, scenario_scene};
use pgd_surgery::app::haptic::{ForceTrace, HapticLoop, HapticScene, HeadlessReport};
use pgd_surgery::app::scene::{Detail, press_targets};
use pgd_surgery::devices::{
    PressMotion, PressTarget, Scripted, TICK_S, Trajectory, press_and_slide,
};
use pgd_surgery::scenario::{Scenario, Scorecard, parse};
use pgd_surgery::store::OnStale;

use crate::vademecums;

const DEPTH_M: f64 = 30e-3;

/// The coarse liver alone under the law `law` names in a scenario (its default stiffening for
/// the exponential law), its vademecum built with the defaults.
fn liver_scene(law: &str) -> HapticScene {
    liver(law).1
}

/// [`liver_scene`] with its scenario.
fn liver(law: &str) -> (Scenario, HapticScene) {
    let text = format!(
        r#"Scenario(title: "Press", briefing: "Press.",
        organs: [Organ(name: "liver", law: {law})],
        tasks: [ForceControl(organ: "liver", min_force_n: 0.1, max_force_n: 0.3,
                             hold_s: 1.0, time_limit_s: 5.0)])"#
    );
    let scenario = parse(Path::new("press.scenario.ron"), &text).unwrap();
    let scene = scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Rebuild).unwrap();
    (scenario, scene)
}

/// The 30 mm press at the demo's point, in 1 s, and that point.
fn press_script(scene: &HapticScene) -> (Trajectory, PressTarget, PressMotion) {
    let target = press_targets(scene)[0];
    let motion = PressMotion {
        tip_radius_m: scene.probe.tip_radius_m,
        depth_m: DEPTH_M,
        slide_m: 0.0,
        press_s: 1.0,
        ..PressMotion::default()
    };
    (press_and_slide(&[target], &motion), target, motion)
}

/// A press 30 mm deep at the demo's point on the liver, in 1 s: the run's report and, per
/// tick of the way in, the tool's depth below the rest surface (m) and the
/// felt force along the surface's normal (N), and the felt force's magnitude (N).
fn press_deep(scene: &HapticScene) -> (HeadlessReport, Vec<(f64, f64)>, Vec<f64>) {
    let (script, target, motion) = press_script(scene);
    let in_s = motion.approach_s + motion.press_s;
    let depth_at = |time_s: f64| {
        let tip = script.sample(time_s).tip_m;
        motion.tip_radius_m - (tip - target.point_m).dot(&target.normal)
    };
    let depths: Vec<f64> = (0..(in_s / TICK_S).round() as usize)
        .map(|k| depth_at(k as f64 * TICK_S))
        .collect();
    let device = Box::new(Scripted::new("30 mm press", script));
    let mut haptic = HapticLoop::new(scene, device).unwrap();
    haptic.keep_trace();
    let report = haptic.run_simulated(depths.len() as u64);
    let trace = std::mem::take(&mut *haptic.hand_mut::<ForceTrace>(0).unwrap());
    let felt: Vec<(f64, f64)> = depths
        .iter()
        .zip(&trace.desired_n)
        .map(|(&depth_m, force_n)| (depth_m, force_n.dot(&target.normal)))
        .collect();
    let magnitudes = trace.desired_n.iter().take(depths.len()).map(|f| f.norm());
    (report, felt, magnitudes.collect())
}

/// The least-squares slope (N/m) of the felt force against depth over depths in `from..to`.
fn slope(felt: &[(f64, f64)], (from_m, to_m): (f64, f64)) -> f64 {
    let points: Vec<&(f64, f64)> = felt
        .iter()
        .filter(|(d, _)| *d >= from_m && *d < to_m)
        .collect();
    let n = points.len() as f64;
    let mean_d = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_f = points.iter().map(|p| p.1).sum::<f64>() / n;
    let covariance: f64 = points.iter().map(|p| (p.0 - mean_d) * (p.1 - mean_f)).sum();
    let variance: f64 = points.iter().map(|p| (p.0 - mean_d).powi(2)).sum();
    covariance / variance
}

/// The slopes over three equal stretches of depth from 1 mm to `edge_m`.
fn slopes(felt: &[(f64, f64)], edge_m: f64) -> [f64; 3] {
    let width_m = (edge_m - 1e-3) / 3.0;
    [0.0, 1.0, 2.0].map(|k| {
        let from_m = 1e-3 + k * width_m;
        slope(felt, (from_m, from_m + width_m))
    })
}

/// The exponential liver, pressed 30 mm: the force is finite and pushes the tool out; its
/// load steps answer the press beyond 22 mm of tool depth (24.6 mm measured), and over those
/// depths its slope grows from stretch to stretch, by over 30 %
/// from the first to the last, where the linear liver's slope changes by under 1 % over the
/// same depths. Deeper, the report counts the ticks beyond the range, and the force grows on
/// with each tick, firming up still: its magnitude over the depth grows past the edge's by
/// over 5 % by the press's end (11 % measured; at the edge's secant stiffness it stayed within
/// 2.8 % of it), and its slope there is the last load-step interval's chord stiffness, no
/// softer than the last stretch's slope within the range (85.5 against 78.3 N/m measured).
#[test]
fn a_30_mm_press_on_the_exponential_liver_firms_up_beyond_its_range_too() {
    let (report, felt, magnitudes) = press_deep(&liver_scene("Exponential"));
    let (linear_report, linear_felt, _) = press_deep(&liver_scene("Linear"));
    assert!(felt.iter().all(|(_, f)| f.is_finite()));
    assert!((felt.last().unwrap().0 - DEPTH_M).abs() < 0.1e-3);
    assert_eq!(linear_report.range.beyond_ticks, 0, "{linear_report}");
    assert!(report.range.beyond_ticks > 0, "{report}");
    let edge_m = DEPTH_M - report.range.max_beyond_mm * 1e-3;
    let (stiffening, linear) = (slopes(&felt, edge_m), slopes(&linear_felt, edge_m));
    eprintln!(
        "{report}
range edge {:.2} mm; slopes (N/m) exponential {stiffening:?}, linear {linear:?}",
        edge_m * 1e3
    );
    assert!(edge_m > 22e-3, "{report}");
    assert!(stiffening.windows(2).all(|s| s[1] > s[0]), "{stiffening:?}");
    assert!(stiffening[2] > 1.3 * stiffening[0], "{stiffening:?}");
    assert!((linear[2] / linear[0] - 1.0).abs() < 0.01, "{linear:?}");
    assert!(felt.last().unwrap().1 > 0.0);
    let beyond: Vec<(f64, f64)> = felt
        .iter()
        .zip(&magnitudes)
        .filter(|((d, _), _)| *d > edge_m + 0.1e-3)
        .map(|((d, _), f)| (*d, *f))
        .collect();
    assert!(beyond.windows(2).all(|w| w[1].1 > w[0].1), "{beyond:?}");
    let secant = |(depth_m, force_n): (f64, f64)| force_n / depth_m;
    let growth = secant(*beyond.last().unwrap()) / secant(beyond[0]) - 1.0;
    let beyond_slope = slope(&felt, (edge_m + 0.1e-3, DEPTH_M + 1e-3));
    eprintln!(
        "beyond the range: force over depth {:+.2} % from the edge's, slope {beyond_slope:.1} N/m",
        growth * 100.0
    );
    assert!(growth > 0.05, "{growth}: {beyond:?}");
    assert!(
        beyond_slope >= stiffening[2],
        "{beyond_slope} N/m beyond against {stiffening:?}"
    );
}

/// The scored attempt says so too: pressed 30 mm into the exponential liver, its feedback
/// says how far beyond the tissue model's range the tool went (as far as the run's report
/// says, to 0.05 mm) and for how long; into the linear liver, whose range has no
/// end, it says nothing of the kind.
#[test]
fn a_scored_press_beyond_the_range_says_so_in_its_feedback() {
    let attempt = |law: &str| {
        let (scenario, scene) = liver(law);
        let (script, ..) = press_script(&scene);
        let ticks = (script.duration_s() / TICK_S).ceil() as u64;
        let device = Box::new(Scripted::new("30 mm press", script));
        run_simulated(scenario, &scene, vec![device], ticks)
            .unwrap()
            .card
    };
    let (exponential, linear) = (attempt("Exponential"), attempt("Linear"));
    let beyond = |card: &Scorecard| {
        card.feedback
            .iter()
            .find(|line| line.contains("deeper than the tissue model covers"))
            .cloned()
    };
    assert_eq!(beyond(&linear), None, "{:?}", linear.feedback);
    let line = beyond(&exponential).unwrap_or_else(|| panic!("{:?}", exponential.feedback));
    let (report, ..) = press_deep(&liver_scene("Exponential"));
    let metrics = &exponential.tasks[0].metrics;
    assert!(
        (metrics.max_beyond_range_mm - report.range.max_beyond_mm).abs() < 0.05,
        "{line}\n{report}"
    );
    assert!(metrics.beyond_range_s > 0.1, "{line}");
    assert!(
        line.contains(&format!("{:.1} mm", metrics.max_beyond_range_mm)),
        "{line}"
    );
}
