//! An attempt's report on disk: the scorecard as JSON, a summary a trainee reads, and
//! a plot of the force against time with each task's limits drawn over its span, and for an
//! incision, the cuts drawn over the marked line; for a keratotomy, the incisions drawn on
//! the cornea seen from the front; and where the critical view of safety was judged, its
//! doublet of pictures.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use nalgebra::Vector3;

use super::critical_view::draw_critical_view;
use super::plot::{Area, PlotResult, draw_legend, legend_stroke, save_png};
use crate::scenario::tasks::{IncisionResult, RadialKeratotomyResult};
use crate::scenario::{CutMade, IncisionMetrics, KeratotomyMetrics, Scorecard};

const SIZE: (u32, u32) = (1200, 500);
/// The plot's size with an incision's or a keratotomy's panel under the force.
const SIZE_WITH_INCISION: (u32, u32) = (1200, 900);

/// The files of an attempt's report.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportFiles {
    pub json: PathBuf,
    pub summary: PathBuf,
    pub plot: PathBuf,
    /// The critical view of safety's doublet, in a scene with a biliary tree.
    pub critical_view: Option<PathBuf>,
}

impl ReportFiles {
    /// Every file, in the order above.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        [&self.json, &self.summary, &self.plot]
            .into_iter()
            .chain(&self.critical_view)
            .map(PathBuf::as_path)
    }
}

/// Writes `<stem>.json`, `<stem>.txt`, `<stem>.png` and, where the critical view was
/// judged, `<stem>.critical-view.png` in `dir`; returns their paths.
pub fn write_report(
    dir: &Path,
    stem: &str,
    card: &Scorecard,
    force_trace: &[(f64, f64)],
) -> Result<ReportFiles, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let [json, text, png] = ["json", "txt", "png"].map(|ext| dir.join(format!("{stem}.{ext}")));
    let body = serde_json::to_string_pretty(card).map_err(|e| e.to_string())?;
    std::fs::write(&json, body).map_err(|e| format!("{}: {e}", json.display()))?;
    std::fs::write(&text, summary(card)).map_err(|e| format!("{}: {e}", text.display()))?;
    plot(&png, card, force_trace).map_err(|e| format!("{}: {e}", png.display()))?;
    let critical_view = (card.critical_view.as_ref())
        .map(|record| {
            let path = dir.join(format!("{stem}.critical-view.png"));
            draw_critical_view(&path, record).map(|()| path)
        })
        .transpose()?;
    Ok(ReportFiles {
        json,
        summary: text,
        plot: png,
        critical_view,
    })
}

/// The scorecard in words: the verdict, each task's metrics and score, what went wrong.
pub fn summary(card: &Scorecard) -> String {
    let mut out = String::new();
    let verdict = if card.passed { "PASSED" } else { "FAILED" };
    let _ = writeln!(
        out,
        "{}: {verdict} with {:.0} / 100 (pass mark {:.0})",
        card.title, card.score, card.pass_mark
    );
    write_operation(&mut out, card);
    for (k, task) in card.tasks.iter().enumerate() {
        let m = &task.metrics;
        let _ = writeln!(
            out,
            "task {}: {}: {}\n  {} in {:.1} s of {:.0} s; contact {:.1} s, peak {:.2} N, mean {:.2} N, {:.1} s above {:.2} N; {} errors; score {:.0}",
            k + 1,
            m.kind,
            m.description,
            if m.completed { "done" } else { "not done" },
            m.time_s,
            m.time_limit_s,
            m.contact_s,
            m.peak_force_n,
            m.mean_force_n,
            m.time_over_limit_s,
            m.force_limit_n,
            m.error_count(),
            task.score
        );
        let motion = &m.motion;
        let economy = motion
            .economy
            .map_or(String::new(), |e| format!(" ({e:.2}× the shortest)"));
        let view = motion
            .out_of_view_s
            .map_or(String::new(), |s| format!(", out of view {s:.1} s"));
        let _ = writeln!(
            out,
            "  motion: path {:.0} mm{economy}, {} movement{}, idle {:.1} s, jerk {:.2} m/s³ rms{view}",
            motion.path_length_mm,
            motion.movements,
            if motion.movements == 1 { "" } else { "s" },
            motion.idle_s,
            motion.rms_jerk_m_per_s3
        );
        if let Some(changes) = motion.instrument_changes {
            let paths: Vec<String> = (motion.path_length_by_instrument_mm.iter())
                .enumerate()
                .map(|(k, mm)| format!("{} {mm:.0} mm", k + 1))
                .collect();
            let _ = writeln!(
                out,
                "  instruments changed {changes} time{}; path by instrument: {}",
                if changes == 1 { "" } else { "s" },
                paths.join(", ")
            );
        }
        if let Some(out_s) = m.target_out_of_view_s {
            let _ = writeln!(out, "  the point to keep in view: out of view {out_s:.1} s");
        }
        for line in m.outcome.iter().flat_map(|o| o.summary()) {
            let _ = writeln!(out, "  {line}");
        }
    }
    if !card.feedback.is_empty() {
        let _ = writeln!(out, "what to work on:");
        for line in &card.feedback {
            let _ = writeln!(out, "  - {line}");
        }
    }
    out
}

