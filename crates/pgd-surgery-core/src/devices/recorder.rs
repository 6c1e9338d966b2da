//! The recorder: wraps any device and keeps what it reported, to be written as a trajectory the
//! scripted device replays. Samples are kept in memory (about 100 bytes a tick: 6 MB a minute)
//! and written when the run ends, so the haptic thread never waits on a disk.

use std::path::{Path, PathBuf};

use super::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, Trajectory, TrajectoryError,
    TrajectoryRow,
};

pub struct Recorder {
    inner: Box<dyn HapticDevice>,
    name: String,
    path: PathBuf,
    recorded: Trajectory,
}

impl Recorder {
    pub fn new(inner: Box<dyn HapticDevice>, path: &Path) -> Self {
        Self {
            name: format!("{} (recorded to {})", inner.name(), path.display()),
            inner,
            path: path.to_owned(),
            recorded: Trajectory::default(),
        }
    }

    /// Writes what was recorded so far.
    pub fn save(&self) -> Result<(), TrajectoryError> {
        self.recorded.save(&self.path)
    }
}

impl HapticDevice for Recorder {
    fn name(&self) -> &str {
        &self.name
    }

    fn limits(&self) -> DeviceLimits {
        self.inner.limits()
    }

    /// Reads the wrapped device and records what it reported; a non-finite or repeated-time
    /// sample is not recorded (the file must replay).
    fn read(&mut self, time_s: f64) -> Result<DeviceSample, DeviceError> {
        let sample = self.inner.read(time_s)?;
        let later = self.recorded.rows.last().is_none_or(|r| time_s > r.time_s);
        if sample.is_finite() && later {
            self.recorded.rows.push(TrajectoryRow::new(time_s, &sample));
        }
        Ok(sample)
    }

    /// The wrapped device guards the force again against its own peak.
    fn render(&mut self, force: EdgeForce) -> Result<(), DeviceError> {
        self.inner.write_force(force.newtons())
    }
}

impl Drop for Recorder {
    /// A run that ends keeps its recording; a failure to write is reported, not swallowed.
    fn drop(&mut self) {
        if self.recorded.rows.is_empty() {
            return;
        }
        match self.save() {
            Ok(()) => eprintln!(
                "recorded {} samples to {}",
                self.recorded.rows.len(),
                self.path.display()
            ),
            Err(e) => eprintln!("recorder: could not write the recording: {e}"),
        }
    }
}
