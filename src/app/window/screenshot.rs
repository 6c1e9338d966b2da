//! `--screenshot FILE`: saves the window (or the offscreen image) after a number of frames, with its legend (what is
//! where, `FILE` with a `.json` extension), then closes it; a failed save closes it with an
//! error rather than a silent success. Shaders compile asynchronously, and until a pipeline is
//! ready Bevy silently skips what it draws (an organ, or the tone mapping of the whole frame):
//! the capture waits until no pipeline has been waiting for a few frames, and one in which the
//! organs are still not drawn is retried a few frames later.

use std::path::{Path, PathBuf};

use bevy::ecs::system::SystemParam;
use bevy::mesh::VertexAttributeValues;
use bevy::prelude::*;
use bevy::render::render_resource::PipelineCache;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::render::{ExtractSchedule, MainWorld, RenderApp};
use bevy::window::PrimaryWindow;

use super::bridge::Snapshot;
use super::laparoscope::CameraMode;
use super::legend::{Aperture, DrawnSurface, Legend, LipLegend, TextLegend, legend};
use super::offscreen::Offscreen;
use super::organs::OrganView;
use super::tool::ToolTip;
use super::{FrameSet, HapticLink};

/// Where to save the window, and after how many frames.
#[derive(Resource, Clone, Debug)]
pub struct ScreenshotPlan {
    pub path: PathBuf,
    pub after_frames: u32,
    /// Nor before the haptic loop's clock has reached this (s): a scripted device's
    /// trajectory run that far, however fast the frames come.
    pub after_haptic_s: f64,
}

impl ScreenshotPlan {
    /// Where the legend of the screenshot goes.
    pub fn legend_path(&self) -> PathBuf {
        self.path.with_extension("json")
    }
}

/// A screenshot of the window after some frames, when planned.
pub(super) struct ScreenshotPlugin(pub Option<ScreenshotPlan>);

impl Plugin for ScreenshotPlugin {
    fn build(&self, app: &mut App) {
        let Some(plan) = self.0.clone() else {
            return;
        };
        app.insert_resource(plan)
            .init_resource::<Progress>()
            .init_resource::<PipelinesReady>()
            .add_systems(Update, take_screenshot.after(FrameSet::Draw));
        if let Some(render) = app.get_sub_app_mut(RenderApp) {
            render.add_systems(ExtractSchedule, count_ready_frames);
        }
    }
}

/// Consecutive frames at whose extraction no render pipeline was waiting to compile.
#[derive(Resource, Default)]
struct PipelinesReady(u32);

/// Frames with every pipeline compiled before a capture: a pipeline asked for late in a frame
/// (after the extraction that counts) shows up as waiting in the next.
const READY_FRAMES: u32 = 3;
/// Frames past the planned one to wait for pipelines before capturing what there is anyway
/// (the drawn check below still applies).
const MAX_COMPILE_FRAMES: u32 = 300;

fn count_ready_frames(mut main_world: ResMut<MainWorld>, pipelines: Res<PipelineCache>) {
    let idle = pipelines.waiting_pipelines().next().is_none();
    if let Some(mut ready) = main_world.get_resource_mut::<PipelinesReady>() {
        ready.0 = if idle { ready.0 + 1 } else { 0 };
    }
}

