//! The recorder: wraps any device and keeps what it reported, to be written as a trajectory the
//! scripted device replays. Samples are kept in memory (about 100 bytes a tick: 6 MB a minute)
//! and written when the run ends, so the haptic thread never waits on a disk. Both hands of a
//! bimanual run go to one file ([`Recorder::hands`]), written when the last hand's ends.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use super::{
    DeviceError, DeviceLimits, DeviceSample, EdgeForce, HapticDevice, Trajectory, TrajectoryError,
    TrajectoryRow,
};

pub struct Recorder {
    inner: Box<dyn HapticDevice>,
    name: String,
    /// This device's hand in the file.
    hand: usize,
    file: Arc<Mutex<RecordedFile>>,
    recorded: Trajectory,
}

/// The file the hands' recorders write together: each hand's recording once it has ended.
struct RecordedFile {
    path: PathBuf,
    hands: Vec<Option<Trajectory>>,
}

impl Recorder {
    /// Records one hand's device to `path`.
    pub fn new(inner: Box<dyn HapticDevice>, path: &Path) -> Self {
        Self::hands(vec![inner], path).remove(0)
    }

    /// Records the hands' devices (the right hand's first) to one file at `path`.
    pub fn hands(devices: Vec<Box<dyn HapticDevice>>, path: &Path) -> Vec<Self> {
        let file = Arc::new(Mutex::new(RecordedFile {
            path: path.to_owned(),
            hands: vec![None; devices.len()],
        }));
        let recorder = |(hand, inner): (usize, Box<dyn HapticDevice>)| Self {
            name: format!("{} (recorded to {})", inner.name(), path.display()),
            inner,
            hand,
            file: file.clone(),
            recorded: Trajectory::default(),
        };
        devices.into_iter().enumerate().map(recorder).collect()
    }

    /// Writes what this hand recorded so far (alone).
    pub fn save(&self) -> Result<(), TrajectoryError> {
        let path = self.file.lock().map(|f| f.path.clone());
        self.recorded
            .save(&path.unwrap_or_else(|p| p.into_inner().path.clone()))
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
    /// A run that ends keeps its recording, written once every hand's has ended; a failure
    /// to write is reported, not swallowed.
    fn drop(&mut self) {
        let mut file = self.file.lock().unwrap_or_else(|p| p.into_inner());
        file.hands[self.hand] = Some(std::mem::take(&mut self.recorded));
        let Some(hands) = file
            .hands
            .iter()
            .cloned()
            .collect::<Option<Vec<Trajectory>>>()
        else {
            return;
        };
        let samples = hands[0].rows.len();
        if samples == 0 {
            return;
        }
        let both = if hands.len() > 1 {
            " of both hands"
        } else {
            ""
        };
        match Trajectory::save_hands(&file.path, &hands) {
            Ok(()) => eprintln!(
                "recorded {samples} samples{both} to {}",
                file.path.display()
            ),
            Err(e) => eprintln!("recorder: could not write the recording: {e}"),
        }
    }
}
