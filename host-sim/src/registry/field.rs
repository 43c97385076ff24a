//! Field records in the registry (`fogsim field pull`): one row per (gyro, sequence); a
//! record pulled again is ignored (the device's ring and the registry agree on it).

use anyhow::Result;

use super::utc::now_utc;
use super::Registry;
use crate::field::records_file::StoredRecord;

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
    use crate::field::records_file::StoredRecord;
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
}
