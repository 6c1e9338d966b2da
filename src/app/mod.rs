//! The Bevy layer: plugins and systems that wrap the numerical core for the trainer window.

pub mod haptic;
pub mod headless;
mod pressed_slab;
pub mod scene;
mod view;

use bevy::prelude::*;

pub use pressed_slab::PressedSlab;

/// Shows a solved default scene in a window until the user closes it.
pub struct TrainerPlugin {
    pub scene: PressedSlab,
}

impl Plugin for TrainerPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(self.scene.clone())
            .insert_resource(ClearColor(Color::srgb(0.05, 0.06, 0.08)))
            .add_systems(Startup, view::spawn_scene);
    }
}

/// Opens the trainer window.
pub fn run_window(scene: PressedSlab) -> AppExit {
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window {
                title: "PGD surgery trainer".into(),
                ..default()
            }),
            ..default()
        }))
        .add_plugins(TrainerPlugin { scene })
        .run()
}

/// Why a window cannot be opened here, if that is known before trying.
pub fn missing_display() -> Option<&'static str> {
    if cfg!(target_os = "linux") && std::env::var_os("DISPLAY").is_none_or(|d| d.is_empty()) {
        Some("no X display is available (DISPLAY is not set)")
    } else {
        None
    }
}
