//! The critical view of safety's doublet (from the front and from behind, each criterion met
//! or not) as an image for the window's debrief: the report's picture, drawn in memory.

use bevy::asset::RenderAssetUsages;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

use crate::biliary::ViewRecord;
use crate::report::critical_view::{SIZE, critical_view_rgb};

/// The doublet of `record` as an image; `None` (and a line on stderr) if it cannot be drawn.
pub(super) fn doublet_image(record: &ViewRecord) -> Option<Image> {
    let rgb = critical_view_rgb(record)
        .inspect_err(|e| eprintln!("trainer: the critical view could not be drawn: {e}"))
        .ok()?;
    let rgba: Vec<u8> = (rgb.chunks_exact(3))
        .flat_map(|p| [p[0], p[1], p[2], u8::MAX])
        .collect();
    Some(Image::new(
        Extent3d {
            width: SIZE.0,
            height: SIZE.1,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        rgba,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    ))
}

/// The doublet beside the debrief's text, as wide as this (pixels).
pub(super) const DOUBLET_WIDTH_PX: f32 = 600.0;

/// A node showing `image` at [`DOUBLET_WIDTH_PX`], its aspect kept.
pub(super) fn doublet_node(image: Handle<Image>) -> impl Bundle {
    (
        Node {
            width: px(DOUBLET_WIDTH_PX),
            aspect_ratio: Some(SIZE.0 as f32 / SIZE.1 as f32),
            margin: UiRect::left(px(16)),
            ..default()
        },
        ImageNode::new(image),
    )
}
