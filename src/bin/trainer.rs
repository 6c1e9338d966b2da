//! `trainer`: the surgical trainee's application.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use pgd_surgery::app::scene::Detail;
use pgd_surgery::app::window::ScreenshotPlan;
use pgd_surgery::app::{self, session};
use pgd_surgery::cli::OnStale;
use pgd_surgery::haptics::{DeviceSpec, TimerMode};

#[derive(Parser)]
#[command(
    name = "trainer",
    version,
    about = "Real-time surgery trainer: organs deform under a haptic tool through PGD vademecums"
)]
struct Cli {
    /// Run the haptic loop without a window and print a summary.
    #[arg(long)]
    headless: bool,
    /// The haptic device: `scripted:FILE` replays a trajectory CSV (time_s,x_m,y_m,z_m,buttons);
    /// `virtual` is the mouse. Headless default: a built-in press-and-slide on every organ.
    #[arg(long)]
    device: Option<DeviceSpec>,
    /// Record what the device reports to this trajectory file (replayable with scripted:FILE).
    #[arg(long)]
    record: Option<PathBuf>,
    /// Headless: ticks to run (default: the script's length plus 100 ms).
    #[arg(long)]
    ticks: Option<u64>,
    /// Print the summary (headless) or the haptic timing report (window) as JSON.
    #[arg(long)]
    json: bool,
    /// Headless: tick on the real clock (1 kHz on a thread of its own) instead of a simulated
    /// one, and report how well it kept time.
    #[arg(long)]
    realtime: bool,
    /// Real-time pacing: `hybrid` sleeps then spins to the deadline, `sleep` only sleeps.
    #[arg(long, default_value = "hybrid", value_parser = parse_timer)]
    timer: TimerMode,
    /// The largest force (N) sent to the device (also capped by the device's own limit).
    #[arg(long, default_value_t = 3.3)]
    max_force_n: f64,
    /// Close the window after this many seconds and report how the haptic loop kept time
    /// while the renderer ran.
    #[arg(long)]
    exit_after_s: Option<f64>,
    /// Save the window to this PNG after `--frames` frames, then close it.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Frames to draw before the screenshot.
    #[arg(long, default_value_t = 30)]
    frames: u32,
    /// Where the organs' vademecums are kept.
    #[arg(long, default_value = "vademecums")]
    vademecums: PathBuf,
    /// Coarse organs (a quarter of the nodes, a 12 mm tool): their vademecums build in
    /// seconds. For a quick look on a slow machine, and for tests.
    #[arg(long)]
    coarse: bool,
    /// Fail (with the command to run) instead of rebuilding a missing or stale vademecum.
    #[arg(long)]
    no_rebuild: bool,
}

fn parse_timer(s: &str) -> Result<TimerMode, String> {
    match s {
        "sleep" => Ok(TimerMode::Sleep),
        "hybrid" => Ok(TimerMode::default()),
        _ => Err(format!("unknown timer `{s}`: expected `hybrid` or `sleep`")),
    }
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
    let realtime = match cli.headless {
        true => cli.realtime.then_some(cli.timer),
        false => Some(cli.timer),
    };
    let options = session::Options {
        vademecums: cli.vademecums.clone(),
        detail: match cli.coarse {
            true => Detail::Coarse,
            false => Detail::Full,
        },
        on_stale,
        device: cli.device.clone(),
        record: cli.record.clone(),
        ticks: cli.ticks,
        realtime,
        max_force_n: cli.max_force_n,
    };
    let result = match cli.headless {
        true => session::run_headless(&options),
        false => {
            let screenshot = cli.screenshot.clone().map(|path| ScreenshotPlan {
                path,
                after_frames: cli.frames.max(1),
            });
            session::open_window(&options, cli.exit_after_s, screenshot)
        }
    };
    match result {
        Ok(report) => {
            report.print(cli.json);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("trainer: {e}");
            ExitCode::FAILURE
        }
    }
}
