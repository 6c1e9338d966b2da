//! Every scored attempt, kept so that a trainee and an educator can follow progress over
//! attempts: in the station's own SQLite database ([`local`]), and on the stations of a
//! programme also in one PostgreSQL database that every station writes to ([`shared`]).
//!
//! An attempt is never lost: when the database cannot be opened or written (a corrupt file, a
//! read-only folder), the attempt is written aside as JSON next to it and the error says where;
//! the database file itself is never overwritten or repaired. A station that cannot reach the
//! shared history keeps the attempt in its own database, marked pending, and sends every
//! pending attempt the next time it reaches the server (sending is idempotent: see
//! [`shared`]).

mod config;
mod local;
pub mod shared;

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use crate::scenario::Scorecard;
pub use config::{CONFIG_VARIABLE, TrainerConfig, machine_name};
pub use local::History;
use shared::{SharedHistory, shown};

/// One scored attempt as the history keeps it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AttemptRecord {
    /// The database's number for it (0 before it is saved).
    pub id: i64,
    /// Its unique id, given when it ends: the same attempt sent twice to a shared history is
    /// kept once. Empty for an attempt kept before attempts had ids.
    #[serde(default)]
    pub uid: String,
    /// The station it was made on (its configured name, else the machine's).
    #[serde(default)]
    pub station: String,
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
    /// Whether it met its scenario's proficiency benchmark; none where the scenario holds no
    /// benchmark (or the attempt was kept before benchmarks were).
    #[serde(default)]
    pub proficient: Option<bool>,
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
    /// The shared history could be reached by neither connection nor queue.
    #[error("the shared history at {url}: {message}")]
    Shared { url: String, message: String },
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

/// Where attempts are kept.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Store {
    /// The station's SQLite database alone.
    Local(PathBuf),
    /// A programme's PostgreSQL database at `url`, the station's SQLite database at `local`
    /// holding a copy of its own attempts and those not yet sent.
    Shared { url: String, local: PathBuf },
}

impl Store {
    /// `history` as `--history` or a configuration file gives it: a `postgres://` (or
    /// `postgresql://`) URL, or a SQLite file; `local` is the station's own database.
    pub fn of(history: &str, local: &Path) -> Self {
        match history.starts_with("postgres://") || history.starts_with("postgresql://") {
            true => Self::Shared {
                url: history.to_owned(),
                local: local.to_owned(),
            },
            false => Self::Local(PathBuf::from(history)),
        }
    }

    /// The station's own database.
    pub fn local(&self) -> &Path {
        match self {
            Self::Local(path) | Self::Shared { local: path, .. } => path,
        }
    }

    /// Where the attempts are, for messages (a URL without its password).
    pub fn shown(&self) -> String {
        match self {
            Self::Local(path) => path.display().to_string(),
            Self::Shared { url, .. } => shown(url),
        }
    }
}

/// Where an attempt was kept.
#[derive(Clone, Debug, PartialEq)]
pub enum Kept {
    /// In the station's database, as attempt `id`.
    Local { id: i64 },
    /// In the shared history, with `sent` attempts in all sent by this call (those queued
    /// before included).
    Shared { sent: usize },
    /// In the station's database, pending: the shared history could not be reached; `pending`
    /// attempts wait to be sent.
    Queued { reason: String, pending: usize },
}

/// Keeps `record` in `store`. In a shared store the attempt is first kept in the station's
/// database as pending, then every pending attempt is sent, oldest first, each marked sent
/// once the server has committed it: an attempt is in the station's database before it is
/// sent, and leaves the queue only once the server holds it. If the station's database cannot
/// take it, the attempt is written aside as JSON beside it, and the error says where.
pub fn keep_attempt(store: &Store, record: &AttemptRecord) -> Result<Kept, HistoryError> {
    let shared = matches!(store, Store::Shared { .. });
    let local = store.local();
    let kept = History::open(local).and_then(|h| {
        let id = match shared {
            true => h.record_pending(record)?,
            false => h.record(record)?,
        };
        Ok((id, h))
    });
    let (id, history) = match kept {
        Ok(kept) => kept,
        Err(e) => return Err(set_aside(local, record, e)),
    };
    match store {
        Store::Local(_) => Ok(Kept::Local { id }),
        Store::Shared { url, .. } => Ok(send_pending(&history, url)),
    }
}

/// Sends the station's pending attempts to the shared history at `url`.
fn send_pending(history: &History, url: &str) -> Kept {
    let queued = |reason: String| {
        let pending = history.pending().map_or(0, |p| p.len());
        Kept::Queued { reason, pending }
    };
    let mut shared = match SharedHistory::connect(url) {
        Ok(shared) => shared,
        Err(reason) => return queued(reason),
    };
    match drain(history, &mut shared) {
        Ok(sent) => Kept::Shared { sent },
        Err(reason) => queued(reason),
    }
}

/// Sends every pending attempt of `history` to `shared`, oldest first; how many were sent.
pub fn drain(history: &History, shared: &mut SharedHistory) -> Result<usize, String> {
    let pending = history.pending().map_err(|e| e.to_string())?;
    for record in &pending {
        shared.insert(record)?;
        history.mark_sent(&record.uid).map_err(|e| e.to_string())?;
    }
    Ok(pending.len())
}

/// The attempts `filter` selects in `store`, oldest first, with a warning when a shared
/// history could not be reached and the station's own attempts are shown instead. The
/// station's pending attempts are sent first, so that the shared history shows them.
pub fn read_attempts(
    store: &Store,
    filter: &HistoryFilter,
) -> Result<(Vec<AttemptRecord>, Option<String>), HistoryError> {
    let local = || History::open(store.local()).and_then(|h| h.attempts(filter));
    let Store::Shared { url, .. } = store else {
        return Ok((local()?, None));
    };
    let shared = SharedHistory::connect(url).and_then(|mut shared| {
        if let Ok(history) = History::open(store.local()) {
            drain(&history, &mut shared)?;
        }
        shared.attempts(filter)
    });
    match shared {
        Ok(attempts) => Ok((attempts, None)),
        Err(reason) => {
            let warning = format!(
                "the shared history at {} cannot be read ({reason}); showing this station's \
                 attempts only, from {}",
                shown(url),
                store.local().display()
            );
            Ok((local()?, Some(warning)))
        }
    }
}

/// Writes `record` aside as JSON beside the database at `path`, which could not take it.
fn set_aside(path: &Path, record: &AttemptRecord, error: HistoryError) -> HistoryError {
    let reason = match error {
        HistoryError::Database { message, .. } => message,
        e => e.to_string(),
    };
    let aside = aside_path(path, record.at_unix_s);
    let written = serde_json::to_string_pretty(record)
        .map_err(|e| e.to_string())
        .and_then(|text| std::fs::write(&aside, text).map_err(|e| e.to_string()));
    match written {
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
    }
}

/// A new attempt's unique id: its end time and 128 random bits, in hex.
fn new_uid(at_unix_s: i64) -> String {
    format!("{at_unix_s:x}-{:032x}", fastrand::u128(..))
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
            uid: new_uid(at_unix_s),
            station: String::new(),
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
            proficient: card.proficient,
        }
    }

    /// The record as made on the station `name`.
    pub fn at_station(self, name: &str) -> Self {
        Self {
            station: name.to_owned(),
            ..self
        }
    }
}
