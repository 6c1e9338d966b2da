//! The trainer's rendering, run as a user runs it, on the coarse organs with Mesa's software
//! Vulkan (`scripts/setup-debian.sh` installs it): drawn offscreen (`--offscreen`, no X
//! server), two screenshots — the tool held away, then pressing the liver — are checked
//! against the legends the trainer writes beside them: each organ's tissue colour shows where
//! its surface is in sight, and the pressed frame differs from the rest frame around the tool
//! and nowhere far from it. The window itself, under Xvfb, is not blank. A missing display is
//! reported plainly, without a panic. Closing the window, and SIGINT, release a hardware
//! device (the fake HD library) at zero force. The laparoscopic view, the keratotomy's view of the
//! cornea and an open incision are checked on their own shipped scenarios, and every shipped
//! scenario's start shows its organs.

#[path = "../../crates/pgd-surgery-core/tests/support/cache.rs"]
mod cache;
mod closing;
mod cornea;
mod incision;
mod laparoscope;
mod scenarios;
mod text;
// The haptics tests' fakes; these tests only load one into the trainer, not its controls.
#[allow(dead_code)]
#[path = "../haptics/vendor_fake.rs"]
mod vendor_fake;
mod xvfb;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use nalgebra::Vector3;
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::scene::{Detail, default_scene, press_targets};
use pgd_surgery::app::window::Legend;
use pgd_surgery::app::window::tissue::{mean_srgb, tissue};
use pgd_surgery::devices::{DeviceSample, Trajectory, TrajectoryRow};
use pgd_surgery::scenario::load;
use pgd_surgery::store::OnStale;

const TRAINER: &str = env!("CARGO_BIN_EXE_trainer");
/// How deep the tool presses into the liver (m).
const PRESS_DEPTH_M: f64 = 0.008;
/// Frames drawn before the screenshot: the scripted press is complete within the first second.
const FRAMES: &str = "12";

/// The coarse vademecums, built once for all tests here.
fn vademecums() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // The scenario tests' organs: the coarse nonlinear organs are built once for both.
        let dir = cache::vademecum_cache().to_owned();
        default_scene(&dir, Detail::Coarse, OnStale::Rebuild).unwrap();
        dir
    })
}

struct Shot {
    width: usize,
    rgb: Vec<u8>,
    legend: Legend,
}

impl Shot {
    /// The mean colour of the 5×5 pixels around `px`.
    fn colour_at(&self, px: [f32; 2]) -> [f32; 3] {
        let height = self.rgb.len() / 3 / self.width;
        let (x, y) = (px[0].round() as i64, px[1].round() as i64);
        let mut sum = [0.0; 3];
        let mut count = 0.0_f32;
        for j in y - 2..=y + 2 {
            for i in x - 2..=x + 2 {
                if i < 0 || j < 0 || i as usize >= self.width || j as usize >= height {
                    continue;
                }
                let at = (j as usize * self.width + i as usize) * 3;
                for (total, &value) in sum.iter_mut().zip(&self.rgb[at..at + 3]) {
                    *total += value as f32;
                }
                count += 1.0;
            }
        }
        sum.map(|s| s / count.max(1.0))
    }
}

/// Runs the trainer offscreen in free play with a scripted device that holds the tool along
/// `rows`, and reads back its screenshot and legend.
fn screenshot(name: &str, rows: Vec<TrajectoryRow>) -> Shot {
    shot_of(
        name,
        rows,
        &["--free-play", "--frames", FRAMES],
        Surface::Offscreen,
    )
}

/// Where the trainer draws.
#[derive(Clone, Copy)]
enum Surface {
    Offscreen,
    /// A window on a private Xvfb.
    Window,
}

/// Runs the trainer with `args` on the coarse organs and a scripted device that holds the tool
/// along `rows`, drawing on `surface`, and reads back its screenshot (`<name>.png`) and legend.
fn shot_of(name: &str, rows: Vec<TrajectoryRow>, args: &[&str], surface: Surface) -> Shot {
    let server = matches!(surface, Surface::Window).then(xvfb::Xvfb::start);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join(format!("{name}.csv"));
    Trajectory { rows }.save(&script).unwrap();
    let png = dir.join(format!("{name}.png"));
    let mut command = Command::new(TRAINER);
    command
        .args(args)
        .args(["--coarse", "--no-rebuild"])
        .arg("--vademecums")
        .arg(vademecums())
        .arg("--device")
        .arg(format!("scripted:{}", script.display()))
        .arg("--screenshot")
        .arg(&png);
    match &server {
        Some(server) => command.env("DISPLAY", &server.display),
        None => command
            .arg("--offscreen")
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY"),
    };
    let output = command.output().unwrap();
    drop(server);
    assert_ran(&output);
    let legend = std::fs::read_to_string(png.with_extension("json")).unwrap();
    let (width, rgb) = read_rgb(&png);
    Shot {
        width,
        rgb,
        legend: serde_json::from_str(&legend).unwrap(),
    }
}

