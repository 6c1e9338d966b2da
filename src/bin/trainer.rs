//! `trainer`: the surgical trainee's application.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use pgd_surgery::app::launch::WindowLesson;
use pgd_surgery::app::scene::Detail;
use pgd_surgery::app::soak::SoakPlan;
use pgd_surgery::app::window::{Opening, ScreenshotPlan};
use pgd_surgery::app::{self, DEFAULT_SCENARIO, launch};
use pgd_surgery::cli::{
    CohortRequest, HistoryRequest, HistoryTarget, debrief, list_devices, menu_curriculum, numbered,
    parse_force_limit_n, parse_positive_seconds, parse_seconds, prepare_scenarios, run_soak,
    show_cohort, show_history, show_standing, validate_scenarios,
};
use pgd_surgery::devices::{DeviceSpec, TimerMode};
use pgd_surgery::history::{HistoryFilter, Store, TrainerConfig, machine_name};
use pgd_surgery::scenario::{self, Scenario};
use pgd_surgery::store::OnStale;

#[derive(Parser)]
#[command(
    name = "trainer",
    version,
    about = "Real-time surgery trainer: organs deform under a haptic tool through PGD vademecums"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Run the haptic loop without a window and print a summary.
    #[arg(long, global = true)]
    headless: bool,
    /// The haptic device: `scripted:FILE` replays a trajectory CSV (time_s,x_m,y_m,z_m,buttons);
    /// `virtual` is the mouse; `openhaptics[:NAME]` a Geomagic Touch, `forcedimension[:INDEX]`
    /// an omega, sigma or delta (INDEX in the SDK's list, 0 first) (their vendor libraries loaded at run time; `trainer devices` says what
    /// is found). Headless default: a built-in press-and-slide on every organ. In a bimanual
    /// scenario this is the right hand's, and a `scripted:FILE` with the left hand's columns
    /// (`left_x_m`…) drives both hands.
    #[arg(long, global = true)]
    device: Option<DeviceSpec>,
    /// A bimanual scenario's left-hand device, named as --device names it (two Geomagic
    /// devices by their configuration names, `openhaptics:LEFT`, two Force Dimension devices
    /// by index, `forcedimension:1`, or one of each backend).
    /// Default: the scenario's `left_backend`, else the mouse (H hands it between the hands).
    #[arg(long, global = true)]
    left_device: Option<DeviceSpec>,
    /// Record what the device reports to this trajectory file (replayable with scripted:FILE).
    #[arg(long, global = true)]
    record: Option<PathBuf>,
    /// Headless: ticks to run (default: the script's length plus 100 ms).
    #[arg(long, global = true)]
    ticks: Option<u64>,
    /// Print the summary (headless) or the haptic timing report (window) as JSON.
    #[arg(long, global = true)]
    json: bool,
    /// Headless: tick on the real clock (1 kHz on a thread of its own) instead of a simulated
    /// one, and report how well it kept time.
    #[arg(long, global = true)]
    realtime: bool,
    /// Real-time pacing: `hybrid` sleeps then spins to the deadline, `sleep` only sleeps.
    #[arg(long, global = true, default_value = "hybrid", value_parser = parse_timer)]
    timer: TimerMode,
    /// The largest force (N) sent to the device, 0 to 20 (also capped by the device's own
    /// limit).
    #[arg(long, global = true, default_value = "3.3", value_parser = parse_force_limit_n)]
    max_force_n: f64,
    /// Close the window after this many seconds and report how the haptic loop kept time
    /// while the renderer ran.
    #[arg(long, global = true, value_parser = parse_positive_seconds)]
    exit_after_s: Option<f64>,
    /// Save the window to this PNG after `--frames` frames, then close it.
    #[arg(long, global = true)]
    screenshot: Option<PathBuf>,
    /// Frames to draw before the screenshot.
    #[arg(long, global = true, default_value_t = 30)]
    frames: u32,
    /// Nor take the screenshot before the haptic loop has run this many seconds (a scripted
    /// device's trajectory played that far, however fast the frames come).
    #[arg(long, global = true, default_value = "0", value_parser = parse_seconds)]
    screenshot_after_s: f64,
    /// Where the organs' vademecums are kept.
    #[arg(long, global = true, default_value = "vademecums")]
    vademecums: PathBuf,
    /// Coarse organs (a quarter of the nodes, a 12 mm tool): their vademecums build in
    /// minutes. For a quick look on a slow machine, and for tests.
    #[arg(long, global = true)]
    coarse: bool,
    /// Fail (with the command to run) instead of rebuilding a missing or stale vademecum.
    #[arg(long, global = true)]
    no_rebuild: bool,
    /// Who is training: each scored attempt is kept under this name (default: the login
    /// name); with `history`, only this trainee's attempts are listed.
    #[arg(long, global = true)]
    trainee: Option<String>,
    /// Where every scored attempt is kept: a SQLite file, or a programme's PostgreSQL
    /// database, postgres://USER@HOST/DATABASE (docs/programme.md). Default: the configuration
    /// file's `history`, else reports/history.sqlite.
    #[arg(long, global = true)]
    history: Option<String>,
    /// The configuration file (default: the one PGD_TRAINER_CONFIG names, else
    /// ~/.config/pgd-surgery/trainer.ron or /etc/pgd-surgery/trainer.ron if there is one).
    #[arg(long, global = true)]
    config: Option<PathBuf>,
    /// The window's menu offers this curriculum's exercises in its order, module by module,
    /// each marked had or locked for --trainee (from --history); a locked one is refused.
    #[arg(long)]
    curriculum: Option<PathBuf>,
    /// The window without an exercise: the organs and the tool only (by default the window
    /// opens the menu of scenarios/, the built-in scenarios/liver-steady-press.scenario.ron
    /// chosen).
    #[arg(long)]
    free_play: bool,
    /// Open a laparoscopic scenario with the free camera instead of the laparoscope (C
    /// switches between them in the window).
    #[arg(long, global = true)]
    free_camera: bool,
    /// Render into an image instead of a window: no X server needed (with --frames and
    /// --screenshot for a picture, --exit-after-s for the frame time).
    #[arg(long, global = true)]
    offscreen: bool,
    /// The offscreen image's size, WIDTHxHEIGHT in pixels.
    #[arg(long, global = true, default_value = "1280x720", value_parser = parse_size)]
    size: (u32, u32),
}

