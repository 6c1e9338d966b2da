//! `--screenshot FILE`: saves the window after a number of frames, with its legend (what is
//! where, `FILE` with a `.json` extension), then closes it; a failed save closes it with an
//! error rather than a silent success.

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

fn take_screenshot(
    mut commands: Commands,
    plan: Res<ScreenshotPlan>,
    mut frames: Local<u32>,
    frame: Frame,
    mut exit: MessageWriter<AppExit>,
) {
    *frames += 1;
    if *frames != plan.after_frames {
        return;
    }
    let written =
        frame_legend(&frame).and_then(|legend| write_legend(&plan.legend_path(), &legend));
    if let Err(e) = written {
        error!(
            "{}: could not write the legend: {e}",
            plan.legend_path().display()
        );
        exit.write(AppExit::from_code(1));
        return;
    }
    let path = plan.path.clone();
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
            let saved = captured
                .image
                .clone()
                .try_into_dynamic()
                .map_err(|e| e.to_string())
                .and_then(|image| image.to_rgb8().save(&path).map_err(|e| e.to_string()));
            match saved {
                Ok(()) => {
                    info!("screenshot saved to {}", path.display());
                    exit.write(AppExit::Success);
                }
                Err(e) => {
                    error!("{}: could not save the screenshot: {e}", path.display());
                    exit.write(AppExit::from_code(1));
                }
            }
        },
    );
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
