//! The registry's records: models sent, uploads and their outcome, seek results; and the
//! history of one gyro read back. Each write is one transaction (whole or not at all).

use fog_core::link::messages::SeekReport;
use fog_core::model::format::RbfModel;
use fog_core::seeking::quality::Validity;
use rusqlite::{params, Row};

use super::Registry;
use crate::io::utc::now_utc;

/// A model as the registry keeps it (identity, inputs, heading calibration).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelRecord {
    pub gyro_id: String,
    pub model_crc32: u32,
    pub model_len: u32,
    /// The model's input features, comma separated (`TempC,TempRateCps`).
    pub inputs: String,
    pub n_centers: u32,
    pub heldout_rms_dph: f64,
    /// a, b, sigma(a), sigma(b) in deg/h and the number of headings, if calibrated.
    pub heading: Option<([f64; 4], u32)>,
    /// CRC-32 of the same model without its heading calibration: the model `train` made
    /// (equal to `model_crc32` for a model without one; `None` for a model a registry of
    /// schema 1 recorded, which did not keep it).
    pub base_crc32: Option<u32>,
}

impl ModelRecord {
    /// The record of a decoded model and its bytes.
    pub fn of(model: &RbfModel, bytes: &[u8]) -> Self {
        let inputs: Vec<String> = model
            .inputs
            .iter()
            .map(|i| format!("{:?}", i.kind))
            .collect();
        let model_crc32 = fog_core::model::crc::crc32(bytes);
        Self {
            gyro_id: model.meta.gyro_id.to_string(),
            model_crc32,
            model_len: bytes.len() as u32,
            inputs: inputs.join(","),
            n_centers: model.centers.len() as u32,
            heldout_rms_dph: f64::from(model.meta.heldout_rms_dph),
            heading: model.heading.map(|h| {
                (
                    [h.cos_dph, h.sin_dph, h.cos_sigma_dph, h.sin_sigma_dph].map(f64::from),
                    u32::from(h.n_headings),
                )
            }),
            base_crc32: match model.heading {
                None => Some(model_crc32),
                Some(_) => crate::io::model::model_crc32(&RbfModel {
                    heading: None,
                    ..model.clone()
                })
                .ok(),
            },
        }
    }
}

/// One upload attempt.
#[derive(Clone, Debug, PartialEq)]
pub struct UploadRecord {
    pub started_utc: String,
    pub counter: u32,
    pub model_crc32: u32,
    /// `sending` while in progress (or if the tool died), `committed`, or the failure.
    pub result: String,
}

/// One seek result as `monitor` received it, with the context of the last status.
#[derive(Clone, Debug, PartialEq)]
pub struct SeekRecord {
    pub received_utc: String,
    pub gyro_id: String,
    pub sequence: u32,
    pub t_end_s: f64,
    pub azimuth_deg: f64,
    pub sigma_deg: f64,
    /// `valid` or `latitude_mismatch`.
    pub verdict: String,
    pub observed_latitude_deg: Option<f64>,
    pub model_crc32: Option<u32>,
    pub temp_c: Option<f64>,
    pub latitude_deg: Option<f64>,
    pub pitch_deg: f64,
    pub roll_deg: f64,
    pub positions: u8,
    pub duration_s: f64,
}

/// The device context a result is stored with (from the status before it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeekContext {
    pub model_crc32: Option<u32>,
    pub temp_c: Option<f64>,
    pub latitude_deg: Option<f64>,
}

