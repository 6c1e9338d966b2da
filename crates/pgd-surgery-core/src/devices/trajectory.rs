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
//!
//! A bimanual file carries both hands on the same times: the right hand's columns as above,
//! the left hand's the same names with the prefix `left_` (`left_x_m,left_y_m,left_z_m`,
//! `left_buttons`, `left_qx`…), in any order:
//!
//! ```text
//! time_s,x_m,y_m,z_m,buttons,left_x_m,left_y_m,left_z_m,left_buttons
//! 0.0,0.02,0.10,0.01,0,-0.03,0.10,0.01,1
//! ```

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

/// The prefix of a bimanual file's left-hand columns.
pub const LEFT_PREFIX: &str = "left_";

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
    #[error(
        "{path}: {found} hand(s) in the file (columns `left_…` are the left hand's), and the \
         run has {wanted}"
    )]
    Hands {
        path: PathBuf,
        found: usize,
        wanted: usize,
    },
}

/// Samples in increasing time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    pub rows: Vec<TrajectoryRow>,
}

impl Trajectory {
    /// Reads a one-hand trajectory file, refusing non-finite numbers, a zero orientation and
    /// times that do not increase, with the line where each is found, and a bimanual file.
    pub fn load(path: &Path) -> Result<Self, TrajectoryError> {
        Self::one_hand(path, Self::load_hands(path)?)
    }

    /// Reads a one-hand trajectory from `file`'s text (fetched by a web page, say), named
    /// `path` in errors; the same checks as [`Trajectory::load`].
    pub fn read(path: &Path, file: impl std::io::Read) -> Result<Self, TrajectoryError> {
        Self::one_hand(path, Self::read_hands(path, file)?)
    }

    /// Reads a trajectory file of one hand or two (the right hand's first); each hand's rows
    /// checked as [`Trajectory::load`] checks them.
    pub fn load_hands(path: &Path) -> Result<Vec<Self>, TrajectoryError> {
        let file = std::fs::File::open(path).map_err(|source| TrajectoryError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::read_hands(path, file)
    }

    /// [`Trajectory::load_hands`] from `file`'s text, named `path` in errors.
    pub fn read_hands(path: &Path, file: impl std::io::Read) -> Result<Vec<Self>, TrajectoryError> {
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
        let columns = HandColumns::of(&headers);
        let mut hands = vec![Self::default(); columns.len()];
        for record in reader.records() {
            let record = record
                .map_err(|e| row_error(e.position().map_or(0, |p| p.line()), e.to_string()))?;
            let line = record.position().map_or(0, |p| p.line());
            for (hand, columns) in hands.iter_mut().zip(&columns) {
                let row: TrajectoryRow = (columns.pick(&record))
                    .deserialize(Some(&columns.names))
                    .map_err(|e| row_error(line, e.to_string()))?;
                check_row(&row, hand.rows.last()).map_err(|m| row_error(line, m))?;
                hand.rows.push(row);
            }
        }
        if hands[0].rows.is_empty() {
            return Err(TrajectoryError::Empty {
                path: path.to_owned(),
            });
        }
        Ok(hands)
    }

    /// The one hand of `hands`, or why not.
    fn one_hand(path: &Path, mut hands: Vec<Self>) -> Result<Self, TrajectoryError> {
        if hands.len() != 1 {
            return Err(TrajectoryError::Hands {
                path: path.to_owned(),
                found: hands.len(),
                wanted: 1,
            });
        }
        Ok(hands.remove(0))
    }

    /// Writes the hands' trajectories as one CSV, the left hand's columns prefixed, on the
    /// right hand's times (the left hand sampled there: a recorder's hands are read on the
    /// same ticks, so nothing is interpolated unless a hand skipped a bad sample).
    pub fn save_hands(path: &Path, hands: &[Self]) -> Result<(), TrajectoryError> {
        let [right, left] = hands else {
            return hands.first().map_or(Ok(()), |hand| hand.save(path));
        };
        let io = |source: std::io::Error| TrajectoryError::Io {
            path: path.to_owned(),
            source,
        };
        let mut writer = csv::Writer::from_path(path).map_err(|e| io(e.into()))?;
        let names = TrajectoryRow::COLUMNS.iter().map(|c| c.to_string());
        let left_names = TrajectoryRow::COLUMNS[1..]
            .iter()
            .map(|c| format!("{LEFT_PREFIX}{c}"));
        let header: Vec<String> = names.chain(left_names).collect();
        writer.write_record(&header).map_err(|e| io(e.into()))?;
        for r in &right.rows {
            let l = TrajectoryRow::new(r.time_s, &left.sample(r.time_s));
            let values = r.values().into_iter().chain(l.values().into_iter().skip(1));
            let record: Vec<String> = values.map(|v| v.to_string()).collect();
            writer.write_record(&record).map_err(|e| io(e.into()))?;
        }
        writer.flush().map_err(io)
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

/// Which of a file's columns are a hand's, and their names without the hand's prefix.
struct HandColumns {
    indices: Vec<usize>,
    names: csv::StringRecord,
}

impl HandColumns {
    /// The right hand's columns (every one without the prefix), and the left hand's (the
    /// time and every one with it), if the file has any.
    fn of(headers: &csv::StringRecord) -> Vec<Self> {
        let left = |name: &str| name.starts_with(LEFT_PREFIX);
        let right = Self::picked(headers, |name| !left(name), |name| name);
        let left_hand = Self::picked(
            headers,
            |name| left(name) || name == "time_s",
            |name| name.strip_prefix(LEFT_PREFIX).unwrap_or(name),
        );
        match left_hand.indices.len() > 1 {
            true => vec![right, left_hand],
            false => vec![right],
        }
    }

    fn picked(
        headers: &csv::StringRecord,
        wanted: impl Fn(&str) -> bool,
        renamed: impl Fn(&str) -> &str,
    ) -> Self {
        let mut columns = Self {
            indices: Vec::new(),
            names: csv::StringRecord::new(),
        };
        for (index, name) in headers.iter().enumerate().filter(|(_, n)| wanted(n)) {
            columns.indices.push(index);
            columns.names.push_field(renamed(name));
        }
        columns
    }

    /// This hand's fields of `record`.
    fn pick(&self, record: &csv::StringRecord) -> csv::StringRecord {
        let mut picked = csv::StringRecord::with_capacity(64, self.indices.len());
        for &index in &self.indices {
            picked.push_field(record.get(index).unwrap_or_default());
        }
        picked
    }
}

impl TrajectoryRow {
    /// The columns of a file, in the order [`TrajectoryRow::values`] gives them.
    const COLUMNS: [&'static str; 9] = [
        "time_s", "x_m", "y_m", "z_m", "buttons", "qx", "qy", "qz", "qw",
    ];

    fn values(&self) -> [f64; 9] {
        [
            self.time_s,
            self.x_m,
            self.y_m,
            self.z_m,
            f64::from(self.buttons),
            self.qx,
            self.qy,
            self.qz,
            self.qw,
        ]
    }

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