/// Runs the scenario in `file` offscreen for `frames` frames (its coarse vademecums built
/// first) with a scripted device held along `rows`, its attempts kept in a history of their
/// own, and reads back its screenshot.
fn scenario_shot(name: &str, file: &Path, frames: u32, rows: Vec<TrajectoryRow>) -> Shot {
    scenario_shot_after(name, file, (frames, 0.0), rows)
}

/// [`scenario_shot`] taken no sooner than `after_s` seconds into the scripted trajectory.
fn scenario_shot_after(
    name: &str,
    file: &Path,
    (frames, after_s): (u32, f64),
    rows: Vec<TrajectoryRow>,
) -> Shot {
    let scenario = load(file).unwrap();
    scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Rebuild).unwrap();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
    std::fs::create_dir_all(&dir).unwrap();
    let history = dir.join(format!("{name}-history.sqlite"));
    let (frames, after_s) = (frames.to_string(), after_s.to_string());
    let args = [
        "run",
        file.to_str().unwrap(),
        "--frames",
        &frames,
        "--screenshot-after-s",
        &after_s,
        "--history",
        history.to_str().unwrap(),
    ];
    shot_of(name, rows, &args, Surface::Offscreen)
}

fn assert_ran(output: &Output) {
    assert!(
        output.status.success(),
        "trainer failed ({}):\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
}

fn read_rgb(path: &Path) -> (usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buffer).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
    buffer.truncate(info.buffer_size());
    (info.width as usize, buffer)
}

/// The liver's most anterior point and its outward normal (where the built-in demo presses).
fn liver_target() -> (Vector3<f64>, Vector3<f64>) {
    let scene = default_scene(vademecums(), Detail::Coarse, OnStale::Refuse).unwrap();
    let target = press_targets(&scene)[0];
    (target.point_m, target.normal)
}

fn held_at(tip_m: Vector3<f64>) -> Vec<TrajectoryRow> {
    [0.0, 600.0].map(|time_s| row(time_s, tip_m)).to_vec()
}

fn row(time_s: f64, tip_m: Vector3<f64>) -> TrajectoryRow {
    TrajectoryRow::new(time_s, &DeviceSample::at(tip_m))
}

/// The tool beside the scene, touching nothing; then pressing the liver 8 mm deep.
fn rest_and_press() -> &'static (Shot, Shot) {
    static SHOTS: OnceLock<(Shot, Shot)> = OnceLock::new();
    SHOTS.get_or_init(|| {
        let (point, normal) = liver_target();
        let radius_m = Detail::Coarse.tip_radius_m();
        let rest = screenshot("rest", held_at(point + Vector3::new(0.3, 0.0, 0.0)));
        let above = point + normal * 0.05;
        let pressed = point + normal * (radius_m - PRESS_DEPTH_M);
        let press = [row(0.0, above), row(0.5, pressed), row(600.0, pressed)].to_vec();
        (rest, screenshot("press", press))
    })
}

/// Hue (degrees) and saturation (HSV) of an RGB colour.
fn hue_saturation(c: [f32; 3]) -> (f32, f32) {
    let max = c[0].max(c[1]).max(c[2]);
    let min = c[0].min(c[1]).min(c[2]);
    let range = max - min;
    if range <= 0.0 {
        return (0.0, 0.0);
    }
    let sector = if max == c[0] {
        ((c[1] - c[2]) / range).rem_euclid(6.0)
    } else if max == c[1] {
        (c[2] - c[0]) / range + 2.0
    } else {
        (c[0] - c[1]) / range + 4.0
    };
    (60.0 * sector, range / max)
}

