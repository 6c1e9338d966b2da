//! `pgd`: offline work — organ meshes, benchmarks; vademecum builds and validation to come.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use pgd_surgery::bench;
use pgd_surgery::mesh::io::{ImportOptions, load, write_vtu};
use pgd_surgery::mesh::organs::{self, Organ, OrganSettings};
use pgd_surgery::mesh::{QualityReport, TetMesh};

#[derive(Parser)]
#[command(
    name = "pgd",
    version,
    about = "Offline tools of the PGD surgery trainer: organ meshes and benchmarks of the numerical core"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Generate an organ (liver, gallbladder, pancreas, duodenum, cornea) or read a mesh file
    /// (.msh, .vtk, .vtu, or a closed .obj/.stl surface, which is tetrahedralized), and print
    /// its statistics and quality report. Exits with status 1 if the mesh cannot be simulated.
    Mesh {
        /// An organ name or a mesh file.
        source: String,
        /// Also write the mesh (with its regions) as .vtu for ParaView.
        #[arg(long, value_name = "FILE.vtu")]
        out: Option<PathBuf>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
        /// Organs: multiplies the node count (1 = the papers' sizes).
        #[arg(long, default_value_t = 1.0)]
        resolution: f64,
        /// Organs: varies proportions deterministically (another patient).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Files: multiplies coordinates (0.001 for files in millimetres).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Surfaces (.obj, .stl): target node count of the tetrahedralization.
        #[arg(long, default_value_t = 4000)]
        nodes: usize,
    },
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
        Command::Mesh {
            source,
            out,
            json,
            resolution,
            seed,
            scale,
            nodes,
        } => {
            let mesh = match Organ::from_name(&source) {
                Some(organ) => organs::generate(organ, &OrganSettings { resolution, seed })
                    .map_err(|e| e.to_string()),
                None => load(
                    Path::new(&source),
                    &ImportOptions {
                        scale,
                        surface_nodes: nodes,
                    },
                )
                .map_err(|e| e.to_string()),
            };
            match mesh {
                Ok(mesh) => report_mesh(&source, &mesh, out.as_deref(), json),
                Err(e) => fail("pgd mesh", &e),
            }
        }
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
                Ok(report) if json => print_json(&report),
                Ok(report) => {
                    print!("{report}");
                    ExitCode::SUCCESS
                }
                Err(e) => fail("pgd bench fem", &e.to_string()),
            }
        }
    }
}

/// Prints a mesh's statistics, regions and quality, writes it if asked, and fails if the mesh
/// cannot be simulated.
fn report_mesh(source: &str, mesh: &TetMesh, out: Option<&Path>, json: bool) -> ExitCode {
    let report = QualityReport::measure(mesh.nodes(), mesh.tets());
    let regions = mesh.regions();
    if json {
        print_json(&serde_json::json!({
            "source": source,
            "quality": report,
            "usable": report.refusal().is_none(),
            "node_sets": regions.node_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
            "face_sets": regions.face_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
        }));
    } else {
        println!("{source}\n{report}");
        for (name, nodes) in &regions.node_sets {
            println!("  node set {name}: {} nodes", nodes.len());
        }
        for (name, faces) in &regions.face_sets {
            println!("  face set {name}: {} faces", faces.len());
        }
    }
    if let Some(path) = out {
        if let Err(e) = write_vtu(path, mesh, &[]) {
            return fail("pgd mesh", &format!("{}: {e}", path.display()));
        }
        if !json {
            println!("wrote {}", path.display());
        }
    }
    if report.refusal().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

fn print_json(value: &impl serde::Serialize) -> ExitCode {
    println!(
        "{}",
        serde_json::to_string_pretty(value).expect("plain data serializes")
    );
    ExitCode::SUCCESS
}

fn fail(command: &str, message: &str) -> ExitCode {
    eprintln!("{command}: {message}");
    ExitCode::FAILURE
}
