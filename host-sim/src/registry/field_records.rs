//! Field records in the registry (`fogsim field pull`): one row per (gyro, sequence); a
//! record pulled again is ignored (the device's ring and the registry agree on it).

use std::path::Path;

use anyhow::Result;
use fog_core::model::format::RbfModel;

use super::Registry;
use crate::io::field_records::StoredRecord;
use crate::io::model::model_crc32;
use crate::io::utc::now_utc;

/// The CRC-32s of the models the calibration registry at `registry` knows to derive from
/// `model` (it with a heading calibration attached: `heading-cal`, then `upload`). Their
/// records measured the same residual bias (`Registry::models_derived_from` says why).
pub fn variants_of(model: &RbfModel, registry: &Path) -> Result<Vec<u32>> {
    Registry::open(registry)?.models_derived_from(model_crc32(model)?)
}

impl Registry {
    /// Stores `records` in one transaction; returns how many were new.
    pub fn insert_field_records(&mut self, records: &[StoredRecord]) -> Result<usize> {
        let tx = self.conn.transaction()?;
        let mut added = 0;
        {
            let mut st = tx.prepare(
                "INSERT OR IGNORE INTO field_records (gyro_id, sequence, received_utc, temp_c, \
                 temp_rate_cps, temp_accel_cps2, t_since_power_on_s, residual_bias_dph, \
                 model_crc32) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
            )?;
            let now = now_utc();
            for r in records {
                added += st.execute(rusqlite::params![
                    r.gyro_id,
                    r.sequence,
                    now,
                    f64::from(r.temp_c),
                    f64::from(r.temp_rate_cps),
                    f64::from(r.temp_accel_cps2),
                    f64::from(r.t_since_power_on_s),
                    f64::from(r.residual_bias_dph),
                    r.model_crc32,
                ])?;
            }
        }
        tx.commit()?;
        Ok(added)
    }

    /// CRC-32s of the models the registry knows to derive from the model `base_crc32`
    /// (the same trained model with a heading calibration attached), `base_crc32` itself
    /// excluded; ascending. A device running such a variant measures the same residual
    /// bias as under the trained model: the harmonic a cos(alpha) + b sin(alpha) is
    /// applied by the north finder to Earth rate, not to the compensated rates, and it
    /// cancels in the half-sum of two opposite positions anyway.
    pub fn models_derived_from(&self, base_crc32: u32) -> Result<Vec<u32>> {
        let mut st = self.conn.prepare(
            "SELECT DISTINCT model_crc32 FROM models \
             WHERE base_crc32 = ?1 AND model_crc32 != ?1 ORDER BY model_crc32",
        )?;
        let rows = st.query_map([base_crc32], |r| r.get(0))?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// How many field records the registry holds for `gyro_id`.
    pub fn field_record_count(&self, gyro_id: &str) -> Result<i64> {
        Ok(self.conn.query_row(
            "SELECT count(*) FROM field_records WHERE gyro_id = ?1",
            [gyro_id],
            |r| r.get(0),
        )?)
    }
}

#[cfg(test)]
mod tests {
    use crate::io::field_records::StoredRecord;
    use fog_core::seeking::field_record::FieldRecord;

    #[test]
    fn a_record_pulled_twice_is_stored_once() {
        let (dir, mut reg) = super::super::test_registry("field");
        let r = |seq| {
            StoredRecord::new(
                "G7",
                &FieldRecord {
                    sequence: seq,
                    residual_bias_dph: 0.01,
                    temp_c: 20.0,
                    ..FieldRecord::ZERO
                },
            )
        };
        assert_eq!(reg.insert_field_records(&[r(1), r(2)]).unwrap(), 2);
        assert_eq!(reg.insert_field_records(&[r(2), r(3)]).unwrap(), 1);
        assert_eq!(reg.field_record_count("G7").unwrap(), 3);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn variants_are_found_by_their_base_and_a_schema_1_registry_is_migrated() {
        use crate::registry::{ModelRecord, Registry};
        let (dir, mut reg) = super::super::test_registry("variants");
        let rec = |crc, base| ModelRecord {
            gyro_id: "G7".into(),
            model_crc32: crc,
            model_len: 100,
            inputs: "TempC".into(),
            n_centers: 3,
            heldout_rms_dph: 0.01,
            heading: None,
            base_crc32: base,
        };
        reg.record_model(&rec(10, Some(10))).unwrap();
        reg.record_model(&rec(11, Some(10))).unwrap();
        reg.record_model(&rec(12, Some(10))).unwrap();
        reg.record_model(&rec(20, Some(19))).unwrap();
        assert_eq!(reg.models_derived_from(10).unwrap(), vec![11, 12]);
        assert!(reg.models_derived_from(20).unwrap().is_empty());
        // A schema-1 registry (no base_crc32 column) gets it on open; its rows keep NULL.
        reg.conn
            .execute_batch(
                "DELETE FROM models; ALTER TABLE models DROP COLUMN base_crc32; \
                 PRAGMA user_version = 1;",
            )
            .unwrap();
        reg.conn
            .execute(
                "INSERT INTO models (gyro_id, model_crc32, model_len, inputs, n_centers, \
                 heldout_rms_dph, first_seen_utc) VALUES ('G7', 11, 100, 'TempC', 3, 0.01, 'x')",
                [],
            )
            .unwrap();
        drop(reg);
        let reg = Registry::open(&dir.join("registry.sqlite")).unwrap();
        let version: i64 = reg
            .conn
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .unwrap();
        // schema 1 -> the current one: base_crc32 added, the fleet's tables created
        assert_eq!(version, 3);
        assert!(reg.type_units("any").unwrap().is_empty());
        assert!(reg.models_derived_from(10).unwrap().is_empty());
        let h = reg.history("G7").unwrap();
        assert_eq!(h.models[0].1.base_crc32, None);
        let _ = std::fs::remove_dir_all(dir);
    }
}
