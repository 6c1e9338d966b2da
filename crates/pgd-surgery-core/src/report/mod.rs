//! Files written for people to read: an attempt's report (scorecard, summary, force plot, the
//! critical view of safety's doublet), a trainee's learning curve, and a vademecum build's
//! convergence curves (table and plot). No Bevy.

mod convergence;
pub mod critical_view;
mod learning_curve;
mod plot;
mod regions;
mod scorecard;

pub use convergence::{
    StepCurve, write as write_convergence, write_of_header as write_convergence_of,
};
pub use critical_view::{critical_view_rgb, draw_critical_view};
pub use learning_curve::{CurvePoint, learning_curve};
pub use plot::{FONT_DATA, LineChart, Series, draw_rgb, line_chart, save_png, without_glyph};
pub use regions::draw_regions;
pub use scorecard::{ReportFiles, summary, write_report};
