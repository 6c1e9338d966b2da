//! The organs as the trainee sees them: each organ's accessible surface, moved every frame by
//! the latest snapshot's displacement at its vertices (formed there only, from the modes at
//! the surface, [`SurfaceModes`]), with nodal normals recomputed on the
//! deformed surface so that shading follows the deformation; a cut organ's surface split
//! along its cut, with the cut's walls ([`super::cut_surface`]).

use std::sync::Arc;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;

use super::bridge::{HapticLink, Snapshot};
use super::cut_surface::{SplitSurface, walls_mesh};
use super::dissection::tint_burns;
use super::{FrameSet, SceneView, tissue};
use crate::dissection::Wall;
use crate::dynamics::DynamicModel;
use crate::mesh::vertex_normals;
use crate::pgd::{PatchLoad, SurfaceModes, Vademecum};

/// An organ's visual model, mapped to its vademecum through the load positions (surface
/// vertex `k` is volume node `positions[k]`).
#[derive(Component)]
pub(super) struct OrganView {
    index: usize,
    vademecum: Arc<Vademecum>,
    triangles: Vec<[usize; 3]>,
    /// Its modes at the surface vertices, which each frame forms the surface from.
    surface: SurfaceModes,
    /// Scratch: the displacement at the surface vertices (m).
    at_vertices: Vec<f64>,
    /// The organ's dynamic model, when it moves.
    motion: Option<Arc<DynamicModel>>,
    /// Its surface split along the scalpel's latest cut, once it is cut.
    split: Option<SplitSurface>,
}

impl OrganView {
    /// Each vertex split by the cut with its copy across it, as drawn-mesh vertex numbers
    /// (none uncut).
    pub(super) fn lips(&self) -> Vec<(usize, usize)> {
        let vertices = self.vademecum.positions.len();
        self.split
            .as_ref()
            .map_or_else(Vec::new, |s| s.lips(vertices).collect())
    }

    /// The triangles drawn: the surface's, split along the cut once it is cut.
    pub(super) fn drawn_triangles(&self) -> &[[usize; 3]] {
        self.split
            .as_ref()
            .map_or(&self.triangles, |s| &s.triangles)
    }
}

/// The walls of organ `index`'s cut, drawn as the tissue inside.
#[derive(Component)]
struct CutWalls {
    index: usize,
}

/// The colour of cut tissue's inside (sRGB).
const INSIDE: Color = Color::srgb(0.45, 0.07, 0.08);

/// The organs drawn and deformed.
pub(super) struct OrganPlugin;

impl Plugin for OrganPlugin {
    fn build(&self, app: &mut App) {
        super::spawn_with_scene(app, (spawn_organs, spawn_camera_and_light));
        app.add_systems(Update, deform.in_set(FrameSet::Draw));
    }
}

fn spawn_organs(
    mut commands: Commands,
    link: Res<HapticLink>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
) {
    for (index, (name, vademecum)) in link.scene.organs.iter().enumerate() {
        let (colour, roughness) = tissue::images(&tissue::tissue(name));
        let triangles: Vec<[usize; 3]> = vademecum
            .triangles
            .iter()
            .map(|t| t.map(|m| m as usize))
            .collect();
        let mesh = surface_mesh(&triangles, &vademecum.position_coords_m);
        commands.spawn((
            SceneView,
            Name::new(name.clone()),
            Mesh3d(meshes.add(mesh)),
            MeshMaterial3d(materials.add(tissue::wet(images.add(colour), images.add(roughness)))),
            OrganView {
                index,
                surface: SurfaceModes::new(vademecum),
                at_vertices: vec![0.0; 3 * vademecum.positions.len()],
                vademecum: vademecum.clone(),
                triangles,
                motion: link
                    .scene
                    .dynamics
                    .as_ref()
                    .and_then(|d| d.model(index).cloned()),
                split: None,
            },
        ));
        if link
            .scene
            .cutting
            .as_ref()
            .is_some_and(|c| c.organ(index).is_some())
        {
            commands.spawn((
                SceneView,
                CutWalls { index },
                Mesh3d(meshes.add(walls_mesh(Vec::new(), Vec::new()))),
                MeshMaterial3d(materials.add(StandardMaterial {
                    base_color: INSIDE,
                    perceptual_roughness: 0.5,
                    double_sided: true,
                    cull_mode: None,
                    ..default()
                })),
            ));
        }
    }
}

