//! The virtual device, driven from the window: the tool tip follows the cursor on the plane
//! facing the camera through the tip, and the wheel (or W/S, ↑/↓) pushes it in and out along
//! the view. Ctrl + wheel is the camera's zoom; a held right or middle button, its orbit or
//! pan, during which the tool stays where it is. Q and E turn the handle (a scalpel's edge)
//! about the axis facing the surgeon. Through a port the cursor still leads the tip: the
//! handle goes where the shaft to it must be. Tab is the device's second button: it changes
//! the instrument in hand, where a scenario gives several. With two hands on the mouse, it
//! drives one at a time ([`MouseHand`]): H hands it to the other, and the hand let go holds
//! its place, its buttons as they were (a closed grasper keeps its hold).

use std::sync::Arc;

use bevy::ecs::system::SystemParam;
use bevy::input::mouse::{MouseScrollUnit, MouseWheel};
use bevy::prelude::*;

use super::bridge::{HapticLink, HapticView};
use super::{FrameSet, from_bevy, to_bevy};
use crate::devices::{CHANGE_BUTTON, VirtualHandle};

/// How far one wheel notch moves the tip along the view (m).
const WHEEL_STEP_M: f32 = 0.002;
/// How fast W/S move the tip along the view (m/s).
const KEY_SPEED_M_PER_S: f32 = 0.02;
/// Pixels of a touchpad scroll per wheel notch.
const PIXELS_PER_NOTCH: f32 = 20.0;
/// How fast Q/E turn the handle (rad/s).
const TURN_RAD_PER_S: f64 = std::f64::consts::FRAC_PI_2;

/// The mouse and keys driving the virtual device.
pub(super) struct InputPlugin;

impl Plugin for InputPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<MouseHand>().add_systems(
            Update,
            (change_hand, drive_virtual_device, turn_and_press)
                .chain()
                .in_set(FrameSet::Input),
        );
    }
}

/// The hand the mouse drives (0 the right, 1 the left).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MouseHand(pub usize);

/// H hands the mouse to the next hand it can drive; one the scene lacks goes back to the first.
fn change_hand(
    link: Res<HapticLink>,
    keys: Res<ButtonInput<KeyCode>>,
    mut hand: ResMut<MouseHand>,
) {
    let driven = |h: &usize| link.mice.get(*h).is_some_and(Option::is_some);
    if !driven(&hand.0) {
        hand.0 = (0..link.mice.len()).find(driven).unwrap_or(0);
    }
    if keys.just_pressed(KeyCode::KeyH) {
        let hands = link.mice.len();
        let next = (1..hands).map(|k| (hand.0 + k) % hands).find(driven);
        hand.0 = next.unwrap_or(hand.0);
    }
}

/// The mouse's handle of the hand it drives, if it drives one.
fn driven(link: &HapticLink, hand: MouseHand) -> Option<&Arc<VirtualHandle>> {
    link.mice.get(hand.0)?.as_ref()
}

/// The window and the camera the cursor is cast from.
#[derive(SystemParam)]
struct CursorView<'w, 's> {
    windows: Query<'w, 's, &'static Window>,
    cameras: Query<'w, 's, (&'static Camera, &'static GlobalTransform)>,
}

fn drive_virtual_device(
    haptic: HapticView,
    view: CursorView,
    mut wheel: MessageReader<MouseWheel>,
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    time: Res<Time>,
    mouse: Res<MouseHand>,
) {
    let (link, snapshot) = (&haptic.link, &haptic.snapshot);
    let (Some(handle), Some(hand), Some(published)) = (
        driven(link, *mouse),
        link.scene.hands.get(mouse.0),
        snapshot.0.hands.get(mouse.0),
    ) else {
        return;
    };
    let (Ok(window), Ok((camera, eye))) = (view.windows.single(), view.cameras.single()) else {
        return;
    };
    let forward = eye.forward();
    // The cursor places the tip of the instrument in hand in the scene; the device's handle
    // is in its own workspace, offset by the instrument's indexing and, through its port,
    // where the shaft to that tip puts it.
    let workspace = hand.workspace;
    let instruments = &published.instruments;
    let port = (hand.instruments.get(instruments.in_hand)).and_then(|i| i.port);
    let offset_m = instruments.offset_m;
    let handle_m = workspace.to_scene_m(&handle.tip_m()) + offset_m;
    let tip_m = port
        .and_then(|p| p.pose(&handle_m))
        .map_or(handle_m, |pose| pose.tip_m);
    let mut tip = to_bevy(&tip_m);
    let steering_camera =
        buttons.pressed(MouseButton::Right) || buttons.pressed(MouseButton::Middle);
    if !steering_camera
        && let Some(cursor) = window.cursor_position()
        && let Ok(ray) = camera.viewport_to_world(eye, cursor)
        && let Some(distance) = ray.intersect_plane(tip, InfinitePlane3d::new(*forward))
    {
        tip = ray.get_point(distance);
    }
    let ctrl = keys.pressed(KeyCode::ControlLeft) || keys.pressed(KeyCode::ControlRight);
    let notches: f32 = wheel
        .read()
        .filter(|_| !ctrl)
        .map(|w| match w.unit {
            MouseScrollUnit::Line => w.y,
            MouseScrollUnit::Pixel => w.y / PIXELS_PER_NOTCH,
        })
        .sum();
    let pressed = |a: KeyCode, b: KeyCode| keys.pressed(a) || keys.pressed(b);
    let keyed = match (
        pressed(KeyCode::KeyW, KeyCode::ArrowUp),
        pressed(KeyCode::KeyS, KeyCode::ArrowDown),
    ) {
        (true, false) => 1.0,
        (false, true) => -1.0,
        _ => 0.0,
    };
    let push = notches * WHEEL_STEP_M + keyed * KEY_SPEED_M_PER_S * time.delta_secs();
    let tip_m = from_bevy(tip + *forward * push);
    let handle_m = port.map_or(Some(tip_m), |p| p.handle_for(&tip_m));
    if let Some(handle_m) = handle_m {
        handle.set_tip(&workspace.to_device(&(handle_m - offset_m)));
    }
}

/// Q and E turn the handle; the left button is the device's first button (a stylus button on
/// hardware), Tab its second.
fn turn_and_press(
    link: Res<HapticLink>,
    mouse: Res<MouseHand>,
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    time: Res<Time>,
) {
    let Some(handle) = driven(&link, *mouse) else {
        return;
    };
    let turning = match (keys.pressed(KeyCode::KeyQ), keys.pressed(KeyCode::KeyE)) {
        (true, false) => 1.0,
        (false, true) => -1.0,
        _ => 0.0,
    };
    let turn = handle.turn_rad() + turning * TURN_RAD_PER_S * time.delta_secs_f64();
    handle.set_turn(turn);
    let change = if keys.pressed(KeyCode::Tab) {
        CHANGE_BUTTON
    } else {
        0
    };
    handle.set_buttons(u32::from(buttons.pressed(MouseButton::Left)) | change);
}