/// The phases with their times, the operation's points and steps, and the global measures,
/// where the scenario has them.
fn write_operation(out: &mut String, card: &Scorecard) {
    for (k, phase) in card.phases.iter().enumerate() {
        let _ = writeln!(
            out,
            "phase {}, {}: {:.1} to {:.1} s ({:.1} s), {}",
            k + 1,
            phase.name,
            phase.started_s,
            phase.ended_s,
            phase.ended_s - phase.started_s,
            if phase.completed { "done" } else { "not done" }
        );
    }
    if let Some(operation) = &card.operation {
        let _ = writeln!(
            out,
            "operation: {:.0} of {:.0} points{}",
            operation.points,
            operation.possible,
            if operation.major_error {
                ", a major error"
            } else {
                ""
            }
        );
        for step in &operation.steps {
            let when = step
                .done_s
                .map_or("not done".into(), |t| format!("done at {t:.1} s"));
            let _ = writeln!(out, "  {} ({} points): {when}", step.name, step.points);
        }
    }
    if let Some(g) = &card.global {
        let economy = |e: Option<f64>| e.map_or("-".into(), |e| format!("{e:.2}"));
        let _ = writeln!(
            out,
            "global: {:.1} s; paths {:.0} / {:.0} mm (right / left), economy {} / {}; out of \
             view {:.1} s, {} movements; {:.1} s above the force limits, peak {:.2} N; {} \
             burns ({:.0} mm²); blood {:.1} ml, bile {:.1} ml",
            g.time_s,
            g.path_mm[0],
            g.path_mm[1],
            economy(g.economy[0]),
            economy(g.economy[1]),
            g.out_of_view_s,
            g.movements,
            g.over_limit_s,
            g.peak_force_n,
            g.burns,
            g.burned_area_mm2,
            g.blood_lost_ml,
            g.bile_spilled_ml
        );
    }
    if let Some(proficient) = card.proficient {
        let verdict = if proficient { "met" } else { "not met" };
        let _ = writeln!(out, "benchmark: {verdict}");
    }
}

fn plot(path: &Path, card: &Scorecard, trace: &[(f64, f64)]) -> PlotResult {
    let incision = (card.tasks.iter())
        .find_map(|t| t.metrics.result::<IncisionResult>())
        .map(|r| &r.incision);
    let keratotomy = (card.tasks.iter())
        .find_map(|t| t.metrics.result::<RadialKeratotomyResult>())
        .map(|r| &r.keratotomy);
    if incision.is_none() && keratotomy.is_none() {
        return save_png(path, SIZE, |root| force_plot(root, card, trace));
    }
    save_png(path, SIZE_WITH_INCISION, |root| {
        let (top, bottom) = root.split_vertically(SIZE.1);
        force_plot(&top, card, trace)?;
        match (incision, keratotomy) {
            (Some(incision), _) => incision_plot(&bottom, incision, &card.cuts),
            (None, Some(keratotomy)) => keratotomy_plot(&bottom, keratotomy),
            (None, None) => Ok(()),
        }
    })
}

