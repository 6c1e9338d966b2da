//! The body cavity around the generated organs, in laparoscopic scenes (a laparoscope or an
//! instrument port): the inner abdominal wall, the posterior wall over the spine, the stomach,
//! the transverse colon and loops of small bowel, drawn static (nothing here is simulated),
//! and a trocar at each port. The shapes are placed for the generated abdomen's layout (the
//! organs' frame: x to the patient's right, y anterior, z to the head); an imported organ
//! keeps its own place among them.

use bevy::asset::RenderAssetUsages;
use bevy::math::primitives::{Capsule3d, Cylinder, Sphere, Torus};
use bevy::prelude::*;
use bevy::render::render_resource::Face;

use super::bridge::HapticLink;
use super::{SceneView, tissue, to_bevy};

/// The inner abdominal wall: an ellipsoid about the floor's centre, insufflated, so that the
/// anterior wall is 5 to 8 cm above the organs' front (m). A port on the wall at (x, z) is at
/// y = −0.085 + 0.24 √(1 − (x / 0.22)² − ((z + 0.05) / 0.3)²).
const WALL_CENTRE: [f32; 3] = [0.0, -0.085, -0.05];
const WALL_SEMI_AXES: [f32; 3] = [0.22, 0.24, 0.3];

/// A trocar's cannula: radius and length (m).
const TROCAR_RADIUS_M: f32 = 0.0065;
const TROCAR_LENGTH_M: f32 = 0.09;

/// One static piece of anatomy: its tissue (for `tissue::tissue`), shape and placement.
struct Part {
    name: &'static str,
    tissue: &'static str,
    mesh: Mesh,
    /// The wall is seen from inside: its outer faces are culled, so the free camera sees
    /// through it from outside.
    seen_from_inside: bool,
}

fn ellipsoid(centre: [f32; 3], semi_axes: [f32; 3]) -> Mesh {
    Sphere::new(1.0)
        .mesh()
        .uv(64, 32)
        .transformed_by(Transform::from_translation(centre.into()).with_scale(semi_axes.into()))
}

fn capsule(centre: [f32; 3], radius: f32, length: f32, along: Vec3) -> Mesh {
    Capsule3d::new(radius, length)
        .mesh()
        .build()
        .transformed_by(
            Transform::from_translation(centre.into())
                .with_rotation(Quat::from_rotation_arc(Vec3::Y, along.normalize())),
        )
}

fn bowel_loop(centre: [f32; 3], tilt_rad: f32) -> Mesh {
    Torus::new(0.012, 0.034).mesh().build().transformed_by(
        Transform::from_translation(centre.into()).with_rotation(Quat::from_rotation_x(tilt_rad)),
    )
}

/// The anatomy around the generated organs, clear of them.
fn parts() -> Vec<Part> {
    let part = |name, tissue, mesh| Part {
        name,
        tissue,
        mesh,
        seen_from_inside: false,
    };
    let mut parts = vec![
        Part {
            seen_from_inside: true,
            ..part(
                "abdominal wall",
                "peritoneum",
                ellipsoid(WALL_CENTRE, WALL_SEMI_AXES),
            )
        },
        part(
            "posterior wall",
            "peritoneum",
            ellipsoid([0.0, -0.085, -0.1], [0.2, 0.012, 0.27]),
        ),
        part(
            "spine",
            "peritoneum",
            capsule([0.0, -0.078, -0.1], 0.016, 0.36, Vec3::Z),
        ),
        part(
            "stomach",
            "stomach",
            ellipsoid([-0.13, -0.005, -0.04], [0.035, 0.03, 0.05]),
        ),
        part(
            "transverse colon",
            "colon",
            capsule([0.0, 0.0, -0.19], 0.02, 0.2, Vec3::X),
        ),
    ];
    let loops = [
        ([-0.06, -0.02, -0.25], 1.2),
        ([0.0, -0.01, -0.26], 1.5),
        ([0.06, -0.02, -0.245], 1.1),
        ([-0.035, -0.03, -0.31], 1.4),
        ([0.04, -0.03, -0.305], 1.3),
    ];
    parts.extend(
        loops
            .into_iter()
            .map(|(centre, tilt)| part("small bowel", "bowel", bowel_loop(centre, tilt))),
    );
    parts
}

/// The abdomen around the organs.
pub(super) struct AbdomenPlugin;

impl Plugin for AbdomenPlugin {
    fn build(&self, app: &mut App) {
        super::spawn_with_scene(app, spawn_abdomen);
    }
}

fn laparoscopic(link: &HapticLink) -> bool {
    link.scene.scope.is_some() || link.scene.ports().next().is_some()
}

fn spawn_abdomen(
    mut commands: Commands,
    link: Res<HapticLink>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
) {
    if !laparoscopic(&link) {
        return;
    }
    for part in parts() {
        let (colour, roughness) = tissue::images(&tissue::tissue(part.tissue));
        let mut material = tissue::wet(images.add(colour), images.add(roughness));
        if part.seen_from_inside {
            material.cull_mode = Some(Face::Front);
        }
        commands.spawn((
            SceneView,
            Name::new(part.name),
            Mesh3d(meshes.add(with_tissue_uvs(part.mesh))),
            MeshMaterial3d(materials.add(material)),
        ));
    }
    spawn_trocars(&mut commands, &link, &mut meshes, &mut materials);
}

/// The tissue tiles laid on a part by the organs' planar projection, so that they have the
/// same scale as on the organs.
fn with_tissue_uvs(mesh: Mesh) -> Mesh {
    let positions: Vec<[f32; 3]> = mesh
        .attribute(Mesh::ATTRIBUTE_POSITION)
        .and_then(|values| values.as_float3())
        .map(<[[f32; 3]]>::to_vec)
        .unwrap_or_default();
    let mut mesh = mesh;
    mesh.insert_attribute(Mesh::ATTRIBUTE_UV_0, tissue::planar_uvs(&positions));
    mesh.asset_usage = RenderAssetUsages::RENDER_WORLD;
    mesh
}

/// A cannula at each port, along the line from the port to the organs' centre.
fn spawn_trocars(
    commands: &mut Commands,
    link: &HapticLink,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
) {
    let ports = (link.scene.ports().map(|p| p.port_m))
        .chain(link.scene.scope.as_ref().map(|s| s.scope.port_m));
    let centre = link.scene_centre();
    let mesh = meshes.add(Cylinder::new(TROCAR_RADIUS_M, TROCAR_LENGTH_M));
    let material = materials.add(StandardMaterial {
        base_color: Color::srgb(0.12, 0.12, 0.13),
        perceptual_roughness: 0.35,
        metallic: 0.2,
        ..default()
    });
    for port in ports {
        let at = to_bevy(&port);
        let inward = (centre - at).normalize_or(Vec3::NEG_Y);
        commands.spawn((
            SceneView,
            Name::new("trocar"),
            Mesh3d(mesh.clone()),
            MeshMaterial3d(material.clone()),
            Transform::from_translation(at).with_rotation(Quat::from_rotation_arc(Vec3::Y, inward)),
        ));
    }
}