/// What the legend needs of the frame.
#[derive(SystemParam)]
struct Frame<'w, 's> {
    camera: Query<'w, 's, (&'static Camera, &'static GlobalTransform)>,
    window: Query<'w, 's, &'static Window, With<PrimaryWindow>>,
    organs: Query<'w, 's, (&'static Name, &'static OrganView, &'static Mesh3d)>,
    tips: Query<'w, 's, (&'static ToolTip, &'static Transform, &'static Visibility)>,
    meshes: Res<'w, Assets<Mesh>>,
    link: Res<'w, HapticLink>,
    snapshot: Res<'w, Snapshot>,
    mode: Res<'w, CameraMode>,
    offscreen: Option<Res<'w, Offscreen>>,
    texts: Query<
        'w,
        's,
        (
            &'static Text,
            &'static ComputedNode,
            &'static UiGlobalTransform,
            &'static InheritedVisibility,
        ),
    >,
}

impl Frame<'_, '_> {
    /// The frame's size in physical pixels and its scale factor: the window's, or the
    /// offscreen image's (scale 1).
    fn size(&self) -> Result<(Vec2, f32), String> {
        if let Some(offscreen) = &self.offscreen {
            return Ok((offscreen.size.as_vec2(), 1.0));
        }
        let window = self.window.single().map_err(|e| e.to_string())?;
        let size = Vec2::new(
            window.physical_width() as f32,
            window.physical_height() as f32,
        );
        Ok((size, window.scale_factor()))
    }

    /// The screenshot of what is drawn: the window, or the offscreen image.
    fn screenshot(&self) -> Screenshot {
        match &self.offscreen {
            Some(offscreen) => Screenshot::image(offscreen.image.clone()),
            None => Screenshot::primary_window(),
        }
    }
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
    ready: Res<PipelinesReady>,
    mut exit: MessageWriter<AppExit>,
) {
    if frame.snapshot.0.time_s < plan.after_haptic_s {
        return;
    }
    progress.frames += 1;
    let due = plan.after_frames + progress.retries * RETRY_FRAMES;
    let compiled = ready.0 >= READY_FRAMES || progress.frames >= due + MAX_COMPILE_FRAMES;
    if progress.waiting || progress.frames < due || !compiled {
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
    commands.spawn(frame.screenshot()).observe(
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
                    info!(
                        "screenshot saved to {} (frame {}, {} retries)",
                        plan.path.display(),
                        progress.frames,
                        progress.retries
                    );
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
/// from the background and from black (vacuously so if none is in sight). A frame whose
/// pipelines are not all compiled may reach the window black, with nothing drawn at all.
fn drawn(width: u32, rgb: &[u8], legend: &Legend, background: [u8; 4]) -> bool {
    let pixels: Vec<[f32; 2]> = legend
        .organs
        .iter()
        .flat_map(|o| o.visible_px.iter().copied())
        .collect();
    let unlike =
        |p: &[u8], other: [u8; 3]| (0..3).map(|c| p[c].abs_diff(other[c]) as u32).sum::<u32>() > 24;
    let differs = pixels
        .iter()
        .filter(|px| {
            let (x, y) = (px[0] as usize, px[1] as usize);
            let at = (y * width as usize + x) * 3;
            x < width as usize
                && rgb.get(at..at + 3).is_some_and(|p| {
                    unlike(p, [background[0], background[1], background[2]]) && unlike(p, [0; 3])
                })
        })
        .count();
    differs * 10 >= pixels.len() * 9
}

fn frame_legend(frame: &Frame) -> Result<Legend, String> {
    let camera = frame.camera.single().map_err(|e| e.to_string())?;
    let (size, scale_factor) = frame.size()?;
    let aperture = (*frame.mode == CameraMode::Laparoscope).then(|| Aperture {
        centre_px: size / 2.0,
        radius_px: size.y / 2.0,
    });
    let drawn: Vec<_> = frame
        .organs
        .iter()
        .filter_map(|(name, view, mesh)| {
            let mesh = frame.meshes.get(&mesh.0)?;
            let attribute = |id| match mesh.attribute(id) {
                Some(VertexAttributeValues::Float32x3(values)) => Some(values),
                _ => None,
            };
            let triangles = view
                .drawn_triangles()
                .iter()
                .map(|t| t.map(|i| i as u32))
                .collect();
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
    // The right hand's tool (the only one of a one-hand exercise).
    let tool = (frame.tips.iter())
        .find(|(tip, _, visibility)| tip.0 == 0 && **visibility != Visibility::Hidden)
        .map(|(_, transform, _)| {
            (
                transform.translation,
                frame.link.scene.probe.tip_radius_m as f32,
            )
        });
    let mut legend = legend(camera, scale_factor, &surfaces, tool, aperture);
    legend.lips = lips(frame, camera, scale_factor);
    legend.texts = texts(frame);
    Ok(legend)
}

/// Each text shown and the rectangle its node takes (an empty one takes none).
fn texts(frame: &Frame) -> Vec<TextLegend> {
    let shown = frame.texts.iter().filter(|(.., visible)| visible.get());
    shown
        .filter_map(|(text, node, transform, _)| {
            let size = node.size();
            let centre = transform.affine().translation;
            (size.x * size.y > 0.0).then(|| TextLegend {
                words: text
                    .0
                    .chars()
                    .take(40)
                    .collect::<String>()
                    .replace('\n', " "),
                min_px: (centre - size / 2.0).to_array(),
                max_px: (centre + size / 2.0).to_array(),
            })
        })
        .collect()
}

/// Where each split vertex of a cut organ and its copy across the cut are drawn.
fn lips(frame: &Frame, camera: (&Camera, &GlobalTransform), scale_factor: f32) -> Vec<LipLegend> {
    let project = |p: [f32; 3]| {
        let px = camera
            .0
            .world_to_viewport(camera.1, Vec3::from_array(p))
            .ok()?;
        Some((px * scale_factor).to_array())
    };
    let mut lips = Vec::new();
    for (name, view, mesh) in &frame.organs {
        let Some(VertexAttributeValues::Float32x3(positions)) = frame
            .meshes
            .get(&mesh.0)
            .and_then(|m| m.attribute(Mesh::ATTRIBUTE_POSITION))
        else {
            continue;
        };
        for (own, across) in view.lips() {
            let (Some(&a), Some(&b)) = (positions.get(own), positions.get(across)) else {
                continue;
            };
            if let (Some(own_px), Some(across_px)) = (project(a), project(b)) {
                lips.push(LipLegend {
                    organ: name.to_string(),
                    own_px,
                    across_px,
                });
            }
        }
    }
    lips
}

fn write_legend(path: &Path, legend: &Legend) -> Result<(), String> {
    let text = serde_json::to_string_pretty(legend).map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::window::OrganLegend;

    /// A 4×1 image whose organ is said to be in sight at its two middle pixels.
    fn organ_at_middle() -> Legend {
        Legend {
            organs: vec![OrganLegend {
                name: "liver".into(),
                visible_px: vec![[1.0, 0.0], [2.0, 0.0]],
            }],
            tool: None,
            lips: Vec::new(),
            texts: Vec::new(),
        }
    }

    #[test]
    fn a_frame_is_drawn_only_where_the_organ_shows_neither_background_nor_black() {
        let background = [13, 15, 20, 255];
        let liver = [150, 70, 60];
        let frame = |middle: [u8; 3]| [[13, 15, 20], middle, middle, [13, 15, 20]].concat();
        let legend = organ_at_middle();
        assert!(drawn(4, &frame(liver), &legend, background));
        assert!(!drawn(4, &frame([13, 15, 20]), &legend, background));
        assert!(!drawn(4, &frame([0, 0, 0]), &legend, background));
    }
}
