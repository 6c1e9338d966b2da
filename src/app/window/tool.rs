//! The tool as the trainee sees it: a sphere at the tip the device reports, the steel shaft
//! of each instrument through a port (the one in hand, and those put down where they were
//! left), and an arrow of the force the device renders.

use bevy::prelude::*;

use super::bridge::{HapticLink, Snapshot};
use super::{FrameSet, SceneView, to_bevy};

/// The sphere drawn at the tool tip.
#[derive(Component)]
pub(super) struct ToolTip;

/// An instrument's shaft through its port (the scenario's instrument this is): a steel rod
/// from its handle to its tip.
#[derive(Component)]
pub(super) struct Shaft(usize);

/// A laparoscopic instrument's shaft radius (m): 5 mm instruments.
const SHAFT_RADIUS_M: f32 = 0.0025;

/// Arrow length per newton (m/N): 0.3 N, a firm press on the liver, draws 6 cm.
const ARROW_M_PER_N: f32 = 0.2;

/// The tool, its force arrow and the instruments.
pub(super) struct ToolPlugin;

impl Plugin for ToolPlugin {
    fn build(&self, app: &mut App) {
        super::spawn_with_scene(app, spawn_tool);
        app.add_systems(
            Update,
            (follow_device, draw_force, draw_shaft).in_set(FrameSet::Draw),
        );
    }
}

fn spawn_tool(
    mut commands: Commands,
    link: Res<HapticLink>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        SceneView,
        ToolTip,
        Mesh3d(meshes.add(Sphere::new(link.scene.probe.tip_radius_m as f32))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.75, 0.77, 0.80),
            metallic: 0.9,
            perceptual_roughness: 0.25,
            ..default()
        })),
        Transform::default(),
        Visibility::Hidden,
    ));
    let shaft = meshes.add(Cylinder::new(SHAFT_RADIUS_M, 1.0));
    let steel = materials.add(StandardMaterial {
        base_color: Color::srgb(0.55, 0.57, 0.60),
        metallic: 0.85,
        perceptual_roughness: 0.3,
        ..default()
    });
    for (index, instrument) in link.scene.hands[0].instruments.iter().enumerate() {
        if instrument.port.is_some() {
            commands.spawn((
                SceneView,
                Shaft(index),
                Mesh3d(shaft.clone()),
                MeshMaterial3d(steel.clone()),
                Transform::default(),
                Visibility::Hidden,
            ));
        }
    }
}

fn follow_device(
    snapshot: Res<Snapshot>,
    mut tip: Query<(&mut Transform, &mut Visibility), With<ToolTip>>,
) {
    let Ok((mut transform, mut visibility)) = tip.single_mut() else {
        return;
    };
    match snapshot.0.first_hand().tip_m {
        Some(p) => {
            transform.translation = to_bevy(&p);
            *visibility = Visibility::Visible;
        }
        None => *visibility = Visibility::Hidden,
    }
}

/// Each instrument's shaft from its handle to its tip (the unit cylinder stretched along the
/// line between them): the one in hand where the device holds it, the others where they were
/// put down; one never taken up is not drawn.
fn draw_shaft(
    link: Res<HapticLink>,
    snapshot: Res<Snapshot>,
    mut shafts: Query<(&Shaft, &mut Transform, &mut Visibility)>,
) {
    let instruments = &snapshot.0.first_hand().instruments;
    for (shaft, mut transform, mut visibility) in &mut shafts {
        let ends = if shaft.0 == instruments.in_hand {
            snapshot
                .0
                .first_hand()
                .handle_m
                .zip(snapshot.0.first_hand().tip_m)
        } else {
            let port = link.scene.hands[0].instruments[shaft.0].port;
            (instruments.put_down[shaft.0].zip(port))
                .and_then(|(handle, port)| Some((handle, port.pose(&handle)?.tip_m)))
        };
        let Some((handle, tip)) = ends else {
            *visibility = Visibility::Hidden;
            continue;
        };
        let (handle, tip) = (to_bevy(&handle), to_bevy(&tip));
        let along = tip - handle;
        *transform = Transform::from_translation((handle + tip) / 2.0)
            .with_rotation(Quat::from_rotation_arc(
                Vec3::Y,
                along.normalize_or(Vec3::Y),
            ))
            .with_scale(Vec3::new(1.0, along.length(), 1.0));
        *visibility = Visibility::Visible;
    }
}

fn draw_force(snapshot: Res<Snapshot>, mut gizmos: Gizmos) {
    let (Some(tip), force) = (
        snapshot.0.first_hand().tip_m,
        snapshot.0.first_hand().force_n,
    ) else {
        return;
    };
    if force.norm() < 1e-4 {
        return;
    }
    let start = to_bevy(&tip);
    let arrow = to_bevy(&force) * ARROW_M_PER_N;
    let colour = if snapshot.0.first_hand().faulted {
        Color::srgb(1.0, 0.2, 0.2)
    } else {
        Color::srgb(1.0, 0.85, 0.2)
    };
    gizmos.arrow(start, start + arrow, colour);
}
