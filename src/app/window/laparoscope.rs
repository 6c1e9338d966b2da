//! The laparoscopic view: in a scene with a laparoscope the window looks through it, with its
//! narrow field of view and the only light at its tip (so highlights move with the camera, as
//! in a real abdomen), and the keys steer it about its port. C switches to the educators' free
//! camera and back; the free camera has the daylight of an open abdomen.

use bevy::asset::RenderAssetUsages;
use bevy::camera::Projection;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

use super::bridge::HapticLink;
use super::{FrameSet, SceneView, to_bevy};
use crate::devices::{Laparoscope, ScopePose, Steer, View};

/// How fast the keys pivot the optic about its port (rad/s).
const PIVOT_RAD_PER_S: f64 = 0.35;
/// How fast U/O push the optic in and pull it out (m/s).
const INSERT_M_PER_S: f64 = 0.03;
/// How fast Z/X roll an angled optic (rad/s).
const ROLL_RAD_PER_S: f64 = 1.0;
/// The free camera's vertical field of view (rad), Bevy's default.
const FREE_FOV_RAD: f32 = std::f32::consts::FRAC_PI_4;
/// How brightly the light at the tip lights tissue at the optic's starting distance (lux): a
/// few times the free view's daylight, as tissue seen through the optic is lit obliquely.
const TIP_LUX: f32 = 30_000.0;

/// Which camera the window looks through.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum CameraMode {
    /// Through the scene's laparoscope.
    Laparoscope,
    /// The free orbiting camera (and the only one without a laparoscope).
    #[default]
    Free,
}

/// The light at the optic's tip: a point light (the light guide's wide cone covers more than
/// the image).
#[derive(Component)]
pub(super) struct TipLight;

/// The daylight of the free view.
#[derive(Component)]
pub(super) struct Daylight;

/// The black surround of the round image.
#[derive(Component)]
pub(super) struct Vignette;

/// Texels across the mask of the round image.
const MASK_TEXELS: usize = 256;

/// Whether the window opens a scene with a laparoscope through it, or with the free camera.
#[derive(Resource, Clone, Copy, Debug)]
struct OpenThroughOptic(bool);

/// The laparoscope: the view through its optic, its light and steering, and the free camera
/// it gives way to.
pub(super) struct LaparoscopePlugin {
    /// Open on the free camera even where the scene has a laparoscope.
    pub free_camera: bool,
}

impl Plugin for LaparoscopePlugin {
    fn build(&self, app: &mut App) {
        let free_camera = self.free_camera;
        app.init_resource::<CameraMode>()
            .insert_resource(OpenThroughOptic(!free_camera));
        super::spawn_with_scene(app, (choose_mode, spawn_tip_light, spawn_vignette));
        app.add_systems(
            Update,
            (
                switch_mode,
                steer_optic.run_if(resource_equals(CameraMode::Laparoscope)),
            )
                .chain()
                .in_set(FrameSet::Input),
        )
        .add_systems(
            Update,
            (look_through_optic, light_for_mode).in_set(FrameSet::Draw),
        );
    }
}

/// A scene with a laparoscope opens looking through it, unless told otherwise.
fn choose_mode(link: Res<HapticLink>, open: Res<OpenThroughOptic>, mut mode: ResMut<CameraMode>) {
    *mode = match link.scene.scope.is_some() && open.0 {
        true => CameraMode::Laparoscope,
        false => CameraMode::Free,
    };
}

fn spawn_tip_light(mut commands: Commands, link: Res<HapticLink>) {
    let Some(rig) = &link.scene.scope else {
        return;
    };
    let pose = rig.pose.get();
    let distance_m = start_distance_m(&rig.scope, &pose, link.scene_centre()) as f32;
    commands.spawn((
        SceneView,
        TipLight,
        PointLight {
            // Lumens for TIP_LUX at the starting distance: E = I / r², I = Φ / 4π.
            intensity: TIP_LUX * distance_m * distance_m * 4.0 * std::f32::consts::PI,
            range: 1.0,
            radius: 0.002,
            ..default()
        },
        camera_transform(&rig.scope.view(&pose)),
    ));
}

/// How far the optic looks at the start: from its lens to the scene's centre, along its view.
fn start_distance_m(scope: &Laparoscope, pose: &ScopePose, centre_m: Vec3) -> f64 {
    let view = scope.view(pose);
    let to_centre = super::from_bevy(centre_m) - view.eye_m;
    to_centre.dot(&view.forward).max(0.02)
}

fn camera_transform(view: &View) -> Transform {
    let eye = to_bevy(&view.eye_m);
    Transform::from_translation(eye).looking_to(to_bevy(&view.forward), to_bevy(&view.up))
}

/// C switches between the laparoscope and the free camera (only with a laparoscope).
fn switch_mode(
    keys: Res<ButtonInput<KeyCode>>,
    link: Res<HapticLink>,
    mut mode: ResMut<CameraMode>,
) {
    if link.scene.scope.is_none() || !keys.just_pressed(KeyCode::KeyC) {
        return;
    }
    *mode = match *mode {
        CameraMode::Laparoscope => CameraMode::Free,
        CameraMode::Free => CameraMode::Laparoscope,
    };
}

