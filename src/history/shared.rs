//! A programme's shared history: one PostgreSQL database every station writes to, through
//! rust-postgres' blocking client. The trainer creates and migrates its schema (versioned
//! migrations, recorded in `schema_migrations`, applied under an advisory lock so that
//! stations starting together migrate once). An attempt is inserted by its unique id with
//! `ON CONFLICT (uid) DO NOTHING`: sent twice (a station that lost the server's answer sends
//! it again), it is kept once.

use std::time::Duration;

use postgres::{Client, NoTls};

use super::{AttemptRecord, HistoryFilter};

/// One step of the schema.
pub struct Migration {
    pub version: i32,
    pub name: &'static str,
    pub sql: &'static str,
}

/// The schema's steps, in order.
pub const MIGRATIONS: [Migration; 3] = [
    Migration {
        version: 1,
        name: "attempts",
        sql: "CREATE TABLE attempts (
            id BIGSERIAL PRIMARY KEY,
            uid TEXT NOT NULL UNIQUE,
            station TEXT NOT NULL,
            trainee TEXT NOT NULL,
            scenario TEXT NOT NULL,
            title TEXT NOT NULL,
            at_unix_s BIGINT NOT NULL,
            score DOUBLE PRECISION NOT NULL,
            passed BOOLEAN NOT NULL,
            time_s DOUBLE PRECISION NOT NULL,
            path_mm DOUBLE PRECISION NOT NULL,
            peak_force_n DOUBLE PRECISION NOT NULL,
            errors BIGINT NOT NULL,
            report TEXT NOT NULL,
            received_at TIMESTAMPTZ NOT NULL DEFAULT now()
        );
        CREATE INDEX attempts_by_trainee ON attempts (trainee, scenario);",
    },
    Migration {
        version: 2,
        name: "attempts in time order",
        sql: "CREATE INDEX attempts_by_time ON attempts (at_unix_s, id);",
    },
    Migration {
        version: 3,
        name: "whether an attempt met its scenario's benchmark",
        sql: "ALTER TABLE attempts ADD COLUMN proficient BOOLEAN;",
    },
];

/// The schema this code writes and reads.
pub const SCHEMA_VERSION: i32 = MIGRATIONS.len() as i32;

/// How long connecting to the server may take before the attempt is queued instead.
const CONNECT_WITHIN: Duration = Duration::from_secs(2);

/// The advisory lock the migrations are applied under (any number of the trainer's own).
const MIGRATION_LOCK: i64 = 0x7067_645f_6869_7374;

/// The columns of an attempt, in the order [`record_of`] reads them.
const COLUMNS: &str = "id, uid, station, trainee, scenario, title, at_unix_s, score, passed, \
    time_s, path_mm, peak_force_n, errors, report, proficient";

/// A connection to the shared history.
pub struct SharedHistory {
    client: Client,
}

/// `url` with its password, if any, left out: what messages show.
pub fn shown(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_owned();
    };
    match rest.split_once('@') {
        Some((user, host)) if user.contains(':') => {
            let name = user.split(':').next().unwrap_or_default();
            format!("{scheme}://{name}:***@{host}")
        }
        _ => url.to_owned(),
    }
}

impl SharedHistory {
    /// Connects to the database at `url` (`postgres://USER[:PASSWORD]@HOST[:PORT]/DATABASE`;
    /// without a password in it, `PGPASSWORD`'s) and brings its schema up to date.
    pub fn connect(url: &str) -> Result<Self, String> {
        let mut config: postgres::Config = url.parse().map_err(|e| format!("{e}"))?;
        if config.get_password().is_none()
            && let Ok(password) = std::env::var("PGPASSWORD")
        {
            config.password(password);
        }
        config
            .connect_timeout(CONNECT_WITHIN)
            .application_name("pgd-surgery trainer");
        let client = config.connect(NoTls).map_err(|e| describe(&e))?;
        let mut shared = Self { client };
        shared.migrate()?;
        Ok(shared)
    }

    /// The schema version the database is at.
    pub fn schema_version(&mut self) -> Result<i32, String> {
        let row = self
            .client
            .query_one(
                "SELECT coalesce(max(version), 0) FROM schema_migrations",
                &[],
            )
            .map_err(|e| describe(&e))?;
        Ok(row.get(0))
    }

