//! `--offscreen`: the trainer drawn into an image instead of a window, so that it renders with
//! no X server, on whatever adapter there is (software Vulkan, or a GPU). The app runs without
//! winit, updating as fast as frames are drawn; the camera renders into the image and the HUD
//! over it, and `--screenshot` reads the image back.

use std::time::Duration;

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::window::ExitCondition;

use super::FrameSet;

/// The image the scene is drawn into, and its size (pixels).
#[derive(Resource, Clone, Debug)]
pub(super) struct Offscreen {
    pub image: Handle<Image>,
    pub size: UVec2,
}

/// Bevy's plugins for a window, or for rendering into an image when `size` is given.
pub(super) fn plugins(app: &mut App, size: Option<(u32, u32)>, assets: AssetPlugin) {
    let window = WindowPlugin {
        primary_window: Some(Window {
            title: "PGD surgery trainer".into(),
            // In a web page: its canvas, sized by the page.
            #[cfg(target_arch = "wasm32")]
            canvas: Some("#trainer".into()),
            #[cfg(target_arch = "wasm32")]
            fit_canvas_to_parent: true,
            ..default()
        }),
        ..default()
    };
    let plugins = DefaultPlugins.set(assets);
    add_plugins(app, plugins, window, size);
    install_font(app);
}

/// DejaVu Sans as the text's default font, in place of Bevy's built-in subset, which lacks
/// signs the HUD and the debrief print (×, ³, µ).
fn install_font(app: &mut App) {
    let font = Font::from_bytes(crate::report::FONT_DATA.to_vec());
    let mut fonts = app.world_mut().resource_mut::<Assets<Font>>();
    if fonts.insert(AssetId::default(), font).is_err() {
        warn!("the text keeps Bevy's built-in font: DejaVu Sans could not replace it");
    }
}

/// `plugins` with `window`, or without one (drawing into an image) when `size` is given.
fn add_plugins(
    app: &mut App,
    plugins: bevy::app::PluginGroupBuilder,
    window: WindowPlugin,
    size: Option<(u32, u32)>,
) {
    match size {
        None => {
            app.add_plugins(plugins.set(window));
        }
        Some(_) => {
            app.add_plugins((
                plugins
                    .set(WindowPlugin {
                        primary_window: None,
                        exit_condition: ExitCondition::DontExit,
                        ..default()
                    })
                    .disable::<bevy::winit::WinitPlugin>(),
                ScheduleRunnerPlugin::run_loop(Duration::ZERO),
            ));
        }
    }
}

/// Drawing into an image of `size` instead of the window, when a size is given.
pub(super) struct OffscreenPlugin {
    /// The image's size (pixels); none draws into the window.
    pub size: Option<(u32, u32)>,
}

impl Plugin for OffscreenPlugin {
    fn build(&self, app: &mut App) {
        let size = self.size;
        let Some((width, height)) = size else {
            return;
        };
        let mut target =
            Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
        // Read back by the screenshot.
        target.texture_descriptor.usage |= TextureUsages::COPY_SRC;
        let image = app.world_mut().resource_mut::<Assets<Image>>().add(target);
        app.insert_resource(Offscreen {
            image,
            size: UVec2::new(width, height),
        })
        .add_systems(
            Update,
            render_into_image
                .after(FrameSet::Respawn)
                .before(FrameSet::Draw),
        );
    }
}

/// Every camera spawned (at start-up, or with another scene) draws into the image, and the
/// HUD over it (with no window, the UI has no camera of its own to find).
fn render_into_image(
    mut commands: Commands,
    offscreen: Res<Offscreen>,
    cameras: Query<Entity, Added<Camera3d>>,
) {
    for camera in &cameras {
        commands.entity(camera).insert((
            RenderTarget::Image(offscreen.image.clone().into()),
            IsDefaultUiCamera,
        ));
    }
}