/// I/K and J/L pivot the optic about its port, U/O push it in and pull it out, Z/X roll it
/// (unless the scenario moves it).
fn steer_optic(keys: Res<ButtonInput<KeyCode>>, link: Res<HapticLink>, time: Res<Time>) {
    let Some(rig) = link.scene.scope.as_ref().filter(|rig| rig.script.is_none()) else {
        return;
    };
    let axis = |plus: KeyCode, minus: KeyCode| {
        f64::from(u8::from(keys.pressed(plus))) - f64::from(u8::from(keys.pressed(minus)))
    };
    let dt = time.delta_secs_f64();
    let steer = Steer {
        right_rad: axis(KeyCode::KeyL, KeyCode::KeyJ) * PIVOT_RAD_PER_S * dt,
        up_rad: axis(KeyCode::KeyI, KeyCode::KeyK) * PIVOT_RAD_PER_S * dt,
        in_m: axis(KeyCode::KeyU, KeyCode::KeyO) * INSERT_M_PER_S * dt,
        roll_rad: axis(KeyCode::KeyX, KeyCode::KeyZ) * ROLL_RAD_PER_S * dt,
    };
    if steer != Steer::default() {
        rig.pose.set(rig.scope.steer(&rig.pose.get(), &steer));
    }
}

/// In the laparoscopic view the camera is the optic's lens, with its field of view; the free
/// camera keeps Bevy's.
fn look_through_optic(
    link: Res<HapticLink>,
    mode: Res<CameraMode>,
    mut cameras: Query<(&mut Transform, &mut Projection), With<Camera3d>>,
    mut lights: Query<&mut Transform, (With<TipLight>, Without<Camera3d>)>,
) {
    let Ok((mut transform, mut projection)) = cameras.single_mut() else {
        return;
    };
    let Some(rig) = &link.scene.scope else {
        return;
    };
    let optic = camera_transform(&rig.scope.view(&rig.pose.get()));
    for mut light in &mut lights {
        *light = optic;
    }
    let fov = match *mode {
        CameraMode::Laparoscope => {
            *transform = optic;
            rig.scope.fov_rad as f32
        }
        CameraMode::Free => FREE_FOV_RAD,
    };
    if let Projection::Perspective(perspective) = &mut *projection
        && perspective.fov != fov
    {
        perspective.fov = fov;
        perspective.near = 0.002;
    }
}

/// What shows in one mode only.
type ModeShown = Or<(With<TipLight>, With<Daylight>, With<Vignette>)>;

/// The tip's light and the round image in the laparoscopic view, daylight in the free one.
fn light_for_mode(
    mode: Res<CameraMode>,
    mut shown: Query<(&mut Visibility, Has<Daylight>), ModeShown>,
) {
    if !mode.is_changed() {
        return;
    }
    let through_optic = *mode == CameraMode::Laparoscope;
    for (mut visibility, daylight) in &mut shown {
        *visibility = match through_optic != daylight {
            true => Visibility::Inherited,
            false => Visibility::Hidden,
        };
    }
}

/// The optic's image is round, inscribed in the window's height: black bars either side and
/// a square mask, clear inside its circle, between them. Behind the HUD's text.
fn spawn_vignette(
    mut commands: Commands,
    link: Res<HapticLink>,
    mut images: ResMut<Assets<Image>>,
) {
    if link.scene.scope.is_none() {
        return;
    }
    let mask = images.add(round_mask());
    let bar = || {
        (
            Node {
                flex_grow: 1.0,
                height: percent(100),
                ..default()
            },
            BackgroundColor(Color::BLACK),
        )
    };
    commands.spawn((
        SceneView,
        Vignette,
        GlobalZIndex(-1),
        Node {
            position_type: PositionType::Absolute,
            width: percent(100),
            height: percent(100),
            flex_direction: FlexDirection::Row,
            ..default()
        },
        children![
            bar(),
            (
                Node {
                    height: percent(100),
                    aspect_ratio: Some(1.0),
                    ..default()
                },
                ImageNode::new(mask),
            ),
            bar(),
        ],
    ));
}

/// Black, opaque outside the inscribed circle and clear inside, with a soft edge of a few
/// texels as a real optic's.
fn round_mask() -> Image {
    let half = MASK_TEXELS as f32 / 2.0;
    let texels: Vec<u8> = (0..MASK_TEXELS * MASK_TEXELS)
        .flat_map(|k| {
            let (x, y) = (
                (k % MASK_TEXELS) as f32 + 0.5,
                (k / MASK_TEXELS) as f32 + 0.5,
            );
            let r = ((x - half).powi(2) + (y - half).powi(2)).sqrt() / half;
            let alpha = ((r - 0.97) / 0.03).clamp(0.0, 1.0);
            [0, 0, 0, (alpha * 255.0).round() as u8]
        })
        .collect();
    Image::new(
        Extent3d {
            width: MASK_TEXELS as u32,
            height: MASK_TEXELS as u32,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        texels,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    )
}
