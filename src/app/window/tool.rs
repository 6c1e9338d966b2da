//! The tools as the trainee sees them, one a hand: a sphere at the tip each device reports,
//! the steel shaft of each instrument through a port (the one in hand, and those put down
//! where they were left), and an arrow of the force each device renders; and the assistant's
//! instrument, where the scene has one.

use bevy::prelude::*;

use super::bridge::{HapticLink, Snapshot};
use super::{FrameSet, SceneView, to_bevy};

/// The sphere drawn at a hand's tool tip (the hand's index: 0 the right).
#[derive(Component)]
pub(super) struct ToolTip(pub(super) usize);

/// An instrument's shaft through its port: a steel rod from its handle to its tip.
#[derive(Component)]
pub(super) struct Shaft {
    /// The hand holding it...
    hand: usize,
    /// ...and its place among that hand's instruments.
    index: usize,
}

/// The assistant's instrument: its tip's sphere and its shaft.
#[derive(Component, Clone, Copy, PartialEq, Eq)]
pub(super) enum AssistantPart {
    Tip,
    Shaft,
}

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
            (follow_device, draw_force, draw_shaft, follow_assistant).in_set(FrameSet::Draw),
        );
    }
}

fn spawn_tool(
    mut commands: Commands,
    link: Res<HapticLink>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let sphere = meshes.add(Sphere::new(link.scene.probe.tip_radius_m as f32));
    let polished = materials.add(StandardMaterial {
        base_color: Color::srgb(0.75, 0.77, 0.80),
        metallic: 0.9,
        perceptual_roughness: 0.25,
        ..default()
    });
    for hand in 0..link.scene.hands.len() {
        commands.spawn((
            SceneView,
            ToolTip(hand),
            Mesh3d(sphere.clone()),
            MeshMaterial3d(polished.clone()),
            Transform::default(),
            Visibility::Hidden,
        ));
    }
    let shaft = meshes.add(Cylinder::new(SHAFT_RADIUS_M, 1.0));
    let steel = materials.add(StandardMaterial {
        base_color: Color::srgb(0.55, 0.57, 0.60),
        metallic: 0.85,
        perceptual_roughness: 0.3,
        ..default()
    });
    let instruments = (link.scene.hands.iter().enumerate()).flat_map(|(hand, h)| {
        h.instruments
            .iter()
            .enumerate()
            .map(move |(k, i)| (hand, k, i))
    });
    for (hand, index, instrument) in instruments {
        if instrument.port.is_some() {
            commands.spawn((
                SceneView,
                Shaft { hand, index },
                Mesh3d(shaft.clone()),
                MeshMaterial3d(steel.clone()),
                Transform::default(),
                Visibility::Hidden,
            ));
        }
    }
    if link.scene.assistant.is_some() {
        let parts = [
            (AssistantPart::Tip, Mesh3d(sphere), MeshMaterial3d(polished)),
            (AssistantPart::Shaft, Mesh3d(shaft), MeshMaterial3d(steel)),
        ];
        for (part, mesh, material) in parts {
            let hidden = (Transform::default(), Visibility::Hidden);
            commands.spawn((SceneView, part, mesh, material, hidden));
        }
    }
}

fn follow_device(
    snapshot: Res<Snapshot>,
    mut tips: Query<(&ToolTip, &mut Transform, &mut Visibility)>,
) {
    for (tip, mut transform, mut visibility) in &mut tips {
        match snapshot.0.hands.get(tip.0).and_then(|hand| hand.tip_m) {
            Some(p) => {
                transform.translation = to_bevy(&p);
                *visibility = Visibility::Visible;
            }
            None => *visibility = Visibility::Hidden,
        }
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
    for (shaft, mut transform, mut visibility) in &mut shafts {
        let Some(hand) = snapshot.0.hands.get(shaft.hand) else {
            continue;
        };
        let ends = if shaft.index == hand.instruments.in_hand {
            hand.handle_m.zip(hand.tip_m)
        } else {
            let port = link.scene.hands[shaft.hand].instruments[shaft.index].port;
            (hand.instruments.put_down[shaft.index].zip(port))
                .and_then(|(handle, port)| Some((handle, port.pose(&handle)?.tip_m)))
        };
        let Some((handle, tip)) = ends else {
            *visibility = Visibility::Hidden;
            continue;
        };
        *transform = shaft_between(&handle, &tip);
        *visibility = Visibility::Visible;
    }
}

/// The assistant's tip and shaft where its script has them.
fn follow_assistant(
    snapshot: Res<Snapshot>,
    mut parts: Query<(&AssistantPart, &mut Transform, &mut Visibility)>,
) {
    let assistant = snapshot.0.assistant.as_ref();
    for (part, mut transform, mut visibility) in &mut parts {
        let placed = match part {
            AssistantPart::Tip => (assistant.and_then(|a| a.tip_m))
                .map(|tip| Transform::from_translation(to_bevy(&tip))),
            AssistantPart::Shaft => (assistant.and_then(|a| a.handle_m.zip(a.tip_m)))
                .map(|(handle, tip)| shaft_between(&handle, &tip)),
        };
        match placed {
            Some(placed) => (*transform, *visibility) = (placed, Visibility::Visible),
            None => *visibility = Visibility::Hidden,
        }
    }
}

/// The unit shaft stretched along the line from `handle` to `tip`.
fn shaft_between(handle: &nalgebra::Vector3<f64>, tip: &nalgebra::Vector3<f64>) -> Transform {
    let (handle, tip) = (to_bevy(handle), to_bevy(tip));
    let along = tip - handle;
    Transform::from_translation((handle + tip) / 2.0)
        .with_rotation(Quat::from_rotation_arc(
            Vec3::Y,
            along.normalize_or(Vec3::Y),
        ))
        .with_scale(Vec3::new(1.0, along.length(), 1.0))
}

/// Each hand's force as an arrow from its tip, red while the hand's force is faded after a
/// fault.
fn draw_force(snapshot: Res<Snapshot>, mut gizmos: Gizmos) {
    for hand in &snapshot.0.hands {
        let Some(tip) = hand.tip_m else {
            continue;
        };
        if hand.force_n.norm() < 1e-4 {
            continue;
        }
        let start = to_bevy(&tip);
        let arrow = to_bevy(&hand.force_n) * ARROW_M_PER_N;
        let colour = match hand.faulted {
            true => Color::srgb(1.0, 0.2, 0.2),
            false => Color::srgb(1.0, 0.85, 0.2),
        };
        gizmos.arrow(start, start + arrow, colour);
    }
}