/// The cornea seen from the front (mm off its axis): the limbus, the optical zone to keep
/// clear, the plan's evenly spaced meridians turned to the first incision, and each incision
/// from its nearest to its farthest reach; the predicted correction in the caption.
fn keratotomy_plot(area: &Area, rk: &KeratotomyMetrics) -> PlotResult {
    let limbus_mm = crate::mesh::organs::CORNEA_RIM_M * 1e3;
    let reach = 1.1 * limbus_mm;
    let correction = rk
        .predicted_correction_d
        .map_or("no correction predicted".to_owned(), |d| {
            format!(
                "predicted correction {d:.1} D for {:.1} D",
                rk.target_correction_d
            )
        });
    let perforated = if rk.perforated { "; PERFORATED" } else { "" };
    // Square to the cornea, with room on its right for the legend.
    let (width, height) = area.dim_in_pixel();
    let wide = (1.8 * f64::from(height)).min(f64::from(width)) as i32;
    let side = (width as i32 - wide) / 2;
    let panel = area.margin(0, 0, side, side);
    // The plotting area's width over its height, less the labels, margins and caption, so
    // that a millimetre is as long across as up.
    let aspect = f64::from(wide - 16 * 2 - 48) / f64::from(height as i32 - 16 * 2 - 40 - 30);
    let mut chart = ChartBuilder::on(&panel)
        .caption(
            format!("the incisions: {correction}{perforated}"),
            ("sans-serif", 20),
        )
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(48)
        .build_cartesian_2d(-reach..reach * (2.0 * aspect - 1.0), -reach..reach)?;
    chart
        .configure_mesh()
        .x_desc("x (mm)")
        .y_desc("y (mm)")
        .draw()?;
    let circle = |radius: f64| {
        (0..=120).map(move |k| {
            let a = std::f64::consts::TAU * f64::from(k) / 120.0;
            (radius * a.cos(), radius * a.sin())
        })
    };
    chart
        .draw_series(LineSeries::new(circle(limbus_mm), BLACK.stroke_width(1)))?
        .label("the limbus")
        .legend(legend_stroke(BLACK.stroke_width(1)));
    chart
        .draw_series([Polygon::new(
            circle(rk.optical_zone_mm / 2.0).collect::<Vec<_>>(),
            RED.mix(0.15).filled(),
        )])?
        .label(format!(
            "the {:.1} mm optical zone, uncut",
            rk.optical_zone_mm
        ))
        .legend(legend_stroke(RED.mix(0.4).stroke_width(8)));
    let turn = rk.incisions.first().map_or(0.0, |c| c.angle_deg);
    for k in 0..rk.planned {
        let a = (turn + 360.0 * k as f64 / rk.planned as f64).to_radians();
        let line = chart.draw_series(LineSeries::new(
            [0.5, 1.0].map(|r| (r * limbus_mm * a.cos(), r * limbus_mm * a.sin())),
            GREEN.stroke_width(2),
        ))?;
        if k == 0 {
            line.label("the plan's spacing")
                .legend(legend_stroke(GREEN.stroke_width(2)));
        }
    }
    for (k, cut) in rk.incisions.iter().enumerate() {
        let a = cut.angle_deg.to_radians();
        let ends = [cut.from_mm, cut.to_mm].map(|r| (r * a.cos(), r * a.sin()));
        let line = chart.draw_series(LineSeries::new(ends, BLACK.stroke_width(3)))?;
        if k == 0 {
            line.label("an incision")
                .legend(legend_stroke(BLACK.stroke_width(3)));
        }
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// The incision seen square to the marked line: along it (mm from its start) and across it
/// (mm off it, in the plane of the line and the scene's front-back axis, or its head-feet
/// axis for a line running front to back), the tolerance band shaded, each stroke from where
/// the tissue parted to where the cut reached.
fn incision_plot(area: &Area, incision: &IncisionMetrics, cuts: &[CutMade]) -> PlotResult {
    let from = Vector3::from(incision.from_mm);
    let along = (Vector3::from(incision.to_mm) - from).normalize();
    let facing = match along.y.abs() < 0.9 {
        true => Vector3::y(),
        false => Vector3::z(),
    };
    let across = along.cross(&facing).normalize();
    let square = |p: [f64; 3]| {
        let d = Vector3::from(p) - from;
        (d.dot(&along), d.dot(&across))
    };
    let length = incision.line_length_mm;
    let reach = cuts
        .iter()
        .flat_map(|c| [square(c.start_mm).1, square(c.end_mm).1])
        .fold(3.0 * incision.tolerance_mm, |m, y| m.max(y.abs() * 1.2));
    let mut chart = ChartBuilder::on(area)
        .caption("the cuts over the marked line", ("sans-serif", 20))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.1 * length..1.1 * length, -reach..reach)?;
    chart
        .configure_mesh()
        .x_desc("along the line (mm)")
        .y_desc("off the line (mm)")
        .draw()?;
    let tolerance = incision.tolerance_mm;
    chart
        .draw_series([Rectangle::new(
            [(0.0, -tolerance), (length, tolerance)],
            GREEN.mix(0.15).filled(),
        )])?
        .label(format!("within {tolerance:.1} mm of the line"))
        .legend(legend_stroke(GREEN.mix(0.4).stroke_width(8)));
    chart
        .draw_series(LineSeries::new(
            [(0.0, 0.0), (length, 0.0)],
            GREEN.stroke_width(2),
        ))?
        .label("the marked line")
        .legend(legend_stroke(GREEN.stroke_width(2)));
    for (k, cut) in cuts.iter().enumerate() {
        let stroke = chart.draw_series(LineSeries::new(
            [square(cut.start_mm), square(cut.end_mm)],
            BLACK.stroke_width(3),
        ))?;
        if k == 0 {
            stroke
                .label("a stroke: where the tissue parted to where the cut reached")
                .legend(legend_stroke(BLACK.stroke_width(3)));
        }
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// The force sent to the device against time, each task's limits over its span.
fn force_plot(root: &Area, card: &Scorecard, trace: &[(f64, f64)]) -> PlotResult {
    let end_s = trace.last().map_or(1.0, |p| p.0).max(1e-3);
    let limits = card.tasks.iter().map(|t| t.metrics.force_limit_n);
    let top_n = trace.iter().map(|p| p.1).chain(limits).fold(0.1, f64::max) * 1.15;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("{}: force against time", card.title),
            ("sans-serif", 22),
        )
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..end_s, 0.0..top_n)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("force (N)")
        .draw()?;
    chart
        .draw_series(LineSeries::new(trace.iter().copied(), BLUE.stroke_width(2)))?
        .label("force sent to the device")
        .legend(legend_stroke(BLUE.stroke_width(2)));
    for task in &card.tasks {
        let m = &task.metrics;
        let span = (m.started_s, m.started_s + m.time_s.max(1e-3));
        let mut bounds = vec![m.force_limit_n];
        bounds.extend(m.outcome.as_ref().and_then(|o| o.lower_force_n()));
        for level in bounds {
            chart.draw_series(LineSeries::new(
                [(span.0, level), (span.1, level)],
                RED.stroke_width(2),
            ))?;
        }
        chart.draw_series([Text::new(
            m.kind.to_string(),
            (span.0, m.force_limit_n),
            ("sans-serif", 14),
        )])?;
    }
    draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    Ok(())
}