const DEFAULT_REPORT_DIR: &str = "reports";

#[derive(Subcommand)]
enum Command {
    /// Run the exercise a scenario file describes and score it (in the window, or with
    /// --headless on a scripted device).
    Run {
        /// The scenario, e.g. scenarios/liver-steady-press.scenario.ron.
        file: PathBuf,
        /// Where the attempt's report goes (JSON, a summary, a force plot).
        #[arg(long, default_value = "reports")]
        report_dir: PathBuf,
    },
    /// Where a trainee (--trainee, default the login name) stands in a curriculum: each
    /// module done, open or locked, each exercise's attempts and best score against its
    /// proficiency rule, from the history (--history).
    Curriculum {
        /// The curriculum, e.g. curricula/cholecystectomy.curriculum.ron.
        file: PathBuf,
    },
    /// Check scenario files (and curricula, `….curriculum.ron`, with every scenario they
    /// name) without running them; every problem is printed with its file, line, column and
    /// field.
    Validate {
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Build the vademecums (and distance fields) the scenario files need, where missing or
    /// stale, and list their files: for a class, or (with --web) for the web page's site.
    Prepare {
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Also write their web forms (`<file>.web`: response values rounded, deflated) into
        /// this folder, with their sizes and how much the felt force changes.
        #[arg(long)]
        web: Option<PathBuf>,
    },
    /// List the haptic device backends, which of them can be used on this machine, and why
    /// the others cannot.
    Devices,
    /// An hour of use on the simulated clock: every shipped one-hand scenario in turn, attempted
    /// carelessly then competently by its scripted runs, each attempt scored and kept; reports
    /// the resident memory (every simulated minute, and its growth per attempt), the tick
    /// times at the start and the end, the forces' NaNs, largest steps and faults (with --json
    /// as JSON).
    Soak {
        /// Simulated seconds of use.
        #[arg(long, default_value = "3600", value_parser = parse_positive_seconds)]
        duration_s: f64,
        /// The history database the soak's attempts are kept in, apart from the trainees'.
        #[arg(long, default_value = "reports/soak-history.sqlite")]
        keep_in: PathBuf,
        /// Also plot the resident memory, sampled every simulated minute, into this PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Only this shipped scenario, over and over (`scenarios/NAME.scenario.ron`): its
        /// memory per attempt then shows a leak within a minute.
        #[arg(long)]
        scenario: Option<String>,
    },
    /// The attempts kept so far (all, or --trainee's), as a table and a learning-curve plot,
    /// or as CSV.
    History {
        /// Only the attempts at this scenario file (as it was given to `run`).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Print CSV (one row per attempt) instead of the table and the plot.
        #[arg(long)]
        csv: bool,
        /// Where the learning-curve plot goes.
        #[arg(long, default_value = "reports/learning-curve.png")]
        plot: PathBuf,
        /// The programme's view: every trainee's standing in the curriculum (--curriculum) as
        /// a table, and their learning curves (--plot, and its numbers beside it as CSV).
        #[arg(long, requires = "curriculum", conflicts_with_all = ["csv", "scenario"])]
        cohort: bool,
        /// The curriculum the cohort's standing is read against.
        #[arg(long)]
        curriculum: Option<PathBuf>,
        /// With --cohort: only these trainees (a group: names separated by commas).
        #[arg(long, value_delimiter = ',', requires = "cohort")]
        group: Vec<String>,
    },
}

fn detail_of(cli: &Cli) -> Detail {
    match cli.coarse {
        true => Detail::Coarse,
        false => Detail::Full,
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let parsed = s
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if (16..=8192).contains(&w) && (16..=8192).contains(&h) => Ok((w, h)),
        _ => Err(format!(
            "`{s}` is not a size: WIDTHxHEIGHT in pixels, each 16 to 8192 (e.g. 1920x1080)"
        )),
    }
}

fn parse_timer(s: &str) -> Result<TimerMode, String> {
    match s {
        "sleep" => Ok(TimerMode::Sleep),
        "hybrid" => Ok(TimerMode::default()),
        _ => Err(format!("unknown timer `{s}`: expected `hybrid` or `sleep`")),
    }
}

/// Set (to anything), `trainer soak` leaks each attempt's haptic world: a defect planted so
/// that the tests can show the soak's growth check failing on a leak.
const PLANT_LEAK: &str = "PGD_SOAK_PLANT_LEAK";

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Before any device opens: a panic or a signal from here on releases it at zero force.
    if let Err(e) = launch::install_exit_guards() {
        eprintln!("trainer: {e}; a device is still zeroed by its watchdog if the trainer dies");
    }
    let history = match history_target(&cli) {
        Ok(history) => history,
        Err(e) => {
            eprintln!("trainer: {e}");
            return ExitCode::from(2);
        }
    };
    if let Some(code) = run_command(&cli, &history) {
        return code;
    }
    if !cli.headless
        && !cli.offscreen
        && let Some(why) = app::missing_display()
    {
        eprintln!(
            "trainer: cannot open a window: {why}.\n\
             Run `cargo run --release -- --headless` to run without a window, or start an X server \
             (for example `Xvfb :99 & DISPLAY=:99 cargo run --release`)."
        );
        return ExitCode::from(2);
    }
    let mut options = launch_options(&cli);
    if let Some(file) = &cli.curriculum {
        match menu_curriculum(file, &history.store, &history.trainee) {
            Ok(curriculum) => options.curriculum = Some(curriculum),
            Err(e) => {
                eprintln!("{e}");
                return ExitCode::FAILURE;
            }
        }
    }
    let exercise = match chosen_exercise(&cli) {
        Ok(exercise) => exercise,
        Err(code) => return code,
    };
    if cli.headless {
        return match exercise {
            Some(chosen) => {
                let outcome = launch::run_scenario_headless(&options, chosen.scenario);
                debrief(
                    outcome,
                    chosen.file,
                    None,
                    chosen.report_dir,
                    cli.json,
                    &history,
                )
            }
            None => finish(launch::run_headless(&options), cli.json),
        };
    }
    run_window(&cli, &options, exercise, &history)
}

