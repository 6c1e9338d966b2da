//! What the binaries' commands do and print, apart from parsing their arguments: `pgd build`,
//! `validate`, `indent`, `fit` and `mesh`; `trainer validate`, `devices`, `history` and the end of an
//! attempt (kept in the history); the parsers of option values, with errors that name the range; how a command ends (JSON or a table, or an error).
//! The binaries keep their clap option types beside them and call in here.

mod output;
mod parse;
mod pgd_bench_dynamics;
mod pgd_build;
mod pgd_fit;
mod pgd_indent;
mod pgd_mesh;
mod pgd_validate;
mod trainer_cohort;
mod trainer_commands;
mod trainer_curriculum;
mod trainer_devices;
mod trainer_history;
mod trainer_soak;

pub use output::{fail, print_json, print_report};
pub use trainer_cohort::{CohortRequest, show_cohort};
pub use trainer_curriculum::{is_curriculum, menu_curriculum, show_standing, validate_curriculum};

/// A mesh read for a command, and the generated organ it is, if it is one.
pub struct LoadedMesh {
    pub organ: Option<crate::mesh::organs::Organ>,
    pub mesh: crate::mesh::TetMesh,
    /// What the region selectors picked, when any were given.
    pub selection: Option<crate::mesh::SelectionReport>,
}
pub use parse::{
    parse_cut_pattern, parse_force_limit_n, parse_inclusion, parse_point_mm,
    parse_positive_seconds, parse_seconds, parse_spacing, parse_stiffness_ratio,
    parse_subdivisions,
};
pub use pgd_bench_dynamics::{DynamicsRequest, bench_dynamics, plot_energy};
pub use pgd_build::{PartReport, build_part, build_vademecum, merge_vademecum, print_build_report};
pub use pgd_fit::{FitReport, fit_uniaxial_test, plot_fit};
pub use pgd_indent::{
    IndentReport, IndentRequest, LawCurve, indent_organ, plot_indentation, print_indentation,
};
pub use pgd_mesh::{MeshReport, report_mesh};
pub use pgd_validate::{
    plot_force_depth, print_cut_validation, print_force_depth, print_validation, validate_cuts,
    validate_vademecum,
};
pub use trainer_commands::{debrief, numbered, prepare_scenarios, validate_scenarios};
pub use trainer_devices::list_devices;
pub use trainer_history::{HistoryRequest, HistoryTarget, keep_scored, show_history};
pub use trainer_soak::run_soak;
