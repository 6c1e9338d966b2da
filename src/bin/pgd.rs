//! `pgd`: offline work — benchmarks now; meshes, vademecum builds and validation to come.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use pgd_surgery::bench;

#[derive(Parser)]
#[command(
    name = "pgd",
    version,
    about = "Offline tools of the PGD surgery trainer: benchmarks of the numerical core"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Time the numerical core and print medians (and ratios to a baseline run alongside).
    Bench {
        #[command(subcommand)]
        what: BenchTarget,
    },
}

#[derive(Subcommand)]
enum BenchTarget {
    /// Assembly, factorization and solve on a liver-sized mesh (~4,300 nodes, ~21,000 tets).
    Fem {
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// How many times each step is timed; the median is reported.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Cubes along x, y, z of the benchmark box (six tets each).
        #[arg(long, num_args = 3, value_names = ["NX", "NY", "NZ"])]
        cells: Option<Vec<usize>>,
    },
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Bench {
            what:
                BenchTarget::Fem {
                    json,
                    repeats,
                    cells,
                },
        } => {
            let cells = cells.map_or(bench::fem::LIVER_SIZED_CELLS, |c| [c[0], c[1], c[2]]);
            match bench::fem::run(cells, repeats) {
                Ok(report) if json => {
                    println!(
                        "{}",
                        serde_json::to_string_pretty(&report).expect("plain data serializes")
                    );
                    ExitCode::SUCCESS
                }
                Ok(report) => {
                    print!("{report}");
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("pgd bench fem: {e}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}