/// Where attempts are kept (the command line's `--history`, else the configuration file's,
/// else reports/history.sqlite), whose they are and the station's name.
fn history_target(cli: &Cli) -> Result<HistoryTarget, String> {
    let config = match &cli.config {
        Some(file) => TrainerConfig::load(file)?,
        None => TrainerConfig::find()?.0,
    };
    let local = (config.local_history.clone()).unwrap_or_else(|| DEFAULT_HISTORY.into());
    let history = (cli.history.clone())
        .or(config.history)
        .unwrap_or_else(|| local.display().to_string());
    Ok(HistoryTarget {
        store: Store::of(&history, &local),
        trainee: cli.trainee.clone().unwrap_or_else(login_name),
        station: config.station.unwrap_or_else(machine_name),
    })
}

/// The station's own history when nothing names another.
const DEFAULT_HISTORY: &str = "reports/history.sqlite";

/// The commands that are not a run of the trainer (validate, prepare, devices, soak,
/// history): their exit code, or `None` for a run.
fn run_command(cli: &Cli, history: &HistoryTarget) -> Option<ExitCode> {
    Some(match cli.command.as_ref()? {
        Command::Validate { files } => validate_scenarios(files),
        Command::Curriculum { file } => show_standing(file, &history.store, &history.trainee),
        Command::Prepare { files, web } => {
            prepare_scenarios(files, &cli.vademecums, detail_of(cli), web.as_deref())
        }
        Command::Devices => list_devices(),
        Command::Soak {
            duration_s,
            keep_in,
            plot,
            scenario,
        } => run_soak(
            &SoakPlan {
                duration_s: *duration_s,
                vademecums: cli.vademecums.clone(),
                detail: detail_of(cli),
                history: keep_in.clone(),
                trainee: cli.trainee.clone().unwrap_or_else(|| "soak".into()),
                leak_each_attempt: std::env::var_os(PLANT_LEAK).is_some(),
                only: scenario.clone(),
            },
            cli.json,
            plot.as_deref(),
        ),
        Command::History {
            cohort: true,
            curriculum: Some(curriculum),
            plot,
            group,
            ..
        } => show_cohort(&CohortRequest {
            store: &history.store,
            curriculum,
            plot,
            group,
        }),
        Command::History {
            scenario,
            csv,
            plot,
            ..
        } => show_history(&HistoryRequest {
            store: &history.store,
            filter: HistoryFilter {
                trainee: cli.trainee.clone(),
                scenario: scenario.as_ref().map(|s| s.display().to_string()),
            },
            csv: *csv,
            plot,
        }),
        Command::Run { .. } => return None,
    })
}

