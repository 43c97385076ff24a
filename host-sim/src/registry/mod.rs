//! The calibration registry: one SQLite database (rusqlite, SQLite compiled in) that keeps,
//! per gyro id, what must outlive a session: the security counters issued (so none is
//! ever reused), the models sent (CRC-32, inputs, heading calibration), every upload with
//! its outcome and every seek result `monitor` received; and the factory's record of gyro
//! types, their units' runs and every unit calibration (`fleet`).
//!
//! Why a database: counters must be issued exactly once even when two uploads run at the
//! same time, and results must be stored whole or not at all under concurrent monitors.
//! Every write is one transaction; counter issue takes the write lock first
//! (`BEGIN IMMEDIATE`) so the read of the last counter and the insert of the next cannot
//! interleave with another writer; a busy database is waited for (`BUSY_TIMEOUT`), not
//! failed. The CSV of results is an export of it (`export`), written atomically.

mod counters;
mod export;
mod field_records;
mod fleet;
mod records;

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use rusqlite::{Connection, OpenFlags};

pub use counters::CounterRefusal;
pub use export::{csv_line, write_results_csv, RESULTS_CSV_HEADER};
pub use field_records::variants_of;
pub use fleet::UnitCalibrationRecord;
pub use records::{History, ModelRecord, SeekContext, SeekRecord, UploadRecord};

/// How long a writer waits for another writer's transaction before giving up.
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(30);

/// `PRAGMA application_id` of a fogsim registry ("FOGR"): tells ours from any other database.
const APPLICATION_ID: i64 = 0x464F_4752;
/// Schema version (`PRAGMA user_version`). 2: `models.base_crc32` (the model a heading
/// calibration was attached to; `migrate` adds the column to a schema-1 registry). 3: the
/// fleet's tables (`fleet`: types, units' runs, unit calibrations), created in any older
/// registry when it is opened.
const SCHEMA_VERSION: i64 = 3;

const SCHEMA: &str = "
CREATE TABLE IF NOT EXISTS counters (
    gyro_id     TEXT    NOT NULL,
    counter     INTEGER NOT NULL CHECK (counter > 0 AND counter <= 4294967295),
    issued_utc  TEXT    NOT NULL,
    model_crc32 INTEGER NOT NULL,
    PRIMARY KEY (gyro_id, counter)
);
CREATE TABLE IF NOT EXISTS models (
    gyro_id          TEXT    NOT NULL,
    model_crc32      INTEGER NOT NULL,
    model_len        INTEGER NOT NULL,
    inputs           TEXT    NOT NULL,
    n_centers        INTEGER NOT NULL,
    heldout_rms_dph  REAL    NOT NULL,
    heading_cos_dph  REAL,
    heading_sin_dph  REAL,
    heading_cos_sigma_dph REAL,
    heading_sin_sigma_dph REAL,
    heading_n        INTEGER,
    first_seen_utc   TEXT    NOT NULL,
    base_crc32       INTEGER,
    PRIMARY KEY (gyro_id, model_crc32)
);
CREATE TABLE IF NOT EXISTS uploads (
    id           INTEGER PRIMARY KEY,
    gyro_id      TEXT    NOT NULL,
    counter      INTEGER NOT NULL,
    model_crc32  INTEGER NOT NULL,
    started_utc  TEXT    NOT NULL,
    finished_utc TEXT,
    result       TEXT    NOT NULL
);
CREATE TABLE IF NOT EXISTS seeks (
    id             INTEGER PRIMARY KEY,
    received_utc   TEXT    NOT NULL,
    gyro_id        TEXT    NOT NULL,
    sequence       INTEGER NOT NULL,
    t_end_s        REAL    NOT NULL,
    azimuth_deg    REAL    NOT NULL,
    sigma_deg      REAL    NOT NULL,
    verdict        TEXT    NOT NULL,
    observed_latitude_deg REAL,
    model_crc32    INTEGER,
    temp_c         REAL,
    latitude_deg   REAL,
    pitch_deg      REAL    NOT NULL,
    roll_deg       REAL    NOT NULL,
    positions      INTEGER NOT NULL,
    duration_s     REAL    NOT NULL
);
CREATE TABLE IF NOT EXISTS field_records (
    gyro_id            TEXT    NOT NULL,
    sequence           INTEGER NOT NULL,
    received_utc       TEXT    NOT NULL,
    temp_c             REAL    NOT NULL,
    temp_rate_cps      REAL    NOT NULL,
    temp_accel_cps2    REAL    NOT NULL,
    t_since_power_on_s REAL    NOT NULL,
    residual_bias_dph  REAL    NOT NULL,
    model_crc32        INTEGER,
    PRIMARY KEY (gyro_id, sequence)
);
";