/// The surgeon's view: of a supine patient from above (anterior, +y), head (+z) up the
/// screen; of the cornea from high over its axis, as under an operating microscope.
fn spawn_camera_and_light(mut commands: Commands, link: Res<HapticLink>) {
    let centre = link.scene_centre();
    let (camera, light) = view_of(link.facing(), link.scene_radius());
    let orbit = super::camera::Orbit::looking_at(centre, camera);
    let projection = Projection::Perspective(PerspectiveProjection {
        near: orbit.near_m(),
        ..default()
    });
    commands.spawn((
        SceneView,
        Camera3d::default(),
        projection,
        orbit.transform(),
        orbit,
    ));
    commands.spawn((
        SceneView,
        super::laparoscope::Daylight,
        DirectionalLight {
            illuminance: 9_000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_translation(centre + light).looking_at(centre, Vec3::Z),
    ));
}

/// Where the camera and the light stand from the scene's centre, for a scene seen from
/// `facing` that reaches `radius_m` from its centre.
fn view_of(facing: Vec3, radius_m: f32) -> (Vec3, Vec3) {
    if facing == Vec3::Y {
        return (Vec3::new(0.0, 0.32, -0.10), Vec3::new(0.1, 0.5, -0.2));
    }
    // 70° above the plane square to `facing`, four of the scene's radii away.
    let aside = facing.any_orthonormal_vector();
    let camera = (facing * 0.94 + aside * 0.34) * 4.0 * radius_m;
    (camera, facing + aside * 0.3)
}

fn deform(
    snapshot: Res<Snapshot>,
    link: Res<HapticLink>,
    mut views: Query<(&mut OrganView, &Mesh3d)>,
    walls: Query<(&CutWalls, &Mesh3d)>,
    mut meshes: ResMut<Assets<Mesh>>,
) {
    for (mut view, mesh) in &mut views {
        let Some(organ) = snapshot.0.organs.get(view.index) else {
            continue;
        };
        let view = &mut *view;
        let mut positions = Vec::with_capacity(view.vademecum.positions.len());
        organ.deformation.deformed_surface(
            &view.vademecum,
            &view.surface,
            &mut view.at_vertices,
            &mut positions,
        );
        if let Some(motion) = &view.motion {
            motion.add_to_surface(&view.vademecum.positions, &organ.motion, &mut positions);
        }
        let loads = &organ.deformation.loads;
        if let Some(rebuilt) = refresh_split(view, &link) {
            if let Some(mut mesh) = meshes.get_mut(&mesh.0) {
                *mesh = rebuilt;
            }
            let drawn = walls.iter().find(|(cut, _)| cut.index == view.index);
            if view.split.is_none()
                && let Some(mut walls) = drawn.and_then(|(_, m)| meshes.get_mut(&m.0))
            {
                *walls = walls_mesh(Vec::new(), Vec::new());
            }
        }
        if let Some(split) = &view.split {
            split.displace(&view.vademecum, loads, &mut positions);
            let drawn = walls.iter().find(|(cut, _)| cut.index == view.index);
            if let Some(mut mesh) = drawn.and_then(|(_, m)| meshes.get_mut(&m.0)) {
                let (points, indices) = split.walls(&positions);
                *mesh = walls_mesh(points, indices);
            }
        }
        let triangles = view.drawn_triangles();
        let mut colours = contact_tint(positions.len(), loads);
        if let Some((name, _)) = link.scene.organs.get(view.index) {
            let burns = &snapshot.0.burns;
            tint_burns(
                &mut colours,
                view.index,
                Wall::of_name(name),
                burns,
                &view.vademecum,
            );
        }
        if let Some(mut mesh) = meshes.get_mut(&mesh.0) {
            mesh.insert_attribute(
                Mesh::ATTRIBUTE_NORMAL,
                vertex_normals(triangles, &positions),
            );
            mesh.insert_attribute(Mesh::ATTRIBUTE_POSITION, positions);
            mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, colours);
        }
    }
}

/// Splits the organ's surface anew when the scalpel's cut has grown, or makes it whole again
/// when the cut is healed (a new attempt): the render mesh to replace the organ's (`None`
/// while the split, or the whole surface, stands).
fn refresh_split(view: &mut OrganView, link: &HapticLink) -> Option<Mesh> {
    let cutting = link.scene.cutting.as_ref()?;
    let cut = cutting.organ(view.index)?.drawn.get();
    if cut.unknowns == 0 {
        view.split.take()?;
        return Some(surface_mesh(
            &view.triangles,
            &view.vademecum.position_coords_m,
        ));
    }
    if view.split.as_ref().is_some_and(|s| s.is_of(&cut)) {
        return None;
    }
    let split = SplitSurface::new(cut, &view.vademecum, &view.triangles);
    let rest = split.with_copies(&view.vademecum.position_coords_m);
    let mesh = surface_mesh(&split.triangles, &rest);
    view.split = Some(split);
    Some(mesh)
}

/// Vertex colours that light up the tool's contact patch (by each position's share of the
/// load) and leave the rest of the organ its tissue's colour.
fn contact_tint(vertices: usize, loads: &[PatchLoad]) -> Vec<[f32; 4]> {
    let mut colours = vec![[1.0; 4]; vertices];
    for load in loads {
        let largest = load.shares.iter().map(|s| s.1).fold(0.0, f64::max);
        if largest <= 0.0 {
            continue;
        }
        for &(m, share) in &load.shares {
            let t = (0.7 * share / largest) as f32;
            colours[m] = [1.0 + t, 1.0 + 0.8 * t, 1.0 + 0.3 * t, 1.0];
        }
    }
    colours
}

/// A render mesh of a surface with area-weighted normals of the given positions and texture
/// coordinates fixed at them.
fn surface_mesh(triangles: &[[usize; 3]], positions: &[[f32; 3]]) -> Mesh {
    let indices: Vec<u32> = triangles.iter().flatten().map(|&i| i as u32).collect();
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions.to_vec())
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vertex_normals(triangles, positions))
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, tissue::planar_uvs(positions))
    .with_inserted_attribute(Mesh::ATTRIBUTE_COLOR, contact_tint(positions.len(), &[]))
    .with_inserted_indices(Indices::U32(indices))
}
