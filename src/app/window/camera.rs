//! A camera that orbits, pans and zooms like other 3D tools: right-drag orbits around the
//! point it looks at, middle-drag pans, +/- (or Ctrl + wheel) zooms. The plain wheel is the
//! tool's, so zoom keeps off it.

use bevy::input::mouse::{AccumulatedMouseMotion, MouseScrollUnit, MouseWheel};
use bevy::prelude::*;

use super::FrameSet;
use super::laparoscope::CameraMode;

/// Radians of orbit per pixel dragged.
const ORBIT_PER_PIXEL: f32 = 0.005;
/// Zoom factor per key press, per frame held, or per wheel notch.
const ZOOM_STEP: f32 = 1.1;

/// Spherical coordinates of the camera around the point it looks at; the scene's +z (the
/// patient's head) stays up the screen.
#[derive(Component, Clone, Copy, Debug)]
pub(super) struct Orbit {
    centre: Vec3,
    distance: f32,
    /// Around +z, from +y.
    azimuth: f32,
    /// Up from the xy-plane towards +z.
    elevation: f32,
    /// How near and how far it may zoom (m): from a seventh to six times its first distance.
    zoom_m: (f32, f32),
}

impl Orbit {
    pub(super) fn looking_at(centre: Vec3, offset: Vec3) -> Self {
        let distance = offset.length();
        Self {
            centre,
            distance,
            azimuth: offset.x.atan2(offset.y),
            elevation: (offset.z / distance).asin(),
            zoom_m: (distance / 7.0, distance * 6.0),
        }
    }

    /// The near clipping plane (m) for the nearest it may zoom to.
    pub(super) fn near_m(&self) -> f32 {
        self.zoom_m.0 / 10.0
    }

    pub(super) fn transform(&self) -> Transform {
        let (sa, ca) = self.azimuth.sin_cos();
        let (se, ce) = self.elevation.sin_cos();
        let offset = Vec3::new(sa * ce, ca * ce, se) * self.distance;
        Transform::from_translation(self.centre + offset).looking_at(self.centre, Vec3::Z)
    }
}

/// The free camera.
pub(super) struct CameraPlugin;

impl Plugin for CameraPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            Update,
            orbit
                .in_set(FrameSet::Input)
                .run_if(resource_equals(CameraMode::Free)),
        );
    }
}

fn orbit(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    motion: Res<AccumulatedMouseMotion>,
    mut wheel: MessageReader<MouseWheel>,
    mut cameras: Query<(&mut Orbit, &mut Transform)>,
) {
    let Ok((mut orbit, mut transform)) = cameras.single_mut() else {
        return;
    };
    let drag = motion.delta;
    if buttons.pressed(MouseButton::Right) {
        orbit.azimuth -= drag.x * ORBIT_PER_PIXEL;
        orbit.elevation = (orbit.elevation + drag.y * ORBIT_PER_PIXEL).clamp(-1.4, 1.4);
    }
    if buttons.pressed(MouseButton::Middle) {
        let scale = orbit.distance * ORBIT_PER_PIXEL * 0.3;
        let pan = transform.right() * -drag.x * scale + transform.up() * drag.y * scale;
        orbit.centre += pan;
    }
    let ctrl = keys.pressed(KeyCode::ControlLeft) || keys.pressed(KeyCode::ControlRight);
    let notches: f32 = wheel
        .read()
        .filter(|_| ctrl)
        .map(|w| match w.unit {
            MouseScrollUnit::Line => w.y,
            MouseScrollUnit::Pixel => w.y / 20.0,
        })
        .sum();
    let keyed = f32::from(keys.pressed(KeyCode::Minus)) - f32::from(keys.pressed(KeyCode::Equal));
    let (nearest, farthest) = orbit.zoom_m;
    orbit.distance = (orbit.distance * ZOOM_STEP.powf(keyed - notches)).clamp(nearest, farthest);
    *transform = orbit.transform();
}