/// An open registry (one connection; open one per thread or process).
pub struct Registry {
    conn: Connection,
    path: PathBuf,
}

/// The registry used when no `--registry` is given: `$XDG_DATA_HOME/fogsim/registry.sqlite`,
/// else `~/.local/share/fogsim/registry.sqlite`.
pub fn default_path() -> Result<PathBuf> {
    let base = match std::env::var_os("XDG_DATA_HOME").filter(|v| !v.is_empty()) {
        Some(d) => PathBuf::from(d),
        None => match std::env::var_os("HOME").filter(|v| !v.is_empty()) {
            Some(h) => PathBuf::from(h).join(".local/share"),
            None => bail!("no --registry given and neither XDG_DATA_HOME nor HOME is set"),
        },
    };
    Ok(base.join("fogsim").join("registry.sqlite"))
}

/// `--registry PATH` or the default.
pub fn resolve(path: Option<&Path>) -> Result<PathBuf> {
    match path {
        Some(p) => Ok(p.to_path_buf()),
        None => default_path(),
    }
}

/// SQLite's file header.
const SQLITE_HEADER: &[u8; 16] = b"SQLite format 3\0";

/// Refuses an existing, non-empty file that does not start with SQLite's header: SQLite
/// takes a one-byte file for an empty database and writes a new one over it (found by
/// the bad-invocation probe). An empty file holds nothing to lose and stays accepted.
fn refuse_non_sqlite(path: &Path) -> Result<()> {
    use std::io::Read;
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(());
    };
    if meta.len() == 0 {
        return Ok(());
    }
    let mut head = [0u8; 16];
    let read = std::fs::File::open(path).and_then(|f| f.take(16).read(&mut head));
    match read {
        Ok(16) if &head == SQLITE_HEADER => Ok(()),
        Ok(_) => bail!(
            "registry {}: not a fogsim registry (no SQLite header), left as it is",
            path.display()
        ),
        Err(e) => Err(e).with_context(|| format!("registry {}: cannot read", path.display())),
    }
}

impl Registry {
    /// Opens (creating if absent, with its directory) the registry at `path`. A file that
    /// is not a fogsim registry is refused and left untouched.
    pub fn open(path: &Path) -> Result<Self> {
        let shown = path.display();
        if path.is_dir() {
            bail!("registry {shown}: is a directory");
        }
        refuse_non_sqlite(path)?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("registry {shown}: cannot create its directory"))?;
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_WRITE
            | OpenFlags::SQLITE_OPEN_CREATE
            | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        let conn = Connection::open_with_flags(path, flags)
            .with_context(|| format!("registry {shown}: cannot open"))?;
        conn.busy_timeout(BUSY_TIMEOUT)?;
        let mut reg = Self {
            conn,
            path: path.to_path_buf(),
        };
        reg.init()
            .with_context(|| format!("registry {shown}: not usable as a fogsim registry"))?;
        Ok(reg)
    }

    /// Checks the identity of the file, switches it to WAL and creates the schema. Safe
    /// when several processes create the same new registry at once: the identity is read
    /// in one snapshot, and checked again inside the write transaction that creates it.
    fn init(&mut self) -> Result<()> {
        // The first access: a file that is not SQLite fails here, and a foreign database
        // is refused before anything (even its journal mode) is changed.
        let tx = self.conn.transaction()?;
        check_identity(&tx)?;
        tx.commit()?;
        // WAL: readers never block the writer; one writer at a time, the others wait.
        // Changing the journal mode does not wait on a busy database by itself: retried.
        let deadline = std::time::Instant::now() + BUSY_TIMEOUT;
        loop {
            match self
                .conn
                .query_row("PRAGMA journal_mode=WAL", [], |r| r.get::<_, String>(0))
            {
                Ok(_) => break,
                Err(e) if is_busy(&e) && std::time::Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(5));
                }
                Err(e) => return Err(e.into()),
            }
        }
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)?;
        check_identity(&tx)?;
        let version: i64 = tx.query_row("PRAGMA user_version", [], |r| r.get(0))?;
        if version > SCHEMA_VERSION {
            bail!("schema version {version} is newer than this fogsim's {SCHEMA_VERSION}");
        }
        tx.execute_batch(SCHEMA)?;
        tx.execute_batch(fleet::FLEET_SCHEMA)?;
        migrate(&tx)?;
        tx.execute_batch(&format!(
            "PRAGMA application_id = {APPLICATION_ID}; PRAGMA user_version = {SCHEMA_VERSION};"
        ))?;
        tx.commit()?;
        Ok(())
    }

    /// Where the database is.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Ours (our application id) or new (no id, no objects); anything else is refused.
