//! The scripted device: replays a trajectory deterministically, for tests, demos and
//! benchmarks. It has no motors: the forces it is sent are the haptic world's to keep (its
//! force trace), so that two runs can be compared.

use super::{DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, Trajectory};

pub struct Scripted {
    name: String,
    trajectory: Trajectory,
    limits: DeviceLimits,
}

impl Scripted {
    pub fn new(name: impl Into<String>, trajectory: Trajectory) -> Self {
        Self {
            name: name.into(),
            trajectory,
            limits: DeviceLimits::default(),
        }
    }

    pub fn with_limits(mut self, limits: DeviceLimits) -> Self {
        self.limits = limits;
        self
    }
}

impl HapticDevice for Scripted {
    fn name(&self) -> &str {
        &self.name
    }

    fn limits(&self) -> DeviceLimits {
        self.limits
    }

    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError> {
        Ok(self.trajectory.sample(time_s))
    }

    fn render(&mut self, _force: EdgeForce) -> Result<(), DeviceError> {
        Ok(())
    }
}
