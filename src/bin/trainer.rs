//! `trainer`: the surgical trainee's application.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pgd_surgery::app::{self, PressedSlab};
use pgd_surgery::cli::{self, OnStale};
use pgd_surgery::fem::Law;
use pgd_surgery::mesh::organs::Organ;

#[derive(Parser)]
#[command(
    name = "trainer",
    version,
    about = "Real-time surgery trainer: organs deform under a haptic tool through PGD vademecums"
)]
struct Cli {
    /// Run without a window: solve the default scene and print a summary.
    #[arg(long)]
    headless: bool,
    /// Where the organs' vademecums are kept.
    #[arg(long, default_value = "vademecums")]
    vademecums: PathBuf,
    /// Fail (with the command to run) instead of rebuilding a missing or stale vademecum.
    #[arg(long)]
    no_rebuild: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if !cli.headless
        && let Some(why) = app::missing_display()
    {
        eprintln!(
            "trainer: cannot open a window: {why}.\n\
             Run `cargo run --release -- --headless` to run without a window, or start an X server \
             (for example `Xvfb :99 & DISPLAY=:99 cargo run --release`)."
        );
        return ExitCode::from(2);
    }
    let on_stale = if cli.no_rebuild {
        OnStale::Refuse
    } else {
        OnStale::Rebuild
    };
    match cli::ensure_vademecum(&cli.vademecums, Organ::Liver, Law::Linear, on_stale) {
        Ok(vademecum) => println!(
            "liver vademecum: {} load positions, {} modes, built in {:.0} s",
            vademecum.positions.len(),
            vademecum.modes(0),
            vademecum.header.build_seconds
        ),
        Err(e) => {
            eprintln!("trainer: {e}");
            return ExitCode::FAILURE;
        }
    }
    let scene = match PressedSlab::solve() {
        Ok(scene) => scene,
        Err(e) => {
            eprintln!("trainer: the default scene could not be solved: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!("{}", scene.summary());
    if cli.headless {
        return ExitCode::SUCCESS;
    }
    match app::run_window(scene) {
        bevy::app::AppExit::Success => ExitCode::SUCCESS,
        bevy::app::AppExit::Error(code) => ExitCode::from(code.get()),
    }
}
