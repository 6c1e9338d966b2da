//! Files written for people to read: an attempt's report (scorecard, summary, force plot) and
//! a vademecum build's convergence curves (table and plot). No Bevy.

mod convergence;
mod plot;
mod scorecard;

pub use convergence::{
    StepCurve, write as write_convergence, write_of_header as write_convergence_of,
};
pub use plot::{LineChart, Series, line_chart, save_png};
pub use scorecard::{summary, write_report};
