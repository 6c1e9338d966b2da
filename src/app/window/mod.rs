//! The trainer window: the organs deforming under the tool from the haptic thread's latest
//! snapshot, the tool and the force it renders, a HUD, and the mouse driving the virtual
//! device. The haptic loop runs apart; this side only reads its snapshots.

mod abdomen;
mod biliary;
mod bridge;
mod camera;
mod cut_surface;
mod dissection;
mod doublet;
mod frames;
mod hud;
mod incision;
mod input;
mod laparoscope;
mod legend;
mod lesson;
mod menu;
mod offscreen;
mod organs;
mod paced;
mod reload;
mod screenshot;
#[cfg(test)]
mod testing;
pub mod tissue;
mod tool;
#[cfg(target_arch = "wasm32")]
mod web_page;

use std::sync::Arc;

use bevy::prelude::*;

pub use bridge::{HapticLink, Snapshot};
pub use frames::FrameReport;
pub use legend::{Legend, LipLegend, OrganLegend, TextLegend, ToolLegend};
pub use lesson::{Lesson, Lessons, Opening};
pub use menu::{MenuCurriculum, MenuPlan, SceneSource};
pub use screenshot::ScreenshotPlan;
#[cfg(target_arch = "wasm32")]
pub use web_page::publish;

use super::haptic::{FramePaced, HapticScene, HapticSnapshot};
use crate::devices::VirtualHandle;

/// Everything the window needs from the haptic side.
pub struct WindowScene {
    pub scene: HapticScene,
    pub snapshots: triple_buffer::Output<HapticSnapshot>,
    /// By hand, the virtual device's handle where the mouse drives the hand's tool.
    pub mice: Vec<Option<Arc<VirtualHandle>>>,
    pub device_name: String,
    /// Close the window after this many seconds (for measurements under Xvfb).
    pub exit_after_s: Option<f64>,
    /// Save the window to a PNG after some frames, then close it.
    pub screenshot: Option<ScreenshotPlan>,
    /// The scenario to brief, run and debrief, and where the window opens it; free play
    /// without one.
    pub lesson: Option<(Lesson, Opening)>,
    /// Every lesson run, for their reports when the window closes.
    pub lessons: Lessons,
    /// The menu of scenarios (none in free play).
    pub menu: Option<MenuPlan>,
    /// Open a scene with a laparoscope with the free camera all the same.
    pub free_camera: bool,
    /// Draw into an image of this size (pixels) instead of a window.
    pub offscreen: Option<(u32, u32)>,
    /// The haptic loop, when the frames tick it (a web page, which has no thread for it);
    /// `None` when it runs on a thread of its own.
    pub paced: Option<FramePaced>,
}

/// The haptic side's f64 vectors as Bevy's (the Bevy end of the seam; parry's is `crate::parry_interop`).
fn to_bevy(v: &nalgebra::Vector3<f64>) -> Vec3 {
    Vec3::from_array([v.x as f32, v.y as f32, v.z as f32])
}

fn from_bevy(v: Vec3) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(v.x as f64, v.y as f64, v.z as f64)
}

/// The stages of a frame, in order.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
enum FrameSet {
    Input,
    Receive,
    /// The scene's entities despawned and spawned again after a change of scene.
    Respawn,
    Draw,
}

/// The haptic scene has changed (another scenario was chosen): what is drawn of it is
/// despawned and spawned again from the [`HapticLink`]'s scene.
#[derive(Message, Clone, Copy, Debug)]
struct SceneChanged;

/// An entity drawn from the haptic scene (organs, tool, camera and light), replaced when it
/// changes.
#[derive(Component)]
struct SceneView;

fn despawn_scene_views(mut commands: Commands, views: Query<Entity, With<SceneView>>) {
    for view in &views {
        commands.entity(view).despawn();
    }
}

/// Runs `spawn` at start-up and again on every change of scene.
fn spawn_with_scene<M>(
    app: &mut App,
    spawn: impl IntoScheduleConfigs<bevy::ecs::system::ScheduleSystem, M> + Clone,
) {
    app.add_systems(Startup, spawn.clone()).add_systems(
        Update,
        spawn
            .run_if(on_message::<SceneChanged>)
            .in_set(FrameSet::Respawn),
    );
}

/// The frame's stages in order, and the despawning of what was drawn of a scene that changed.
struct FrameStagesPlugin;

impl Plugin for FrameStagesPlugin {
    fn build(&self, app: &mut App) {
        app.configure_sets(
            Update,
            (
                FrameSet::Input,
                FrameSet::Receive,
                FrameSet::Respawn,
                FrameSet::Draw,
            )
                .chain(),
        )
        .add_message::<SceneChanged>()
        .add_systems(
            Update,
            despawn_scene_views
                .run_if(on_message::<SceneChanged>)
                .in_set(FrameSet::Receive),
        );
    }
}

/// The trainer window's concerns, a plugin each, from the run's data.
struct TrainerWindowPlugins {
    window: WindowScene,
    log: frames::FrameLog,
    /// The scenarios folder watched for edits.
    folder: Option<std::path::PathBuf>,
}

impl PluginGroup for TrainerWindowPlugins {
    fn build(mut self) -> bevy::app::PluginGroupBuilder {
        let window = &mut self.window;
        let group = bevy::app::PluginGroupBuilder::start::<Self>()
            .add(FrameStagesPlugin)
            .add(offscreen::OffscreenPlugin {
                size: window.offscreen,
            })
            .add(screenshot::ScreenshotPlugin(window.screenshot.take()))
            .add(reload::ReloadPlugin {
                folder: self.folder,
            })
            .add(lesson::LessonPlugin {
                lesson: window.lesson.take(),
                lessons: window.lessons.clone(),
            })
            .add(menu::MenuPlugin(window.menu.take()))
            .add(paced::PacedPlugin(std::sync::Mutex::new(
                window.paced.take(),
            )))
            .add(laparoscope::LaparoscopePlugin {
                free_camera: window.free_camera,
            })
            .add(bridge::BridgePlugin::new(self.window))
            .add(organs::OrganPlugin)
            .add(abdomen::AbdomenPlugin)
            .add(camera::CameraPlugin)
            .add(tool::ToolPlugin)
            .add(incision::IncisionPlugin)
            .add(dissection::DissectionPlugin)
            .add(biliary::BiliaryPlugin)
            .add(input::InputPlugin)
            .add(hud::HudPlugin)
            .add(frames::FramesPlugin(self.log));
        #[cfg(target_arch = "wasm32")]
        let group = group.add(web_page::WebPagePlugin);
        group
    }
}

/// Opens the trainer window (or draws into an image, offscreen) and returns, when it closes,
/// how it closed and how fast it drew.
pub fn run(window: WindowScene) -> (AppExit, Option<FrameReport>) {
    let log = frames::FrameLog::default();
    let mut app = App::new();
    // The scenarios folder is watched: an edit of the lesson's file reloads it.
    let folder = window.menu.as_ref().and_then(|m| m.folder.clone());
    offscreen::plugins(
        &mut app,
        window.offscreen,
        reload::asset_plugin(folder.as_deref()),
    );
    app.insert_resource(ClearColor(Color::srgb(0.05, 0.06, 0.08)))
        .add_plugins(TrainerWindowPlugins {
            window,
            log: log.clone(),
            folder,
        });
    let exit = app.run();
    (exit, log.report())
}
