//! `--screenshot FILE`: saves the window after a number of frames, then closes it; a failed
//! save closes it with an error rather than a silent success.

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};

use super::FrameSet;

/// Where to save the window, and after how many frames.
#[derive(Resource, Clone, Debug)]
pub struct ScreenshotPlan {
    pub path: PathBuf,
    pub after_frames: u32,
}

pub(super) fn setup(app: &mut App, plan: Option<ScreenshotPlan>) {
    if let Some(plan) = plan {
        app.insert_resource(plan)
            .add_systems(Update, take_screenshot.after(FrameSet::Draw));
    }
}

fn take_screenshot(mut commands: Commands, plan: Res<ScreenshotPlan>, mut frames: Local<u32>) {
    *frames += 1;
    if *frames != plan.after_frames {
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
