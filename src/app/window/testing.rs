//! What the window's tests share: a scene without organs, and driving a headless app of the
//! window's stages (a key tapped, the stage, the text on screen).

use bevy::prelude::*;

use super::lesson::Stage;
use crate::app::haptic::HapticScene;

/// A scene without organs, for the window's stages in a headless app.
pub fn scene_without_organs() -> HapticScene {
    HapticScene::without_organs()
}

/// Presses `key` for one frame, then lets it go for another.
pub fn tap(app: &mut App, key: KeyCode) {
    app.world_mut()
        .resource_mut::<ButtonInput<KeyCode>>()
        .press(key);
    app.update();
    let mut keys = app.world_mut().resource_mut::<ButtonInput<KeyCode>>();
    keys.release_all();
    keys.clear();
    app.update();
}

pub fn stage(app: &App) -> Stage {
    *app.world().resource::<State<Stage>>().get()
}

/// Every text on screen, one after another.
pub fn texts(app: &mut App) -> String {
    let mut texts = app.world_mut().query::<&Text>();
    let all: Vec<String> = texts.iter(app.world()).map(|t| t.0.clone()).collect();
    all.join("\n")
}