/// How the trainer runs, from the command line.
fn launch_options(cli: &Cli) -> launch::Options {
    // The window opens at once on a first run: nonlinear tissue comes as its vademecums are
    // built in the background. A headless run builds them first, to be the same every time.
    let on_stale = match (cli.no_rebuild, cli.headless) {
        (true, _) => OnStale::Refuse,
        (false, true) => OnStale::Rebuild,
        (false, false) => OnStale::Meanwhile,
    };
    let realtime = match cli.headless {
        true => cli.realtime.then_some(cli.timer),
        false => Some(cli.timer),
    };
    launch::Options {
        vademecums: cli.vademecums.clone(),
        detail: detail_of(cli),
        on_stale,
        device: cli.device.clone(),
        left_device: cli.left_device.clone(),
        record: cli.record.clone(),
        ticks: cli.ticks,
        realtime,
        max_force_n: cli.max_force_n,
        free_camera: cli.free_camera,
        offscreen: cli.offscreen.then_some(cli.size),
        curriculum: None,
    }
}

/// The scenario a run opens, its file, and where its reports go.
struct Chosen<'a> {
    scenario: Scenario,
    file: &'a Path,
    report_dir: &'a Path,
}

/// The scenario to run: `trainer run FILE`'s, none for free play or a headless run without
/// one, else the built-in one. The exit code when it does not read.
fn chosen_exercise(cli: &Cli) -> Result<Option<Chosen<'_>>, ExitCode> {
    match &cli.command {
        Some(Command::Run { file, report_dir }) => match scenario::load(file) {
            Ok(scenario) => Ok(Some(Chosen {
                scenario,
                file,
                report_dir,
            })),
            Err(e) => {
                eprintln!("{e}");
                Err(ExitCode::from(2))
            }
        },
        _ if cli.headless || cli.free_play => Ok(None),
        _ => match scenario::parse(Path::new(DEFAULT_SCENARIO.0), DEFAULT_SCENARIO.1) {
            Ok(scenario) => Ok(Some(Chosen {
                scenario,
                file: Path::new(DEFAULT_SCENARIO.0),
                report_dir: Path::new(DEFAULT_REPORT_DIR),
            })),
            Err(e) => {
                eprintln!("trainer: the built-in scenario does not read: {e}");
                Err(ExitCode::FAILURE)
            }
        },
    }
}

