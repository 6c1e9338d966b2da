//! The convergence curves of a vademecum build, as a CSV table and a PNG plot in the manner of
//! figures 13–14 of paper 000: error against the total number of modes over all load steps
//! (the plateaus of the load-step scheme), and error against modes per load step, with the
//! optimal rank-n error (the brute-force SVD) for comparison.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::plot::{Area, PlotResult, draw_legend, legend_stroke, save_png};
use crate::pgd::{ErrorCurve, Header};

const SIZE: (u32, u32) = (1400, 560);

/// Which of a step's curves a plotted series shows.
type CurveValues = fn(&ErrorCurve) -> &[f64];

/// One load step's curve and the indentation it stands for.
pub struct StepCurve<'a> {
    pub indentation_m: f64,
    pub curve: &'a ErrorCurve,
}

/// Writes the curves a vademecum's header keeps, per load step, beside it; returns the paths.
pub fn write_of_header(vademecum: &Path, header: &Header) -> Result<[PathBuf; 2], String> {
    let steps: Vec<StepCurve> = header
        .indentation_levels_m
        .iter()
        .zip(&header.convergence)
        .map(|(&indentation_m, curve)| StepCurve {
            indentation_m,
            curve,
        })
        .collect();
    write(vademecum, &steps)
}

/// Writes `<stem>.convergence.csv` and `<stem>.convergence.png` beside `vademecum`; returns
/// their paths.
pub fn write(vademecum: &Path, steps: &[StepCurve]) -> Result<[PathBuf; 2], String> {
    let csv = vademecum.with_extension("convergence.csv");
    let png = vademecum.with_extension("convergence.png");
    std::fs::write(&csv, table(steps)).map_err(|e| format!("{}: {e}", csv.display()))?;
    plot(&png, steps).map_err(|e| format!("{}: {e}", png.display()))?;
    Ok([csv, png])
}

/// One row per step and mode count: the PGD's energy error, the optimal one, their ratio and
/// the whole vademecum's field error (the estimator) and the 95th percentile of each load's own
/// field error (empty for files written before it was recorded).
pub fn table(steps: &[StepCurve]) -> String {
    let mut out = String::from(
        "step,indentation_mm,modes,total_modes,pgd_energy_error,optimal_energy_error,ratio,vademecum_field_error,per_load_field_error_p95\n",
    );
    let mut total = 0;
    for (k, step) in steps.iter().enumerate() {
        let c = step.curve;
        for n in 0..c.separated.len() {
            total += 1;
            let optimal = c.optimal.get(n).copied().unwrap_or(f64::NAN);
            let field = c.field.get(n).copied().unwrap_or(f64::NAN);
            let p95 = c
                .field_p95
                .get(n)
                .map_or(String::new(), |e| format!("{e:.6e}"));
            let _ = writeln!(
                out,
                "{k},{:.3},{},{total},{:.6e},{:.6e},{:.4},{:.6e},{p95}",
                step.indentation_m * 1e3,
                n + 1,
                c.separated[n],
                optimal,
                c.separated[n] / optimal,
                field,
            );
        }
    }
    out
}

fn plot(path: &Path, steps: &[StepCurve]) -> PlotResult {
    save_png(path, SIZE, |root| {
        let (left, right) = root.split_horizontally(SIZE.0 / 2);
        let lowest = steps
            .iter()
            .flat_map(|s| {
                s.curve
                    .separated
                    .iter()
                    .chain(&s.curve.optimal)
                    .chain(&s.curve.field)
            })
            .copied()
            .filter(|e| *e > 0.0)
            .fold(1.0, f64::min);
        let floor = 10f64.powf(lowest.log10().floor());
        all_steps(&left, steps, floor)?;
        per_step(&right, steps, floor)
    })
}

/// Figure 13: the energy error of the separated part against all modes so far.
fn all_steps(area: &Area, steps: &[StepCurve], floor: f64) -> PlotResult {
    let total: usize = steps.iter().map(|s| s.curve.separated.len()).sum();
    let mut chart = ChartBuilder::on(area)
        .caption("Error against total number of modes", ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(0usize..total.max(1), (floor..1.0).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("modes (all load steps)")
        .y_desc("relative error")
        .draw()?;
    let series: [(CurveValues, RGBColor, &str); 2] = [
        (|c| &c.separated, BLUE, "PGD separated part (energy norm)"),
        (
            |c| &c.field,
            RED,
            "whole vademecum, modes + exact near field (L2)",
        ),
    ];
    for (values, colour, label) in series {
        let points = steps
            .iter()
            .flat_map(|s| values(s.curve).iter().copied())
            .enumerate()
            .map(|(n, e)| (n + 1, e.max(floor)));
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(2)))?
            .label(label)
            .legend(legend_stroke(colour.stroke_width(2)));
    }
    draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    Ok(())
}

/// Figure 14: per load step, the PGD's error and the optimal rank-n error.
fn per_step(area: &Area, steps: &[StepCurve], floor: f64) -> PlotResult {
    let longest = steps
        .iter()
        .map(|s| s.curve.separated.len())
        .max()
        .unwrap_or(1);
    let mut chart = ChartBuilder::on(area)
        .caption("Error against modes per load step", ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(1usize..longest.max(2), (floor..1.0).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("modes in the step")
        .y_desc("relative energy error")
        .draw()?;
    for (k, step) in steps.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        let label = format!("step {k} ({:.1} mm)", step.indentation_m * 1e3);
        let curve = step.curve.separated.iter().enumerate();
        chart
            .draw_series(LineSeries::new(
                curve.map(|(n, e)| (n + 1, e.max(floor))),
                colour.stroke_width(2),
            ))?
            .label(label)
            .legend(legend_stroke(colour.stroke_width(2)));
        let optimal = step.curve.optimal.iter().enumerate();
        chart.draw_series(DashedLineSeries::new(
            optimal.map(|(n, e)| (n + 1, e.max(floor))),
            6,
            4,
            colour.stroke_width(1),
        ))?;
    }
    draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    chart.plotting_area().draw(&Text::new(
        "dashed: optimal rank-n (SVD)",
        (longest.max(2) * 2 / 3, 0.5),
        ("sans-serif", 16),
    ))?;
    Ok(())
}