impl SeekRecord {
    /// A result received now from `gyro_id`.
    pub fn new(gyro_id: &str, r: &SeekReport, ctx: SeekContext) -> Self {
        let (verdict, observed) = match r.validity {
            Validity::Valid => ("valid", None),
            Validity::LatitudeMismatch {
                observed_latitude_deg,
            } => ("latitude_mismatch", Some(f64::from(observed_latitude_deg))),
        };
        Self {
            received_utc: now_utc(),
            gyro_id: gyro_id.to_string(),
            sequence: r.sequence,
            t_end_s: r.t_end_s,
            azimuth_deg: r.azimuth_deg,
            sigma_deg: f64::from(r.sigma_deg),
            verdict: verdict.to_string(),
            observed_latitude_deg: observed,
            model_crc32: ctx.model_crc32,
            temp_c: ctx.temp_c,
            latitude_deg: ctx.latitude_deg,
            pitch_deg: f64::from(r.tilt.pitch_deg),
            roll_deg: f64::from(r.tilt.roll_deg),
            positions: r.positions,
            duration_s: f64::from(r.duration_s),
        }
    }

    fn from_row(r: &Row<'_>) -> rusqlite::Result<Self> {
        Ok(Self {
            received_utc: r.get(0)?,
            gyro_id: r.get(1)?,
            sequence: r.get(2)?,
            t_end_s: r.get(3)?,
            azimuth_deg: r.get(4)?,
            sigma_deg: r.get(5)?,
            verdict: r.get(6)?,
            observed_latitude_deg: r.get(7)?,
            model_crc32: r.get(8)?,
            temp_c: r.get(9)?,
            latitude_deg: r.get(10)?,
            pitch_deg: r.get(11)?,
            roll_deg: r.get(12)?,
            positions: r.get(13)?,
            duration_s: r.get(14)?,
        })
    }
}

const SEEK_COLUMNS: &str = "received_utc, gyro_id, sequence, t_end_s, azimuth_deg, sigma_deg, verdict, \
     observed_latitude_deg, model_crc32, temp_c, latitude_deg, pitch_deg, roll_deg, positions, duration_s";

/// Everything the registry holds about one gyro.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct History {
    /// (counter, issued UTC, model CRC-32), ascending.
    pub counters: Vec<(u32, String, u32)>,
    pub models: Vec<(String, ModelRecord)>,
    pub uploads: Vec<UploadRecord>,
    pub seeks: Vec<SeekRecord>,
}

impl Registry {
    /// Records a model (once per gyro and CRC; later sends keep the first record).
    pub fn record_model(&mut self, m: &ModelRecord) -> anyhow::Result<()> {
        let h = m.heading;
        self.conn.execute(
            "INSERT OR IGNORE INTO models (gyro_id, model_crc32, model_len, inputs, n_centers, \
             heldout_rms_dph, heading_cos_dph, heading_sin_dph, heading_cos_sigma_dph, \
             heading_sin_sigma_dph, heading_n, first_seen_utc, base_crc32) \
             VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)",
            params![
                m.gyro_id,
                m.model_crc32,
                m.model_len,
                m.inputs,
                m.n_centers,
                m.heldout_rms_dph,
                h.map(|(v, _)| v[0]),
                h.map(|(v, _)| v[1]),
                h.map(|(v, _)| v[2]),
                h.map(|(v, _)| v[3]),
                h.map(|(_, n)| n),
                now_utc(),
                m.base_crc32
            ],
        )?;
        Ok(())
    }

    /// Records the start of an upload (`sending`); returns its row id for `finish_upload`.
    pub fn begin_upload(
        &mut self,
        gyro_id: &str,
        counter: u32,
        model_crc32: u32,
    ) -> anyhow::Result<i64> {
        self.conn.execute(
            "INSERT INTO uploads (gyro_id, counter, model_crc32, started_utc, result) \
             VALUES (?1, ?2, ?3, ?4, 'sending')",
            params![gyro_id, counter, model_crc32, now_utc()],
        )?;
        Ok(self.conn.last_insert_rowid())
    }

    /// Records the outcome of upload `id`.
    pub fn finish_upload(&mut self, id: i64, result: &str) -> anyhow::Result<()> {
        self.conn.execute(
            "UPDATE uploads SET finished_utc = ?1, result = ?2 WHERE id = ?3",
            params![now_utc(), result, id],
        )?;
        Ok(())
    }