fn hue_distance(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

/// Pixels this grey carry no hue to tell tissues by (specular highlights, the background).
const MIN_SATURATION: f32 = 0.15;

fn distance(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>().sqrt()
}

/// Legend pixels not under the HUD's lines of text (top left).
fn clear_of_hud(px: &[f32; 2]) -> bool {
    !(px[1] < 150.0 && px[0] < 720.0)
}

#[test]
fn the_window_is_not_blank() {
    let (point, _) = liver_target();
    let rest = shot_of(
        "window",
        held_at(point + Vector3::new(0.3, 0.0, 0.0)),
        &["--free-play", "--frames", FRAMES],
        Surface::Window,
    );
    let background = rest.colour_at([2.0, rest.rgb.len() as f32 / 3.0 / rest.width as f32 - 3.0]);
    let pixels = rest.rgb.len() / 3;
    let drawn = rest
        .rgb
        .chunks(3)
        .filter(|p| distance([p[0], p[1], p[2]].map(f32::from), background) > 30.0)
        .count();
    let fraction = drawn as f64 / pixels as f64;
    assert!(
        fraction > 0.10,
        "only {:.1} % of the image is drawn",
        100.0 * fraction
    );
}

/// Where the legend says an organ's surface is in sight, the image shows that organ's tissue:
/// of the pixels with a hue (highlights are white), at least three in four are nearer in hue
/// to its own tissue than to any other organ's. Lighting and tone mapping change brightness
/// and saturation; hue is what survives them.
#[test]
fn each_organ_shows_its_colour_where_it_is() {
    let (rest, _) = rest_and_press();
    let references: Vec<f32> = rest
        .legend
        .organs
        .iter()
        .map(|o| hue_saturation(mean_srgb(&tissue(&o.name)).map(f32::from)).0)
        .collect();
    assert_eq!(rest.legend.organs.len(), 4);
    for (k, organ) in rest.legend.organs.iter().enumerate() {
        let hues: Vec<f32> = organ
            .visible_px
            .iter()
            .filter(|px| clear_of_hud(px))
            .map(|&px| hue_saturation(rest.colour_at(px)))
            .filter(|&(_, saturation)| saturation >= MIN_SATURATION)
            .map(|(hue, _)| hue)
            .collect();
        assert!(
            hues.len() >= 5,
            "{}: only {} pixels in sight",
            organ.name,
            hues.len()
        );
        let own = hues
            .iter()
            .filter(|&&hue| {
                let d = hue_distance(hue, references[k]);
                references.iter().all(|&r| d <= hue_distance(hue, r))
            })
            .count();
        assert!(
            own * 4 >= hues.len() * 3,
            "{}: {own} of {} pixels show its tissue (hues {hues:?}, references {references:?})",
            organ.name,
            hues.len()
        );
    }
}

/// Pressing changes the picture around the tool (the dimple's shading, the contact tint) and
/// leaves it the same far from it.
#[test]
fn pressing_changes_the_picture_where_the_tool_presses() {
    let (rest, press) = rest_and_press();
    assert_eq!(
        (rest.width, rest.rgb.len()),
        (press.width, press.rgb.len()),
        "the two screenshots differ in size"
    );
    let tool = press.legend.tool.as_ref().expect("the tool is drawn");
    let centre = tool.centre_px;
    let ring: Vec<[f32; 2]> = (0..48)
        .flat_map(|k| {
            let angle = k as f32 / 48.0 * std::f32::consts::TAU;
            [1.3, 1.7, 2.2].map(|r| {
                let radius = r * tool.radius_px;
                [
                    centre[0] + radius * angle.cos(),
                    centre[1] + radius * angle.sin(),
                ]
            })
        })
        .collect();
    let change = |pixels: &[[f32; 2]]| {
        pixels
            .iter()
            .map(|&px| distance(rest.colour_at(px), press.colour_at(px)))
            .sum::<f32>()
            / pixels.len().max(1) as f32
    };
    let near = change(&ring);
    let far: Vec<[f32; 2]> = press
        .legend
        .organs
        .iter()
        .flat_map(|o| o.visible_px.iter().copied())
        .filter(|px| {
            let d = ((px[0] - centre[0]).powi(2) + (px[1] - centre[1]).powi(2)).sqrt();
            d > 6.0 * tool.radius_px && clear_of_hud(px)
        })
        .collect();
    assert!(
        far.len() >= 20,
        "only {} pixels far from the tool",
        far.len()
    );
    let far = change(&far);
    assert!(
        near > 10.0,
        "around the tool the colour moved by only {near:.1}"
    );
    assert!(far < 2.0, "far from the tool the colour moved by {far:.1}");
}

/// Without an X server the trainer says so and points to --headless, with no panic.
#[test]
fn no_display_is_reported_plainly() {
    for display in ["", ":199"] {
        let output = Command::new(TRAINER)
            .env("DISPLAY", display)
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("--headless"), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}
