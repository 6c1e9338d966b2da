//! The hand-over of another scene to the running haptic loop, wherever it ticks (its own
//! thread, or the page's frame loop in a browser).

use std::sync::{Arc, Mutex};

use super::runner::HapticLoop;

/// Another scene for the running thread: a parked loop (see [`HapticLoop::parked`]) offered
/// here is taken at the start of the next tick, with the running loop's device; the loop it
/// replaces is kept here, to be dropped away from the haptic thread.
#[derive(Clone, Default)]
pub struct SceneSwap(Arc<Mutex<Swap>>);

#[derive(Default)]
struct Swap {
    incoming: Option<HapticLoop>,
    retired: Option<HapticLoop>,
}

impl SceneSwap {
    /// Offers `next` to the haptic thread (replacing one offered and not yet taken).
    pub fn offer(&self, next: HapticLoop) {
        let retired = self.0.lock().ok().and_then(|mut swap| {
            swap.incoming = Some(next);
            swap.retired.take()
        });
        // Dropped here, outside the lock, on the caller's thread.
        drop(retired);
    }

    /// Whether a loop offered has not been taken yet.
    pub fn pending(&self) -> bool {
        self.0.lock().is_ok_and(|swap| swap.incoming.is_some())
    }

    /// On the haptic thread: runs the offered loop from now on, if there is one and the lock
    /// is free (never waits).
    pub(super) fn take(&self, running: &mut HapticLoop) {
        if let Ok(mut swap) = self.0.try_lock()
            && let Some(mut next) = swap.incoming.take()
        {
            next.take_devices(running);
            swap.retired = Some(std::mem::replace(running, next));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::haptic::HapticScene;
    use crate::app::haptic::hand::{Device, Safety};
    use crate::app::haptic::resources::TickClock;
    use crate::devices::{DeviceSample, Scripted, Trajectory, TrajectoryRow};
    use nalgebra::Vector3;

    fn scene(max_force_n: f64) -> HapticScene {
        let mut scene = HapticScene::without_organs();
        scene.safety.max_force_n = max_force_n;
        scene
    }

    /// The offered world runs from the next tick with the running one's device, under its own
    /// force limit; the world it replaced is kept for the other side to drop, without a device.
    #[test]
    fn a_swapped_scene_takes_over_the_device() {
        let rows = vec![TrajectoryRow::new(0.0, &DeviceSample::at(Vector3::zeros()))];
        let device = Box::new(Scripted::new("the hand", Trajectory { rows }));
        let mut running = HapticLoop::new(&scene(3.3), device).unwrap();
        let swap = SceneSwap::default();
        swap.offer(HapticLoop::parked(&scene(1.0)).unwrap());
        assert!(swap.pending());
        swap.take(&mut running);
        assert!(!swap.pending());
        assert_eq!(running.device_name(), "the hand");
        assert_eq!(running.hand::<Safety>(0).unwrap().0.max_force_n(), 1.0);
        running.tick(TickClock::default());
        let retired = swap.0.lock().unwrap().retired.take().unwrap();
        assert!(retired.hand::<Device>(0).is_none());
    }

    /// A two-hand scene taking over a one-hand loop: its right hand takes the running loop's
    /// device, its left keeps the one given it while parked.
    #[test]
    fn a_hand_new_to_the_running_loop_keeps_the_device_given_it() {
        let scripted = |name: &str| {
            let rows = vec![TrajectoryRow::new(0.0, &DeviceSample::at(Vector3::zeros()))];
            Box::new(Scripted::new(name, Trajectory { rows }))
        };
        let mut running = HapticLoop::new(&scene(3.3), scripted("the right hand")).unwrap();
        let mut two_hands = scene(3.3);
        two_hands.hands.push(two_hands.hands[0].clone());
        let mut parked = HapticLoop::parked(&two_hands).unwrap();
        parked.give_device(1, scripted("the left hand"));
        let swap = SceneSwap::default();
        swap.offer(parked);
        swap.take(&mut running);
        let name = |hand| running.hand::<Device>(hand).map(|d| d.0.name().to_owned());
        assert_eq!(name(0).as_deref(), Some("the right hand"));
        assert_eq!(name(1).as_deref(), Some("the left hand"));
        assert!(running.hand::<Safety>(1).is_some());
    }
}