    /// Applies the migrations the database lacks, in one transaction under the trainer's
    /// advisory lock. A database a newer trainer migrated is refused; a station whose role may
    /// not migrate is told who can.
    fn migrate(&mut self) -> Result<(), String> {
        let mut transaction = self.client.transaction().map_err(|e| describe(&e))?;
        transaction
            .execute("SELECT pg_advisory_xact_lock($1)", &[&MIGRATION_LOCK])
            .map_err(|e| describe(&e))?;
        let exists: bool = transaction
            .query_one("SELECT to_regclass('schema_migrations') IS NOT NULL", &[])
            .map_err(|e| describe(&e))?
            .get(0);
        let version: i32 = match exists {
            false => 0,
            true => transaction
                .query_one(
                    "SELECT coalesce(max(version), 0) FROM schema_migrations",
                    &[],
                )
                .map_err(|e| describe(&e))?
                .get(0),
        };
        if version > SCHEMA_VERSION {
            return Err(format!(
                "its schema is at version {version}, written by a newer trainer (this one \
                 knows up to {SCHEMA_VERSION}): update this station's trainer"
            ));
        }
        if version == SCHEMA_VERSION {
            return Ok(());
        }
        let cannot = |e: postgres::Error| {
            format!(
                "its schema is at version {version} and this trainer needs {SCHEMA_VERSION}, \
                 but migrating it failed ({}): run any trainer command against it once as the \
                 database's owner, e.g. `trainer history --history postgres://OWNER@…` \
                 (docs/programme.md)",
                describe(&e)
            )
        };
        if !exists {
            transaction
                .batch_execute(
                    "CREATE TABLE schema_migrations (version INTEGER PRIMARY KEY, \
                     name TEXT NOT NULL, applied_at TIMESTAMPTZ NOT NULL DEFAULT now())",
                )
                .map_err(cannot)?;
        }
        for migration in MIGRATIONS.iter().filter(|m| m.version > version) {
            transaction.batch_execute(migration.sql).map_err(cannot)?;
            transaction
                .execute(
                    "INSERT INTO schema_migrations (version, name) VALUES ($1, $2)",
                    &[&migration.version, &migration.name],
                )
                .map_err(cannot)?;
        }
        transaction.commit().map_err(|e| describe(&e))
    }

    /// Inserts `record` unless an attempt with its uid is there already; whether it was new.
    pub fn insert(&mut self, record: &AttemptRecord) -> Result<bool, String> {
        let inserted = self
            .client
            .execute(
                "INSERT INTO attempts (uid, station, trainee, scenario, title, at_unix_s, score, \
                 passed, time_s, path_mm, peak_force_n, errors, report, proficient) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14) \
                 ON CONFLICT (uid) DO NOTHING",
                &[
                    &record.uid,
                    &record.station,
                    &record.trainee,
                    &record.scenario,
                    &record.title,
                    &record.at_unix_s,
                    &record.score,
                    &record.passed,
                    &record.time_s,
                    &record.path_mm,
                    &record.peak_force_n,
                    &record.errors,
                    &record.report,
                    &record.proficient,
                ],
            )
            .map_err(|e| describe(&e))?;
        Ok(inserted == 1)
    }

    /// The attempts `filter` selects, every station's, oldest first.
    pub fn attempts(&mut self, filter: &HistoryFilter) -> Result<Vec<AttemptRecord>, String> {
        let rows = self
            .client
            .query(
                &format!(
                    "SELECT {COLUMNS} FROM attempts \
                     WHERE ($1::TEXT IS NULL OR trainee = $1) \
                     AND ($2::TEXT IS NULL OR scenario = $2) ORDER BY at_unix_s, id"
                ),
                &[&filter.trainee, &filter.scenario],
            )
            .map_err(|e| describe(&e))?;
        Ok(rows.iter().map(record_of).collect())
    }
}

/// A PostgreSQL error with the server's own words when it gave some, else with its cause
/// (the connection refused, the name not found).
fn describe(e: &postgres::Error) -> String {
    match (e.as_db_error(), std::error::Error::source(e)) {
        (Some(db), _) => format!("{}: {}", db.severity(), db.message()),
        (None, Some(cause)) => format!("{e}: {cause}"),
        (None, None) => e.to_string(),
    }
}

fn record_of(row: &postgres::Row) -> AttemptRecord {
    AttemptRecord {
        id: row.get(0),
        uid: row.get(1),
        station: row.get(2),
        trainee: row.get(3),
        scenario: row.get(4),
        title: row.get(5),
        at_unix_s: row.get(6),
        score: row.get(7),
        passed: row.get(8),
        time_s: row.get(9),
        path_mm: row.get(10),
        peak_force_n: row.get(11),
        errors: row.get(12),
        report: row.get(13),
        proficient: row.get(14),
    }
}
