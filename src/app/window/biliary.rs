//! The biliary tree as the trainee sees it: the ducts and the artery as tubes that bend and
//! part where divided, the hepatocystic triangle's fat until it is cleared, the titanium clips
//! on the tubes, and what an open stump lets out pooling below it (blood hides what it
//! covers; bile stains).

use bevy::prelude::*;
use nalgebra::Vector3;

use super::bridge::{HapticLink, Snapshot};
use super::{FrameSet, SceneView, to_bevy};
use crate::app::haptic::{ClipView, LeakView};
use crate::biliary::{Fluid, Structure};

/// A segment of a tube: the tube's place in the tree and the segment's.
#[derive(Component)]
struct TubeSegment {
    tube: usize,
    segment: usize,
}

/// A strand of the triangle's fat.
#[derive(Component)]
struct FatPiece(usize);

/// The `k`th clip, drawn once there is one.
#[derive(Component)]
struct ClipMark(usize);

/// The pool of the `leak`th open stump, drawn when it lets out `fluid` (each stump has one
/// of each fluid's colour).
#[derive(Component)]
struct Pool {
    leak: usize,
    fluid: Fluid,
}

/// Room for this many clips and open stumps drawn (the tree keeps as many).
const CLIPS_DRAWN: usize = 32;
const LEAKS_DRAWN: usize = 64;

/// A clip's size across its tube beyond the tube's diameter, along it, and its depth (m).
const CLIP_OVERHANG_M: f32 = 0.001;
const CLIP_WIDTH_M: f32 = 0.0012;
const CLIP_DEPTH_M: f32 = 0.0015;
/// A pool's depth (m): what a stump has let out spreads this thick, up to 40 mm across.
const POOL_DEPTH_M: f64 = 0.002;
const POOL_MAX_RADIUS_M: f64 = 0.02;
/// Blood and bile run back along gravity (the patient supine: to the back) before pooling.
const POOL_DROP_M: f32 = 0.004;

pub(super) struct BiliaryPlugin;

impl Plugin for BiliaryPlugin {
    fn build(&self, app: &mut App) {
        super::spawn_with_scene(app, spawn_tree);
        app.add_systems(
            Update,
            (draw_tubes, draw_fat, draw_clips, draw_pools).in_set(FrameSet::Draw),
        );
    }
}

/// A surface of `colour`, translucent where `alpha` is below 1.
fn tissue(
    materials: &mut Assets<StandardMaterial>,
    colour: Color,
    alpha: f32,
) -> Handle<StandardMaterial> {
    materials.add(StandardMaterial {
        base_color: colour.with_alpha(alpha),
        perceptual_roughness: 0.45,
        alpha_mode: if alpha < 1.0 {
            AlphaMode::Blend
        } else {
            AlphaMode::Opaque
        },
        ..default()
    })
}

fn spawn_tree(
    mut commands: Commands,
    link: Res<HapticLink>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let Some(biliary) = &link.scene.biliary else {
        return;
    };
    let cylinder = meshes.add(Cylinder::new(1.0, 1.0));
    let duct = tissue(&mut materials, Color::srgb(0.62, 0.72, 0.48), 1.0);
    let artery = tissue(&mut materials, Color::srgb(0.72, 0.14, 0.12), 1.0);
    let fat = tissue(&mut materials, Color::srgb(0.96, 0.86, 0.45), 0.85);
    let titanium = materials.add(StandardMaterial {
        base_color: Color::srgb(0.78, 0.78, 0.8),
        metallic: 0.9,
        perceptual_roughness: 0.3,
        ..default()
    });
    let hidden = |mesh: &Handle<Mesh>, material: &Handle<StandardMaterial>| {
        (
            SceneView,
            Mesh3d(mesh.clone()),
            MeshMaterial3d(material.clone()),
            Transform::default(),
            Visibility::Hidden,
        )
    };
    for (t, tube) in biliary.tree.tubes.iter().enumerate() {
        let material = match tube.structure {
            Structure::CysticArtery => &artery,
            _ => &duct,
        };
        for segment in 0..tube.rod.nodes() - 1 {
            commands.spawn((
                TubeSegment { tube: t, segment },
                hidden(&cylinder, material),
            ));
        }
    }
    for k in 0..biliary.tree.fat.strands.len() {
        commands.spawn((FatPiece(k), hidden(&cylinder, &fat)));
    }
    let bar = meshes.add(Cuboid::new(1.0, 1.0, 1.0));
    for k in 0..CLIPS_DRAWN {
        commands.spawn((ClipMark(k), hidden(&bar, &titanium)));
    }
    let disc = meshes.add(Cylinder::new(1.0, 1.0));
    let blood = tissue(&mut materials, Color::srgb(0.45, 0.02, 0.02), 1.0);
    let bile = tissue(&mut materials, Color::srgb(0.42, 0.55, 0.08), 0.8);
    for leak in 0..LEAKS_DRAWN {
        for (fluid, material) in [(Fluid::Blood, &blood), (Fluid::Bile, &bile)] {
            commands.spawn((Pool { leak, fluid }, hidden(&disc, material)));
        }
    }
}

