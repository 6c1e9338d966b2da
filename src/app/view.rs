//! Draws the default scene: the deformed tissue surface, the probe, light, camera and HUD.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;

use super::PressedSlab;
use crate::mesh::vertex_normals;

/// Spawns everything once the solved scene is available as a resource.
pub fn spawn_scene(
    mut commands: Commands,
    slab: Res<PressedSlab>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        Mesh3d(meshes.add(surface_mesh(&slab.triangles, &slab.deformed_positions))),
        MeshMaterial3d(materials.add(StandardMaterial {
            // Liver: dark red-brown, glossy because wet.
            base_color: Color::srgb(0.50, 0.16, 0.12),
            perceptual_roughness: 0.35,
            reflectance: 0.5,
            ..default()
        })),
    ));
    let tip = Vec3::from(slab.probe_tip);
    let shaft_length = 0.12;
    commands.spawn((
        Mesh3d(meshes.add(Cylinder::new(0.004, shaft_length))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.75, 0.77, 0.80),
            metallic: 0.9,
            perceptual_roughness: 0.25,
            ..default()
        })),
        Transform::from_translation(tip + Vec3::Y * (shaft_length / 2.0)),
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: 8_000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(0.2, 0.5, 0.3).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.16, 0.17, 0.24).looking_at(Vec3::new(0.0, -0.01, 0.0), Vec3::Y),
    ));
    commands.spawn((
        Text::new(format!("Default scene: {}", slab.summary())),
        TextFont {
            font_size: FontSize::Px(15.0),
            ..default()
        },
        Node {
            position_type: PositionType::Absolute,
            top: px(10),
            left: px(10),
            ..default()
        },
    ));
}

/// A render mesh of a surface with area-weighted normals of the given positions.
fn surface_mesh(triangles: &[[usize; 3]], positions: &[[f32; 3]]) -> Mesh {
    let indices: Vec<u32> = triangles.iter().flatten().map(|&i| i as u32).collect();
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions.to_vec())
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vertex_normals(triangles, positions))
    .with_inserted_indices(Indices::U32(indices))
}
