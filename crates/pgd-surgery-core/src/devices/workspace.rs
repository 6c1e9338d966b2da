//! How the device's workspace maps onto the scene: a desktop device reaches a few centimetres
//! each way, and a scenario may scale its motion up to reach a whole organ, or down for fine
//! work. The forces are not scaled, so the tissue feels `scale` times stiffer under the hand.

use nalgebra::Vector3;

use super::DeviceSample;

/// The tool tip in the scene is `scale ×` the device's tip, both about the scene's origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Workspace {
    pub scale: f64,
}

impl Default for Workspace {
    fn default() -> Self {
        Self { scale: 1.0 }
    }
}

impl Workspace {
    /// The device's sample as the scene's tool (its orientation and buttons unchanged).
    pub fn to_scene(&self, sample: DeviceSample) -> DeviceSample {
        DeviceSample {
            tip_m: self.to_scene_m(&sample.tip_m),
            ..sample
        }
    }

    /// Where the tool is for the device at `device_m`.
    pub fn to_scene_m(&self, device_m: &Vector3<f64>) -> Vector3<f64> {
        device_m * self.scale
    }

    /// Where the device must be for the tool to be at `scene_m`.
    pub fn to_device(&self, scene_m: &Vector3<f64>) -> Vector3<f64> {
        scene_m / self.scale
    }
}
