//! Every scored attempt, kept in a local SQLite database (the library bundled: nothing to
//! install), so that a trainee and an educator can follow progress over attempts.
//!
//! An attempt is never lost: when the database cannot be opened or written (a corrupt file, a
//! read-only folder), the attempt is written aside as JSON next to it and the error says where;
//! the database file itself is never overwritten or repaired.

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use rusqlite::{Connection, OpenFlags, params};
use serde::{Deserialize, Serialize};

use crate::scenario::Scorecard;

/// The schema this code writes and reads (SQLite's `user_version`).
const SCHEMA_VERSION: i64 = 1;

/// One scored attempt as the history keeps it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AttemptRecord {
    /// The database's number for it (0 before it is saved).
    pub id: i64,
    pub trainee: String,
    /// The scenario file, as it was given.
    pub scenario: String,
    pub title: String,
    /// When it ended, in seconds since the Unix epoch (UTC).
    pub at_unix_s: i64,
    /// 0–100.
    pub score: f64,
    pub passed: bool,
    /// Over its tasks: the time spent (s), the tool tip's path (mm), the peak force (N), errors.
    pub time_s: f64,
    pub path_mm: f64,
    pub peak_force_n: f64,
    pub errors: i64,
    /// The attempt's JSON report, if one was written.
    pub report: String,
}

impl AttemptRecord {
    /// When it ended, as RFC 3339 (UTC, to the second).
    pub fn when(&self) -> String {
        let at = UNIX_EPOCH + Duration::from_secs(self.at_unix_s.max(0) as u64);
        humantime::format_rfc3339_seconds(at).to_string()
    }
}

/// The seconds since the Unix epoch now.
pub fn now_unix_s() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64)
}

/// Which attempts to list.
#[derive(Clone, Debug, Default)]
pub struct HistoryFilter {
    pub trainee: Option<String>,
    pub scenario: Option<String>,
}

#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    #[error("{path}: {message}")]
    Database { path: PathBuf, message: String },
    #[error(
        "{path}: the attempt could not be kept in the history ({reason}); it was written to {aside} instead"
    )]
    SetAside {
        path: PathBuf,
        reason: String,
        aside: PathBuf,
    },
    #[error(
        "{path}: the attempt could not be kept in the history ({reason}), nor written aside to {aside} ({aside_error})"
    )]
    Lost {
        path: PathBuf,
        reason: String,
        aside: PathBuf,
        aside_error: String,
    },
}

/// An open history database.
pub struct History {
    path: PathBuf,
    connection: Connection,
}

impl History {
    /// Opens the history at `path`, creating it (and its folder) if it does not exist. A file
    /// that is not a history database is refused, untouched.
    pub fn open(path: &Path) -> Result<Self, HistoryError> {
        let fail = |message: String| HistoryError::Database {
            path: path.to_owned(),
            message,
        };
        if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) {
            std::fs::create_dir_all(folder).map_err(|e| fail(e.to_string()))?;
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_CREATE;
        let connection =
            Connection::open_with_flags(path, flags).map_err(|e| fail(e.to_string()))?;
        let version: i64 = connection
            .query_row("PRAGMA user_version", [], |row| row.get(0))
            .map_err(|e| fail(format!("not a history database: {e}")))?;
        match version {
            0 => create(&connection).map_err(|e| fail(e.to_string()))?,
            SCHEMA_VERSION => {}
            other => {
                return Err(fail(format!(
                    "written by another version of the trainer (schema {other}, this one reads {SCHEMA_VERSION})"
                )));
            }
        }
        Ok(Self {
            path: path.to_owned(),
            connection,
        })
    }

    /// Adds `record`; returns its number.
    pub fn record(&self, record: &AttemptRecord) -> Result<i64, HistoryError> {
        self.connection
            .execute(
                "INSERT INTO attempts (trainee, scenario, title, at_unix_s, score, passed, time_s, \
                 path_mm, peak_force_n, errors, report) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)",
                params![
                    record.trainee,
                    record.scenario,
                    record.title,
                    record.at_unix_s,
                    record.score,
                    record.passed,
                    record.time_s,
                    record.path_mm,
                    record.peak_force_n,
                    record.errors,
                    record.report
                ],
            )
            .map_err(|e| self.error(e))?;
        Ok(self.connection.last_insert_rowid())
    }

