//! A trainee's learning curve: score and time of each attempt, in the order made, one line
//! per scenario.

use std::path::Path;

use plotters::prelude::*;

use super::plot::{draw_legend, legend_stroke, save_png};

const SIZE: (u32, u32) = (1000, 700);

/// One attempt on the curve.
#[derive(Clone, Copy, Debug)]
pub struct CurvePoint<'a> {
    /// The scenario's title: one line each.
    pub scenario: &'a str,
    pub score: f64,
    pub time_s: f64,
}

/// Draws the score (top) and the time taken (bottom) of `attempts` (oldest first) against
/// the attempt's number within its scenario, one colour per scenario.
pub fn learning_curve(path: &Path, attempts: &[CurvePoint]) -> Result<(), String> {
    let mut scenarios: Vec<&str> = attempts.iter().map(|a| a.scenario).collect();
    scenarios.sort_unstable();
    scenarios.dedup();
    let series = |title: &str, value: fn(&CurvePoint) -> f64| -> Vec<(f64, f64)> {
        attempts
            .iter()
            .filter(|a| a.scenario == title)
            .enumerate()
            .map(|(k, a)| ((k + 1) as f64, value(a)))
            .collect()
    };
    let count = |title: &&str| attempts.iter().filter(|a| a.scenario == *title).count();
    let most = scenarios.iter().map(count).max().unwrap_or(1) as f64;
    let slowest = attempts.iter().map(|a| a.time_s).fold(1.0, f64::max) * 1.1;
    let colours = [BLUE, RED, GREEN, MAGENTA, CYAN, BLACK];
    save_png(path, SIZE, |root| {
        let panels = root.split_evenly((2, 1));
        let panel = [
            (
                "score over attempts",
                "score (0–100)",
                0.0..100.0,
                (|a: &CurvePoint| a.score) as fn(&CurvePoint) -> f64,
            ),
            (
                "time over attempts",
                "time (s)",
                0.0..slowest,
                |a: &CurvePoint| a.time_s,
            ),
        ];
        for (area, (caption, y_desc, range, value)) in panels.iter().zip(panel) {
            let mut chart = ChartBuilder::on(area)
                .caption(caption, ("sans-serif", 20))
                .margin(12)
                .x_label_area_size(36)
                .y_label_area_size(56)
                .build_cartesian_2d(0.5..most + 0.5, range)?;
            chart
                .configure_mesh()
                .x_labels(most as usize + 1)
                .x_label_formatter(&|x| match x.fract() == 0.0 {
                    true => format!("{x:.0}"),
                    false => String::new(),
                })
                .x_desc("attempt")
                .y_desc(y_desc)
                .draw()?;
            for (scenario, colour) in scenarios.iter().zip(colours.iter().cycle()) {
                let colour = *colour;
                let points = series(scenario, value);
                chart
                    .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
                    .label(*scenario)
                    .legend(legend_stroke(colour));
                chart.draw_series(
                    points
                        .into_iter()
                        .map(|p| Circle::new(p, 4, colour.filled())),
                )?;
            }
            draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
        }
        Ok(())
    })
    .map_err(|e| format!("{}: {e}", path.display()))
}