/// Opens the window on the exercise (or free play), then debriefs every attempt made.
fn run_window(
    cli: &Cli,
    options: &launch::Options,
    exercise: Option<Chosen<'_>>,
    history: &HistoryTarget,
) -> ExitCode {
    let screenshot = cli.screenshot.clone().map(|path| ScreenshotPlan {
        path,
        after_frames: cli.frames.max(1),
        after_haptic_s: cli.screenshot_after_s,
    });
    // `trainer run FILE` opens FILE's briefing, its menu offering FILE's folder; the plain
    // trainer opens the menu of `scenarios/`, the built-in scenario chosen.
    let run_file = matches!(cli.command, Some(Command::Run { .. }));
    let report_dir = exercise
        .as_ref()
        .map(|chosen| chosen.report_dir.to_path_buf());
    let lesson = exercise.map(|Chosen { scenario, file, .. }| WindowLesson {
        scenario,
        file: file.to_owned(),
        opening: match run_file {
            true => Opening::Lesson,
            false => Opening::Menu,
        },
        folder: Some(file.parent().unwrap_or(Path::new(".")).to_owned())
            .filter(|folder| folder.is_dir()),
    });
    let (report, attempts) =
        match launch::open_window(options, cli.exit_after_s, screenshot, lesson) {
            Ok(ran) => ran,
            Err(e) => return finish(Err(e), cli.json),
        };
    match report_dir {
        Some(dir) if !attempts.is_empty() => {
            // With --json, stdout carries the scorecards alone.
            if !cli.json {
                report.print(false);
            }
            let codes: Vec<ExitCode> = numbered(attempts)
                .into_iter()
                .map(|(file, attempt, outcome)| {
                    debrief(Ok(outcome), &file, attempt, &dir, cli.json, history)
                })
                .collect();
            codes
                .into_iter()
                .find(|code| *code != ExitCode::SUCCESS)
                .unwrap_or(ExitCode::SUCCESS)
        }
        Some(_) => {
            eprintln!(
                "trainer: no exercise was begun (Space on a briefing begins it): nothing scored, no report"
            );
            finish(Ok(report), cli.json)
        }
        None => finish(Ok(report), cli.json),
    }
}

/// Whom an attempt is kept under when `--trainee` does not say: the login name.
fn login_name() -> String {
    std::env::var("USER")
        .ok()
        .filter(|u| !u.is_empty())
        .unwrap_or_else(|| "trainee".into())
}

fn finish(result: Result<launch::Report, String>, json: bool) -> ExitCode {
    match result {
        Ok(report) => {
            report.print(json);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("trainer: {e}");
            ExitCode::FAILURE
        }
    }
}
