//! The link to the haptic thread: the latest snapshot, read once per frame without waiting.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use super::{FrameSet, WindowScene};
use crate::app::haptic::{HapticScene, HapticSnapshot};
use crate::devices::VirtualHandle;
use crate::mesh::organs::Organ;

/// What the window holds of the haptic side.
#[derive(Resource)]
pub struct HapticLink {
    pub scene: HapticScene,
    /// By hand, the virtual device's handle where the mouse drives the hand's tool.
    pub mice: Vec<Option<Arc<VirtualHandle>>>,
    pub device_name: String,
    snapshots: Mutex<triple_buffer::Output<HapticSnapshot>>,
    exit_after: Option<Duration>,
}

impl HapticLink {
    /// Another scene, whose snapshots come from `snapshots` (the haptic thread takes its world
    /// from the scene swap).
    pub(super) fn change_scene(
        &mut self,
        scene: HapticScene,
        snapshots: triple_buffer::Output<HapticSnapshot>,
    ) {
        self.scene = scene;
        self.snapshots = Mutex::new(snapshots);
    }

    /// Whether the mouse drives any hand.
    pub(super) fn mouse_drives(&self) -> bool {
        self.mice.iter().any(Option::is_some)
    }

    /// The centre of the scene's organs (m).
    pub(super) fn scene_centre(&self) -> Vec3 {
        let points = self
            .scene
            .organs
            .iter()
            .flat_map(|(_, v)| v.position_coords_m.iter());
        let (sum, count) = points.fold((Vec3::ZERO, 0), |(s, n), p| (s + Vec3::from(*p), n + 1));
        sum / count.max(1) as f32
    }

    /// How far (m) the scene's organs reach from their centre.
    pub(super) fn scene_radius(&self) -> f32 {
        let centre = self.scene_centre();
        let points = self
            .scene
            .organs
            .iter()
            .flat_map(|(_, v)| v.position_coords_m.iter());
        points.fold(0.0, |r, p| r.max(Vec3::from(*p).distance(centre)))
    }

    /// The direction the surgeon looks at the scene from: its first organ's (anterior, +y,
    /// for the abdomen and for an organ from a mesh file).
    pub(super) fn facing(&self) -> Vec3 {
        let first = self.scene.organs.first().map(|(name, _)| name.as_str());
        let organ = first.and_then(Organ::from_name).unwrap_or(Organ::Liver);
        Vec3::from(organ.facing().map(|c| c as f32))
    }

    /// How far out of an organ's surface (m) the lines drawn on it are lifted, so that it
    /// does not hide them: a sixth of the tool's radius (1 mm for the abdomen's 6 mm tool).
    pub(super) fn line_lift_m(&self) -> f64 {
        self.scene.probe.tip_radius_m / 6.0
    }

    /// A link without a device, for the window's stages in a headless app.
    #[cfg(test)]
    pub(super) fn headless(
        scene: HapticScene,
        snapshots: triple_buffer::Output<HapticSnapshot>,
    ) -> Self {
        Self {
            scene,
            mice: Vec::new(),
            device_name: String::new(),
            snapshots: Mutex::new(snapshots),
            exit_after: None,
        }
    }
}

/// The haptic side as a frame reads it: the link and this frame's snapshot.
#[derive(SystemParam)]
pub(super) struct HapticView<'w> {
    pub link: Res<'w, HapticLink>,
    pub snapshot: Res<'w, Snapshot>,
}

/// The haptic state this frame draws.
#[derive(Resource, Default)]
pub struct Snapshot(pub HapticSnapshot);

/// The link to the haptic side (moved into the app when the plugin is built) and each
/// frame's copy of its latest snapshot.
pub(super) struct BridgePlugin(pub Mutex<Option<HapticLink>>);

impl BridgePlugin {
    pub fn new(window: WindowScene) -> Self {
        Self(Mutex::new(Some(HapticLink {
            scene: window.scene,
            mice: window.mice,
            device_name: window.device_name,
            snapshots: Mutex::new(window.snapshots),
            exit_after: window.exit_after_s.map(Duration::from_secs_f64),
        })))
    }
}

impl Plugin for BridgePlugin {
    fn build(&self, app: &mut App) {
        if let Some(link) = self.0.lock().ok().and_then(|mut link| link.take()) {
            app.insert_resource(link);
        }
        app.init_resource::<Snapshot>()
            .add_systems(Update, (receive, exit_when_due).in_set(FrameSet::Receive));
    }
}

/// Copies the latest complete tick (the triple buffer's reader never blocks the writer; the
/// mutex is only ever taken by this system).
fn receive(link: Res<HapticLink>, mut snapshot: ResMut<Snapshot>) {
    if let Ok(mut output) = link.snapshots.lock() {
        snapshot.0.clone_from(output.read());
    }
}

/// Closes the window once the wall-clock time asked for has passed (virtual time would lag
/// behind on a slow renderer: it caps each frame's step).
fn exit_when_due(link: Res<HapticLink>, time: Res<Time<Real>>, mut exit: MessageWriter<AppExit>) {
    if link.exit_after.is_some_and(|after| time.elapsed() >= after) {
        exit.write(AppExit::Success);
    }
}
