//! Trajectory files: what a scripted device replays and a recorder writes. CSV, one row per
//! sample, so that a script can be written by hand or in a spreadsheet:
//!
//! ```text
//! time_s,x_m,y_m,z_m,buttons
//! 0.0,0.02,0.10,0.01,0
//! 0.5,0.02,0.09,0.01,1
//! ```
//!
//! Orientation columns `qx,qy,qz,qw` (a unit quaternion) are optional; without them the tool
//! points along the scene's axes.

use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::DeviceSample;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryRow {
    pub time_s: f64,
    pub x_m: f64,
    pub y_m: f64,
    pub z_m: f64,
    #[serde(default)]
    pub buttons: u32,
    #[serde(default)]
    pub qx: f64,
    #[serde(default)]
    pub qy: f64,
    #[serde(default)]
    pub qz: f64,
    #[serde(default = "one")]
    pub qw: f64,
}

fn one() -> f64 {
    1.0
}

impl TrajectoryRow {
    pub fn new(time_s: f64, sample: &DeviceSample) -> Self {
        let q = sample.orientation.coords;
        Self {
            time_s,
            x_m: sample.tip_m.x,
            y_m: sample.tip_m.y,
            z_m: sample.tip_m.z,
            buttons: sample.buttons,
            qx: q.x,
            qy: q.y,
            qz: q.z,
            qw: q.w,
        }
    }

    fn tip_m(&self) -> Vector3<f64> {
        Vector3::new(self.x_m, self.y_m, self.z_m)
    }

    fn orientation(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_quaternion(Quaternion::new(self.qw, self.qx, self.qy, self.qz))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum TrajectoryError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}, line {line}: {message}")]
    Row {
        path: PathBuf,
        line: u64,
        message: String,
    },
    #[error("{path}: no samples")]
    Empty { path: PathBuf },
}

/// Samples in increasing time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    pub rows: Vec<TrajectoryRow>,
}

impl Trajectory {
    /// Reads a trajectory file, refusing non-finite numbers, a zero orientation and times that
    /// do not increase, with the line where each is found.
    pub fn load(path: &Path) -> Result<Self, TrajectoryError> {
        let file = std::fs::File::open(path).map_err(|source| TrajectoryError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::read(path, file)
    }

    /// Reads a trajectory from `file`'s text (fetched by a web page, say), named `path` in
    /// errors; the same checks as [`Trajectory::load`].
    pub fn read(path: &Path, file: impl std::io::Read) -> Result<Self, TrajectoryError> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(file);
        let row_error = |line: u64, message: String| TrajectoryError::Row {
            path: path.to_owned(),
            line,
            message,
        };
        let headers = reader
            .headers()
            .map_err(|e| row_error(1, e.to_string()))?
            .clone();
        let mut rows: Vec<TrajectoryRow> = Vec::new();
        for record in reader.records() {
            let record = record
                .map_err(|e| row_error(e.position().map_or(0, |p| p.line()), e.to_string()))?;
            let line = record.position().map_or(0, |p| p.line());
            let row: TrajectoryRow = record
                .deserialize(Some(&headers))
                .map_err(|e| row_error(line, e.to_string()))?;
            check_row(&row, rows.last()).map_err(|m| row_error(line, m))?;
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(TrajectoryError::Empty {
                path: path.to_owned(),
            });
        }
        Ok(Self { rows })
    }

    /// Writes the trajectory as CSV.
    pub fn save(&self, path: &Path) -> Result<(), TrajectoryError> {
        let io = |source: std::io::Error| TrajectoryError::Io {
            path: path.to_owned(),
            source,
        };
        let mut writer = csv::Writer::from_path(path).map_err(|e| io(e.into()))?;
        for row in &self.rows {
            writer.serialize(row).map_err(|e| io(e.into()))?;
        }
        writer.flush().map_err(io)
    }

    /// The sample at `time_s`: positions interpolated linearly between rows, orientations by
    /// slerp, buttons held from the last row at or before; held at both ends.
    pub fn sample(&self, time_s: f64) -> DeviceSample {
        let after = self.rows.partition_point(|r| r.time_s <= time_s);
        if after == 0 {
            return self.rows[0].sample();
        }
        if after == self.rows.len() {
            return self.rows[after - 1].sample();
        }
        let (a, b) = (&self.rows[after - 1], &self.rows[after]);
        let t = (time_s - a.time_s) / (b.time_s - a.time_s);
        DeviceSample {
            tip_m: a.tip_m().lerp(&b.tip_m(), t),
            orientation: a.orientation().slerp(&b.orientation(), t),
            buttons: a.buttons,
        }
    }

    pub fn duration_s(&self) -> f64 {
        self.rows.last().map_or(0.0, |r| r.time_s)
    }
}

impl TrajectoryRow {
    fn sample(&self) -> DeviceSample {
        DeviceSample {
            tip_m: self.tip_m(),
            orientation: self.orientation(),
            buttons: self.buttons,
        }
    }
}

fn check_row(row: &TrajectoryRow, previous: Option<&TrajectoryRow>) -> Result<(), String> {
    let numbers = [
        row.time_s, row.x_m, row.y_m, row.z_m, row.qx, row.qy, row.qz, row.qw,
    ];
    if numbers.iter().any(|v| !v.is_finite()) {
        return Err("a number is not finite".into());
    }
    if [row.qx, row.qy, row.qz, row.qw].iter().all(|&q| q == 0.0) {
        return Err("the orientation quaternion is zero".into());
    }
    if let Some(previous) = previous
        && row.time_s <= previous.time_s
    {
        return Err(format!(
            "time {} s does not follow {} s: times must increase",
            row.time_s, previous.time_s
        ));
    }
    Ok(())
}
