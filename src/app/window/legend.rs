//! What a screenshot shows where: for each organ, image pixels where its surface is in plain
//! sight, and where the tool is. Written beside the PNG so that a
//! test (or a script) can check a render without knowing the camera.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// The legend of one screenshot, in image pixels (origin top-left).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Legend {
    pub organs: Vec<OrganLegend>,
    pub tool: Option<ToolLegend>,
    /// Each vertex split by a cut and its copy across the cut, where they are drawn: the two
    /// lips of an incision (none uncut).
    #[serde(default)]
    pub lips: Vec<LipLegend>,
    /// Each text shown, and the rectangle it takes: a test can check that none overlaps
    /// another or leaves the screen.
    #[serde(default)]
    pub texts: Vec<TextLegend>,
}

/// A text on the screen: its first words and the rectangle it takes (pixels, corners).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TextLegend {
    pub words: String,
    pub min_px: [f32; 2],
    pub max_px: [f32; 2],
}

/// One split vertex of a cut organ's surface: its own lip and the copy on the other.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LipLegend {
    pub organ: String,
    pub own_px: [f32; 2],
    pub across_px: [f32; 2],
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct OrganLegend {
    pub name: String,
    /// Pixels where a vertex of it faces the camera with nothing in front of it.
    pub visible_px: Vec<[f32; 2]>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ToolLegend {
    pub centre_px: [f32; 2],
    pub radius_px: f32,
}

/// One organ's surface as drawn this frame.
pub struct DrawnSurface<'a> {
    pub name: &'a str,
    pub positions: &'a [[f32; 3]],
    pub normals: &'a [[f32; 3]],
    pub triangles: &'a [[u32; 3]],
}

/// At most this many pixels per organ, spread over its visible vertices.
const SAMPLES_PER_ORGAN: usize = 24;
/// A vertex is sampled only where its surface faces the camera this squarely (cosine), away
/// from silhouettes where a pixel may show what lies behind.
const FACING: f32 = 0.6;

/// The round image of a laparoscope on the screen (pixels): what lies outside is masked.
#[derive(Clone, Copy, Debug)]
pub struct Aperture {
    pub centre_px: Vec2,
    pub radius_px: f32,
}

/// The legend of the frame `camera` sees: `surfaces` as drawn, and the tool's sphere; only
/// pixels inside the `aperture`, if the view has one.
pub fn legend(
    camera: (&Camera, &GlobalTransform),
    scale_factor: f32,
    surfaces: &[DrawnSurface],
    tool: Option<(Vec3, f32)>,
    aperture: Option<Aperture>,
) -> Legend {
    let unmasked = |px: &Vec2| aperture.is_none_or(|a| px.distance(a.centre_px) <= a.radius_px);
    let eye = camera.1.translation();
    let meshes: Vec<_> = surfaces
        .iter()
        .map(|s| crate::parry_interop::trimesh(s.positions, s.triangles))
        .collect();
    let project = |p: Vec3| {
        camera
            .0
            .world_to_viewport(camera.1, p)
            .ok()
            .map(|px| px * scale_factor)
            .filter(unmasked)
    };
    let in_sight = |p: Vec3| {
        let (distance, dir) = ((p - eye).length(), (p - eye).normalize());
        let blocked_by_mesh = meshes.iter().flatten().any(|mesh| {
            crate::parry_interop::ray_distance(mesh, eye.to_array(), dir.to_array(), distance)
                .is_some_and(|hit| hit < distance - 1e-3)
        });
        let blocked_by_tool = tool.is_some_and(|(centre, radius)| {
            ray_sphere(eye, dir, centre, radius).is_some_and(|hit| hit < distance)
        });
        !blocked_by_mesh && !blocked_by_tool
    };
    let organs = surfaces
        .iter()
        .map(|surface| {
            let visible: Vec<[f32; 2]> = (0..surface.positions.len())
                .filter_map(|k| {
                    let p = Vec3::from_array(surface.positions[k]);
                    let facing = Vec3::from_array(surface.normals[k]).dot((eye - p).normalize());
                    (facing > FACING && in_sight(p))
                        .then(|| project(p))
                        .flatten()
                        .map(|px| px.to_array())
                })
                .collect();
            let stride = visible.len().div_ceil(SAMPLES_PER_ORGAN).max(1);
            OrganLegend {
                name: surface.name.to_owned(),
                visible_px: visible.into_iter().step_by(stride).collect(),
            }
        })
        .collect();
    let tool = tool.and_then(|(centre, radius)| {
        let rim = centre + camera.1.right() * radius;
        let (centre_px, rim_px) = (project(centre)?, project(rim)?);
        Some(ToolLegend {
            centre_px: centre_px.to_array(),
            radius_px: centre_px.distance(rim_px),
        })
    });
    Legend {
        organs,
        tool,
        lips: Vec::new(),
        texts: Vec::new(),
    }
}

/// Distance along a unit ray to its first hit on a sphere, if any ahead.
fn ray_sphere(origin: Vec3, dir: Vec3, centre: Vec3, radius: f32) -> Option<f32> {
    let to_centre = centre - origin;
    let along = to_centre.dot(dir);
    let miss_sq = to_centre.length_squared() - along * along;
    let half_chord_sq = radius * radius - miss_sq;
    (half_chord_sq >= 0.0)
        .then(|| along - half_chord_sq.sqrt())
        .filter(|&t| t > 0.0)
}