fn check_identity(conn: &Connection) -> Result<()> {
    let app: i64 = conn.query_row("PRAGMA application_id", [], |r| r.get(0))?;
    let objects: i64 = conn.query_row("SELECT count(*) FROM sqlite_master", [], |r| r.get(0))?;
    if app != APPLICATION_ID && (app != 0 || objects != 0) {
        bail!("another application's SQLite database (application_id {app:#x}, {objects} objects)");
    }
    Ok(())
}

/// Brings a schema-1 registry to schema 2 (inside the caller's transaction): adds
/// `models.base_crc32`. Its existing rows keep NULL there (the bytes they were recorded
/// from are not kept): such a model matches field records only by its own CRC.
fn migrate(conn: &Connection) -> Result<()> {
    let has_base: i64 = conn.query_row(
        "SELECT count(*) FROM pragma_table_info('models') WHERE name = 'base_crc32'",
        [],
        |r| r.get(0),
    )?;
    if has_base == 0 {
        conn.execute_batch("ALTER TABLE models ADD COLUMN base_crc32 INTEGER")?;
    }
    Ok(())
}

fn is_busy(e: &rusqlite::Error) -> bool {
    matches!(
        e.sqlite_error_code(),
        Some(rusqlite::ErrorCode::DatabaseBusy | rusqlite::ErrorCode::DatabaseLocked)
    )
}

#[cfg(test)]
pub(crate) fn test_registry(name: &str) -> (PathBuf, Registry) {
    let dir = std::env::temp_dir().join(format!("fogsim-registry-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("registry.sqlite");
    let reg = Registry::open(&path).unwrap();
    (dir, reg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_a_file_that_is_not_a_registry_and_leaves_it_intact() {
        let (dir, _) = test_registry("foreign");
        let text = dir.join("notes.txt");
        std::fs::write(&text, "t_s,rate_dph\n0,1\n".repeat(100)).unwrap();
        let before = std::fs::read(&text).unwrap();
        let err = Registry::open(&text).err().unwrap();
        assert!(format!("{err:#}").contains("notes.txt"), "{err:#}");
        assert_eq!(std::fs::read(&text).unwrap(), before);

        let other = dir.join("other.sqlite");
        Connection::open(&other)
            .unwrap()
            .execute_batch("CREATE TABLE t(x)")
            .unwrap();
        let err = format!("{:#}", Registry::open(&other).err().unwrap());
        assert!(err.contains("another application"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reopening_keeps_the_schema_and_the_rows() {
        let (dir, mut reg) = test_registry("reopen");
        assert_eq!(reg.issue_counter("G1", None, 0, 7).unwrap(), 1);
        drop(reg);
        let mut reg = Registry::open(&dir.join("registry.sqlite")).unwrap();
        assert_eq!(reg.issue_counter("G1", None, 0, 7).unwrap(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
