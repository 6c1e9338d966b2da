//! `--screenshot FILE`: saves the window after a number of frames, with its legend (what is
//! where, `FILE` with a `.json` extension), then closes it; a failed save closes it with an
//! error rather than a silent success. A capture in which the organs are not drawn yet (their
//! shaders still compiling) is retried a few frames later.

use std::path::{Path, PathBuf};

use bevy::ecs::system::SystemParam;
use bevy::mesh::VertexAttributeValues;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::PrimaryWindow;

use super::legend::{DrawnSurface, Legend, legend};
use super::organs::OrganView;
use super::tool::ToolTip;
use super::{FrameSet, HapticLink};

/// Where to save the window, and after how many frames.
#[derive(Resource, Clone, Debug)]
pub struct ScreenshotPlan {
    pub path: PathBuf,
    pub after_frames: u32,
}

impl ScreenshotPlan {
    /// Where the legend of the screenshot goes.
    pub fn legend_path(&self) -> PathBuf {
        self.path.with_extension("json")
    }
}

pub(super) fn setup(app: &mut App, plan: Option<ScreenshotPlan>) {
    if let Some(plan) = plan {
        app.insert_resource(plan)
            .init_resource::<Progress>()
            .add_systems(Update, take_screenshot.after(FrameSet::Draw));
    }
}

/// What the legend needs of the frame.
#[derive(SystemParam)]
struct Frame<'w, 's> {
    camera: Query<'w, 's, (&'static Camera, &'static GlobalTransform)>,
    window: Query<'w, 's, &'static Window, With<PrimaryWindow>>,
    organs: Query<'w, 's, (&'static Name, &'static OrganView, &'static Mesh3d)>,
    tip: Query<'w, 's, (&'static Transform, &'static Visibility), With<ToolTip>>,
    meshes: Res<'w, Assets<Mesh>>,
    link: Res<'w, HapticLink>,
}

/// Where the screenshot stands.
#[derive(Resource, Default)]
struct Progress {
    frames: u32,
    /// Captures found not drawn yet, each retried later.
    retries: u32,
    /// A capture is on its way.
    waiting: bool,
}

/// Frames between a capture found not drawn yet and the next one.
const RETRY_FRAMES: u32 = 10;
/// Captures retried before saving what there is anyway.
const MAX_RETRIES: u32 = 30;

fn take_screenshot(
    mut commands: Commands,
    plan: Res<ScreenshotPlan>,
    mut progress: ResMut<Progress>,
    frame: Frame,
    clear: Res<ClearColor>,
    mut exit: MessageWriter<AppExit>,
) {
    progress.frames += 1;
    if progress.waiting || progress.frames < plan.after_frames + progress.retries * RETRY_FRAMES {
        return;
    }
    let legend = match frame_legend(&frame) {
        Ok(legend) => legend,
        Err(e) => {
            error!("could not make the screenshot's legend: {e}");
            exit.write(AppExit::from_code(1));
            return;
        }
    };
    progress.waiting = true;
    let plan = plan.clone();
    let background = clear.0.to_srgba().to_u8_array();
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>,
              mut progress: ResMut<Progress>,
              mut exit: MessageWriter<AppExit>| {
            let image = match captured.image.clone().try_into_dynamic() {
                Ok(image) => image.to_rgb8(),
                Err(e) => {
                    error!(
                        "{}: could not read the screenshot: {e}",
                        plan.path.display()
                    );
                    exit.write(AppExit::from_code(1));
                    return;
                }
            };
            if !drawn(image.width(), image.as_raw(), &legend, background)
                && progress.retries < MAX_RETRIES
            {
                // Shaders compile asynchronously: until they are ready, meshes are not drawn.
                progress.retries += 1;
                progress.waiting = false;
                return;
            }
            let saved = image
                .save(&plan.path)
                .map_err(|e| format!("{}: {e}", plan.path.display()))
                .and_then(|()| write_legend(&plan.legend_path(), &legend));
            match saved {
                Ok(()) => {
                    info!("screenshot saved to {}", plan.path.display());
                    exit.write(AppExit::Success);
                }
                Err(e) => {
                    error!("could not save the screenshot: {e}");
                    exit.write(AppExit::from_code(1));
                }
            }
        },
    );
}

/// Whether the organs are drawn where the legend puts them: nine in ten of those pixels differ
/// from the background (vacuously so if none is in sight).
fn drawn(width: u32, rgb: &[u8], legend: &Legend, background: [u8; 4]) -> bool {
    let pixels: Vec<[f32; 2]> = legend
        .organs
        .iter()
        .flat_map(|o| o.visible_px.iter().copied())
        .collect();
    let differs = pixels
        .iter()
        .filter(|px| {
            let (x, y) = (px[0] as usize, px[1] as usize);
            let at = (y * width as usize + x) * 3;
            x < width as usize
                && rgb.get(at..at + 3).is_some_and(|p| {
                    (0..3)
                        .map(|c| p[c].abs_diff(background[c]) as u32)
                        .sum::<u32>()
                        > 24
                })
        })
        .count();
    differs * 10 >= pixels.len() * 9
}

fn frame_legend(frame: &Frame) -> Result<Legend, String> {
    let camera = frame.camera.single().map_err(|e| e.to_string())?;
    let scale_factor = frame
        .window
        .single()
        .map_err(|e| e.to_string())?
        .scale_factor();
    let drawn: Vec<_> = frame
        .organs
        .iter()
        .filter_map(|(name, view, mesh)| {
            let mesh = frame.meshes.get(&mesh.0)?;
            let attribute = |id| match mesh.attribute(id) {
                Some(VertexAttributeValues::Float32x3(values)) => Some(values),
                _ => None,
            };
            let triangles = view.triangles.iter().map(|t| t.map(|i| i as u32)).collect();
            let positions = attribute(Mesh::ATTRIBUTE_POSITION)?;
            Some((
                name,
                positions,
                attribute(Mesh::ATTRIBUTE_NORMAL)?,
                triangles,
            ))
        })
        .collect::<Vec<(_, _, _, Vec<[u32; 3]>)>>();
    let surfaces: Vec<DrawnSurface> = drawn
        .iter()
        .map(|(name, positions, normals, triangles)| DrawnSurface {
            name: name.as_str(),
            positions,
            normals,
            triangles,
        })
        .collect();
    let tool = frame
        .tip
        .single()
        .ok()
        .filter(|(_, visibility)| **visibility != Visibility::Hidden)
        .map(|(transform, _)| {
            (
                transform.translation,
                frame.link.scene.probe.tip_radius_m as f32,
            )
        });
    Ok(legend(camera, scale_factor, &surfaces, tool))
}

fn write_legend(path: &Path, legend: &Legend) -> Result<(), String> {
    let text = serde_json::to_string_pretty(legend).map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| e.to_string())
}