    /// Stores one seek result (one row, one transaction).
    pub fn record_seek(&mut self, s: &SeekRecord) -> anyhow::Result<()> {
        self.conn.execute(
            &format!(
                "INSERT INTO seeks ({SEEK_COLUMNS}) VALUES \
                 (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15)"
            ),
            params![
                s.received_utc,
                s.gyro_id,
                s.sequence,
                s.t_end_s,
                s.azimuth_deg,
                s.sigma_deg,
                s.verdict,
                s.observed_latitude_deg,
                s.model_crc32,
                s.temp_c,
                s.latitude_deg,
                s.pitch_deg,
                s.roll_deg,
                s.positions,
                s.duration_s
            ],
        )?;
        Ok(())
    }

    /// Seek results of one gyro (all gyros if `None`), in the order they were stored.
    pub fn seeks(&self, gyro_id: Option<&str>) -> anyhow::Result<Vec<SeekRecord>> {
        let mut stmt = self.conn.prepare(&format!(
            "SELECT {SEEK_COLUMNS} FROM seeks WHERE ?1 IS NULL OR gyro_id = ?1 ORDER BY id"
        ))?;
        let rows = stmt.query_map([gyro_id], SeekRecord::from_row)?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// Gyro ids the registry knows (from any table), sorted.
    pub fn gyros(&self) -> anyhow::Result<Vec<String>> {
        let mut stmt = self.conn.prepare(
            "SELECT gyro_id FROM counters UNION SELECT gyro_id FROM uploads \
             UNION SELECT gyro_id FROM seeks UNION SELECT gyro_id FROM models ORDER BY 1",
        )?;
        let rows = stmt.query_map([], |r| r.get(0))?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// Everything about `gyro_id`.
    pub fn history(&self, gyro_id: &str) -> anyhow::Result<History> {
        let mut h = History::default();
        let mut stmt = self.conn.prepare(
            "SELECT counter, issued_utc, model_crc32 FROM counters WHERE gyro_id = ?1 ORDER BY counter",
        )?;
        h.counters = stmt
            .query_map([gyro_id], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))?
            .collect::<rusqlite::Result<_>>()?;
        let mut stmt = self.conn.prepare(
            "SELECT first_seen_utc, gyro_id, model_crc32, model_len, inputs, n_centers, heldout_rms_dph, \
             heading_cos_dph, heading_sin_dph, heading_cos_sigma_dph, heading_sin_sigma_dph, heading_n, \
             base_crc32 FROM models WHERE gyro_id = ?1 ORDER BY first_seen_utc, model_crc32",
        )?;
        h.models = stmt
            .query_map([gyro_id], |r| {
                let heading = match (r.get(7)?, r.get(8)?, r.get(9)?, r.get(10)?, r.get(11)?) {
                    (Some(a), Some(b), Some(sa), Some(sb), Some(n)) => Some(([a, b, sa, sb], n)),
                    _ => None,
                };
                Ok((
                    r.get(0)?,
                    ModelRecord {
                        gyro_id: r.get(1)?,
                        model_crc32: r.get(2)?,
                        model_len: r.get(3)?,
                        inputs: r.get(4)?,
                        n_centers: r.get(5)?,
                        heldout_rms_dph: r.get(6)?,
                        heading,
                        base_crc32: r.get(12)?,
                    },
                ))
            })?
            .collect::<rusqlite::Result<_>>()?;
        let mut stmt = self.conn.prepare(
            "SELECT started_utc, counter, model_crc32, result FROM uploads WHERE gyro_id = ?1 ORDER BY id",
        )?;
        h.uploads = stmt
            .query_map([gyro_id], |r| {
                Ok(UploadRecord {
                    started_utc: r.get(0)?,
                    counter: r.get(1)?,
                    model_crc32: r.get(2)?,
                    result: r.get(3)?,
                })
            })?
            .collect::<rusqlite::Result<_>>()?;
        h.seeks = self.seeks(Some(gyro_id))?;
        Ok(h)
    }
}
