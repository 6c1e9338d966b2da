//! `trainer`: the surgical trainee's application.

use std::process::ExitCode;

use clap::Parser;
use pgd_surgery::app::{self, PressedSlab};

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