    /// The attempts `filter` selects, oldest first.
    pub fn attempts(&self, filter: &HistoryFilter) -> Result<Vec<AttemptRecord>, HistoryError> {
        let mut statement = self
            .connection
            .prepare(
                "SELECT id, trainee, scenario, title, at_unix_s, score, passed, time_s, path_mm, \
                 peak_force_n, errors, report FROM attempts \
                 WHERE (?1 IS NULL OR trainee = ?1) AND (?2 IS NULL OR scenario = ?2) \
                 ORDER BY at_unix_s, id",
            )
            .map_err(|e| self.error(e))?;
        let rows = statement
            .query_map(params![filter.trainee, filter.scenario], |row| {
                Ok(AttemptRecord {
                    id: row.get(0)?,
                    trainee: row.get(1)?,
                    scenario: row.get(2)?,
                    title: row.get(3)?,
                    at_unix_s: row.get(4)?,
                    score: row.get(5)?,
                    passed: row.get(6)?,
                    time_s: row.get(7)?,
                    path_mm: row.get(8)?,
                    peak_force_n: row.get(9)?,
                    errors: row.get(10)?,
                    report: row.get(11)?,
                })
            })
            .map_err(|e| self.error(e))?;
        rows.collect::<Result<_, _>>().map_err(|e| self.error(e))
    }

    fn error(&self, e: rusqlite::Error) -> HistoryError {
        HistoryError::Database {
            path: self.path.clone(),
            message: e.to_string(),
        }
    }
}

fn create(connection: &Connection) -> rusqlite::Result<()> {
    connection.execute_batch(&format!(
        "CREATE TABLE attempts (
            id INTEGER PRIMARY KEY,
            trainee TEXT NOT NULL,
            scenario TEXT NOT NULL,
            title TEXT NOT NULL,
            at_unix_s INTEGER NOT NULL,
            score REAL NOT NULL,
            passed INTEGER NOT NULL,
            time_s REAL NOT NULL,
            path_mm REAL NOT NULL,
            peak_force_n REAL NOT NULL,
            errors INTEGER NOT NULL,
            report TEXT NOT NULL
        );
        CREATE INDEX attempts_by_trainee ON attempts (trainee, scenario);
        PRAGMA user_version = {SCHEMA_VERSION};"
    ))
}

/// Keeps `record` in the history at `path`; returns its number. If the history cannot take
/// it, the attempt is written aside as JSON beside the database, and the error says where.
pub fn keep_attempt(path: &Path, record: &AttemptRecord) -> Result<i64, HistoryError> {
    let reason = match History::open(path).and_then(|h| h.record(record)) {
        Ok(id) => return Ok(id),
        Err(HistoryError::Database { message, .. }) => message,
        Err(e) => e.to_string(),
    };
    let aside = aside_path(path, record.at_unix_s);
    let written = serde_json::to_string_pretty(record)
        .map_err(|e| e.to_string())
        .and_then(|text| std::fs::write(&aside, text).map_err(|e| e.to_string()));
    Err(match written {
        Ok(()) => HistoryError::SetAside {
            path: path.to_owned(),
            reason,
            aside,
        },
        Err(aside_error) => HistoryError::Lost {
            path: path.to_owned(),
            reason,
            aside,
            aside_error,
        },
    })
}

/// `<database>.unsaved-<time>-<n>.json`, the first `n` not taken.
fn aside_path(path: &Path, at_unix_s: i64) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "history".into(), |n| n.to_string_lossy().into_owned());
    (0..)
        .map(|n| path.with_file_name(format!("{name}.unsaved-{at_unix_s}-{n}.json")))
        .find(|p| !p.exists())
        .unwrap_or_else(|| path.with_file_name(format!("{name}.unsaved.json")))
}

impl AttemptRecord {
    /// The record of an attempt at `scenario` by `trainee`, scored `card`, its report at
    /// `report`, ended at `at_unix_s`.
    pub fn of(
        card: &Scorecard,
        scenario: &Path,
        trainee: &str,
        report: Option<&Path>,
        at_unix_s: i64,
    ) -> Self {
        let tasks = || card.tasks.iter().map(|t| &t.metrics);
        Self {
            id: 0,
            trainee: trainee.to_owned(),
            scenario: scenario.display().to_string(),
            title: card.title.clone(),
            at_unix_s,
            score: card.score,
            passed: card.passed,
            time_s: tasks().map(|m| m.time_s).sum(),
            path_mm: tasks().map(|m| m.motion.path_length_mm).sum(),
            peak_force_n: tasks().map(|m| m.peak_force_n).fold(0.0, f64::max),
            errors: tasks().map(|m| m.error_count() as i64).sum(),
            report: report.map_or_else(String::new, |p| p.display().to_string()),
        }
    }
}
