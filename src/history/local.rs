//! The station's own history: a SQLite database (the library bundled: nothing to install).
//! On a station of a programme it also holds the attempts not yet sent to the shared history.

use std::path::{Path, PathBuf};

use rusqlite::{Connection, OpenFlags, params};

use super::{AttemptRecord, HistoryError, HistoryFilter};

/// The schema's versions (SQLite's `user_version`), each the step from the one before.
/// 1: the attempts. 2: each attempt's unique id, its station and whether it is still to be
/// sent to a shared history.
const MIGRATIONS: [&str; 3] = [
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
    CREATE INDEX attempts_by_trainee ON attempts (trainee, scenario);",
    "ALTER TABLE attempts ADD COLUMN uid TEXT;
    ALTER TABLE attempts ADD COLUMN station TEXT NOT NULL DEFAULT '';
    ALTER TABLE attempts ADD COLUMN pending INTEGER NOT NULL DEFAULT 0;
    CREATE UNIQUE INDEX attempts_by_uid ON attempts (uid);",
    "ALTER TABLE attempts ADD COLUMN proficient INTEGER;",
];

/// The schema this code writes and reads.
const SCHEMA_VERSION: i64 = MIGRATIONS.len() as i64;

/// The columns of an attempt, in the order [`record_of`] reads them.
const COLUMNS: &str = "id, uid, station, trainee, scenario, title, at_unix_s, score, passed, \
    time_s, path_mm, peak_force_n, errors, report, proficient";

/// An open local history database.
pub struct History {
    path: PathBuf,
    connection: Connection,
}

impl History {
    /// Opens the history at `path`, creating it (and its folder) if it does not exist, and
    /// bringing an older schema up to date. A file that is not a history database, or one a
    /// newer trainer wrote, is refused, untouched.
    pub fn open(path: &Path) -> Result<Self, HistoryError> {
        let fail = |message: String| HistoryError::Database {
            path: path.to_owned(),
            message,
        };
        if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) {
            std::fs::create_dir_all(folder).map_err(|e| fail(e.to_string()))?;
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_CREATE;
        let mut connection =
            Connection::open_with_flags(path, flags).map_err(|e| fail(e.to_string()))?;
        let version: i64 = connection
            .query_row("PRAGMA user_version", [], |row| row.get(0))
            .map_err(|e| fail(format!("not a history database: {e}")))?;
        if version > SCHEMA_VERSION {
            return Err(fail(format!(
                "written by a newer version of the trainer (schema {version}, this one reads \
                 up to {SCHEMA_VERSION})"
            )));
        }
        migrate(&mut connection, version).map_err(|e| fail(e.to_string()))?;
        Ok(Self {
            path: path.to_owned(),
            connection,
        })
    }

    /// Adds `record`; returns its number. An attempt already kept (its uid) is not kept
    /// twice: its number is returned.
    pub fn record(&self, record: &AttemptRecord) -> Result<i64, HistoryError> {
        self.insert(record, false)
    }

    /// Adds `record` as [`Self::record`] does, pending: to be sent to a shared history.
    pub fn record_pending(&self, record: &AttemptRecord) -> Result<i64, HistoryError> {
        self.insert(record, true)
    }

    fn insert(&self, record: &AttemptRecord, pending: bool) -> Result<i64, HistoryError> {
        // An attempt without a uid (one kept before attempts had them) is kept as NULL, which
        // the unique index lets repeat.
        let uid = (!record.uid.is_empty()).then_some(&record.uid);
        let inserted = self
            .connection
            .execute(
                "INSERT INTO attempts (uid, station, trainee, scenario, title, at_unix_s, score, \
                 passed, time_s, path_mm, peak_force_n, errors, report, pending, proficient) \
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15) \
                 ON CONFLICT (uid) DO NOTHING",
                params![
                    uid,
                    record.station,
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
                    record.report,
                    pending,
                    record.proficient
                ],
            )
            .map_err(|e| self.error(e))?;
        match (inserted, uid) {
            (0, Some(uid)) => self
                .connection
                .query_row("SELECT id FROM attempts WHERE uid = ?1", [uid], |r| {
                    r.get(0)
                })
                .map_err(|e| self.error(e)),
            _ => Ok(self.connection.last_insert_rowid()),
        }
    }

    /// The attempts `filter` selects, oldest first.
    pub fn attempts(&self, filter: &HistoryFilter) -> Result<Vec<AttemptRecord>, HistoryError> {
        self.select(
            "WHERE (?1 IS NULL OR trainee = ?1) AND (?2 IS NULL OR scenario = ?2)",
            params![filter.trainee, filter.scenario],
        )
    }

    /// The attempts still to be sent to the shared history, oldest first.
    pub fn pending(&self) -> Result<Vec<AttemptRecord>, HistoryError> {
        self.select("WHERE pending = 1", params![])
    }

    /// The attempt `uid` is in the shared history: not to be sent again.
    pub fn mark_sent(&self, uid: &str) -> Result<(), HistoryError> {
        self.connection
            .execute("UPDATE attempts SET pending = 0 WHERE uid = ?1", [uid])
            .map(|_| ())
            .map_err(|e| self.error(e))
    }

    fn select(
        &self,
        condition: &str,
        values: &[&dyn rusqlite::ToSql],
    ) -> Result<Vec<AttemptRecord>, HistoryError> {
        let sql = format!("SELECT {COLUMNS} FROM attempts {condition} ORDER BY at_unix_s, id");
        let mut statement = self.connection.prepare(&sql).map_err(|e| self.error(e))?;
        let rows = statement
            .query_map(values, record_of)
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

/// Applies the migrations after `version`, each with its version, in one transaction.
fn migrate(connection: &mut Connection, version: i64) -> rusqlite::Result<()> {
    if version == SCHEMA_VERSION {
        return Ok(());
    }
    let transaction = connection.transaction()?;
    for (step, sql) in MIGRATIONS.iter().enumerate().skip(version as usize) {
        transaction.execute_batch(sql)?;
        transaction.pragma_update(None, "user_version", step as i64 + 1)?;
    }
    transaction.commit()
}

/// One row of [`COLUMNS`]; an attempt kept before attempts had ids has none (empty).
fn record_of(row: &rusqlite::Row) -> rusqlite::Result<AttemptRecord> {
    Ok(AttemptRecord {
        id: row.get(0)?,
        uid: row.get::<_, Option<String>>(1)?.unwrap_or_default(),
        station: row.get(2)?,
        trainee: row.get(3)?,
        scenario: row.get(4)?,
        title: row.get(5)?,
        at_unix_s: row.get(6)?,
        score: row.get(7)?,
        passed: row.get(8)?,
        time_s: row.get(9)?,
        path_mm: row.get(10)?,
        peak_force_n: row.get(11)?,
        errors: row.get(12)?,
        report: row.get(13)?,
        proficient: row.get(14)?,
    })
}