/// The unit cylinder stretched from `from` to `to` at `radius`.
fn rod_between(from: Vec3, to: Vec3, radius: f32) -> Transform {
    let along = to - from;
    Transform::from_translation((from + to) / 2.0)
        .with_rotation(Quat::from_rotation_arc(
            Vec3::Y,
            along.normalize_or(Vec3::Y),
        ))
        .with_scale(Vec3::new(radius, along.length(), radius))
}

fn draw_tubes(
    snapshot: Res<Snapshot>,
    mut segments: Query<(&TubeSegment, &mut Transform, &mut Visibility)>,
) {
    let Some(view) = &snapshot.0.biliary else {
        return;
    };
    for (piece, mut transform, mut visibility) in &mut segments {
        let Some(tube) = view.tubes.get(piece.tube) else {
            continue;
        };
        let (Some(from), Some(to)) = (
            tube.nodes_m.get(piece.segment),
            tube.nodes_m.get(piece.segment + 1),
        ) else {
            continue;
        };
        if tube.divided[piece.segment] {
            *visibility = Visibility::Hidden;
            continue;
        }
        *transform = rod_between(to_bevy(from), to_bevy(to), tube.radius_m as f32);
        *visibility = Visibility::Visible;
    }
}

fn draw_fat(
    snapshot: Res<Snapshot>,
    mut pieces: Query<(&FatPiece, &mut Transform, &mut Visibility)>,
) {
    let Some(view) = &snapshot.0.biliary else {
        return;
    };
    for (piece, mut transform, mut visibility) in &mut pieces {
        let Some(strand) = view.fat.get(piece.0) else {
            continue;
        };
        if strand.cleared {
            *visibility = Visibility::Hidden;
            continue;
        }
        let axis = strand.axis;
        *transform = rod_between(
            to_bevy(&axis.from_m),
            to_bevy(&axis.to_m),
            strand.radius_m as f32,
        );
        *visibility = Visibility::Visible;
    }
}

/// A clip: a bar across its tube, a little longer than the tube is wide.
fn clip_transform(clip: &ClipView) -> Transform {
    let along = to_bevy(&clip.along).normalize_or(Vec3::X);
    let across = along.any_orthonormal_vector();
    let length = 2.0 * clip.radius_m as f32 + CLIP_OVERHANG_M;
    Transform::from_translation(to_bevy(&clip.at_m))
        .with_rotation(Quat::from_mat3(&Mat3::from_cols(
            across,
            along,
            across.cross(along),
        )))
        .with_scale(Vec3::new(length, CLIP_WIDTH_M, CLIP_DEPTH_M))
}

fn draw_clips(
    snapshot: Res<Snapshot>,
    mut clips: Query<(&ClipMark, &mut Transform, &mut Visibility)>,
) {
    let placed = snapshot
        .0
        .biliary
        .as_ref()
        .map_or(&[][..], |v| &v.clips[..]);
    for (mark, mut transform, mut visibility) in &mut clips {
        match placed.get(mark.0) {
            Some(clip) => {
                *transform = clip_transform(clip);
                *visibility = Visibility::Visible;
            }
            None => *visibility = Visibility::Hidden,
        }
    }
}

/// A pool below an open stump, as wide as what it let out spread [`POOL_DEPTH_M`] thick.
fn pool_transform(leak: &LeakView) -> Option<Transform> {
    let radius = (leak.lost_m3 / (std::f64::consts::PI * POOL_DEPTH_M)).sqrt();
    if radius < 1e-4 {
        return None;
    }
    let radius = radius.min(POOL_MAX_RADIUS_M) as f32;
    // The unit disc's axis is the scene's y, the way gravity pulls a supine patient's fluids.
    let below = to_bevy(&(leak.at_m - Vector3::y() * f64::from(POOL_DROP_M)));
    Some(Transform::from_translation(below).with_scale(Vec3::new(
        radius,
        POOL_DEPTH_M as f32,
        radius,
    )))
}

/// Each open stump's pool, in its fluid's colour.
fn draw_pools(snapshot: Res<Snapshot>, mut pools: Query<(&Pool, &mut Transform, &mut Visibility)>) {
    let leaks = snapshot
        .0
        .biliary
        .as_ref()
        .map_or(&[][..], |v| &v.leaks[..]);
    for (pool, mut transform, mut visibility) in &mut pools {
        let leak = (leaks.get(pool.leak)).filter(|leak| leak.fluid == pool.fluid);
        match leak.and_then(pool_transform) {
            Some(at) => {
                *transform = at;
                *visibility = Visibility::Visible;
            }
            None => *visibility = Visibility::Hidden,
        }
    }
}
