//! The factory's record of gyro types, their units and runs, and every unit calibration:
//! which units and runs a type was learnt from (so a later unit is never calibrated
//! against a type it helped make without the registry saying so), and which type, runs and
//! terms made each unit's model (found again by the model's CRC-32, as uploads record it).
//!
//! On a fleet of thousands of units the same tables move to a server database behind these
//! functions; the type fit itself stays small (units x terms).

use anyhow::Result;
use rusqlite::params;

use super::Registry;
use crate::io::utc::now_utc;

/// The tables (created with the schema, `super::SCHEMA`).
pub(super) const FLEET_SCHEMA: &str = "
CREATE TABLE IF NOT EXISTS gyro_types (
    type_id      TEXT    NOT NULL PRIMARY KEY,
    fitted_utc   TEXT    NOT NULL,
    units        INTEGER NOT NULL,
    runs         INTEGER NOT NULL,
    model_crc32  INTEGER NOT NULL,
    type_json    TEXT    NOT NULL
);
CREATE TABLE IF NOT EXISTS unit_runs (
    unit_id      TEXT    NOT NULL,
    run          TEXT    NOT NULL,
    type_id      TEXT    NOT NULL,
    role         TEXT    NOT NULL CHECK (role IN ('type', 'unit')),
    recorded_utc TEXT    NOT NULL,
    PRIMARY KEY (unit_id, run, role)
);
CREATE TABLE IF NOT EXISTS unit_calibrations (
    id             INTEGER PRIMARY KEY,
    unit_id        TEXT    NOT NULL,
    type_id        TEXT    NOT NULL,
    calibrated_utc TEXT    NOT NULL,
    runs           INTEGER NOT NULL,
    terms          TEXT    NOT NULL,
    prior_weight   REAL    NOT NULL,
    misfit         TEXT    NOT NULL,
    outcome        TEXT    NOT NULL,
    model_crc32    INTEGER
);
";

/// One unit calibration as recorded.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitCalibrationRecord {
    pub unit_id: String,
    pub type_id: String,
    pub runs: usize,
    /// The unit terms fitted, comma-separated (empty: the type alone).
    pub terms: String,
    pub prior_weight: f64,
    /// The misfit test's lines, joined by `; `.
    pub misfit: String,
    /// `calibrated`, `refused (misfit)`, `refused (misfit, too few runs of its own)` or
    /// `own model (misfit)` (its CRC that of the own model written).
    pub outcome: String,
    pub model_crc32: Option<u32>,
}

/// One run of a unit, in the role it played (`type`: a type was learnt from it; `unit`: a
/// unit calibration).
fn record_unit_run(
    tx: &rusqlite::Transaction,
    unit_id: &str,
    run: &str,
    type_id: &str,
    role: &str,
    now: &str,
) -> Result<()> {
    tx.execute(
        "INSERT OR REPLACE INTO unit_runs (unit_id, run, type_id, role, recorded_utc)
         VALUES (?1, ?2, ?3, ?4, ?5)",
        params![unit_id, run, type_id, role, now],
    )?;
    Ok(())
}

impl Registry {
    /// Records a type (replacing an earlier fit of the same id) and the runs of its units,
    /// in one transaction.
    pub fn record_type(
        &mut self,
        type_id: &str,
        units: usize,
        model_crc32: u32,
        type_json: &str,
        runs: &[(String, String)],
    ) -> Result<()> {
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)?;
        let now = now_utc();
        tx.execute(
            "INSERT OR REPLACE INTO gyro_types (type_id, fitted_utc, units, runs, model_crc32, type_json)
             VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
            params![type_id, now, units as i64, runs.len() as i64, i64::from(model_crc32), type_json],
        )?;
        for (unit, run) in runs {
            record_unit_run(&tx, unit, run, type_id, "type", &now)?;
        }
        tx.commit()?;
        Ok(())
    }

    /// Records a unit calibration (whatever its outcome) and the unit's runs.
    pub fn record_unit_calibration(
        &mut self,
        rec: &UnitCalibrationRecord,
        runs: &[String],
    ) -> Result<()> {
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)?;
        let now = now_utc();
        tx.execute(
            "INSERT INTO unit_calibrations (unit_id, type_id, calibrated_utc, runs, terms, prior_weight, misfit, outcome, model_crc32)
             VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
            params![
                rec.unit_id,
                rec.type_id,
                now,
                rec.runs as i64,
                rec.terms,
                rec.prior_weight,
                rec.misfit,
                rec.outcome,
                rec.model_crc32.map(i64::from)
            ],
        )?;
        for run in runs {
            record_unit_run(&tx, &rec.unit_id, run, &rec.type_id, "unit", &now)?;
        }
        tx.commit()?;
        Ok(())
    }

    /// The units a type was learnt from, with their run counts, by unit id.
    pub fn type_units(&self, type_id: &str) -> Result<Vec<(String, usize)>> {
        let mut st = self.conn.prepare(
            "SELECT unit_id, count(*) FROM unit_runs WHERE type_id = ?1 AND role = 'type'
             GROUP BY unit_id ORDER BY unit_id",
        )?;
        let rows = st.query_map([type_id], |r| Ok((r.get(0)?, r.get::<_, i64>(1)? as usize)))?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// Every calibration of a unit, oldest first.
    pub fn unit_calibrations(&self, unit_id: &str) -> Result<Vec<UnitCalibrationRecord>> {
        let mut st = self.conn.prepare(
            "SELECT unit_id, type_id, runs, terms, prior_weight, misfit, outcome, model_crc32
             FROM unit_calibrations WHERE unit_id = ?1 ORDER BY id",
        )?;
        let rows = st.query_map([unit_id], |r| {
            Ok(UnitCalibrationRecord {
                unit_id: r.get(0)?,
                type_id: r.get(1)?,
                runs: r.get::<_, i64>(2)? as usize,
                terms: r.get(3)?,
                prior_weight: r.get(4)?,
                misfit: r.get(5)?,
                outcome: r.get(6)?,
                model_crc32: r.get::<_, Option<i64>>(7)?.map(|v| v as u32),
            })
        })?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }
}
