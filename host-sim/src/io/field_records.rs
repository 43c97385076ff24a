//! Field records in a directory: `field_records.json` (what `fogsim train --field` reads)
//! and `field_records.csv` (the same rows for a spreadsheet), both written together and
//! atomically (`StagedFiles`). A pull into a directory that already holds records merges
//! them by sequence (a device ring forgets its oldest; the directory keeps them). The JSON
//! is read size-bounded and checked whole: one bad record rejects the file with its place.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use fog_core::seeking::field_record::FieldRecord;
use serde::{Deserialize, Serialize};

use crate::io::{read_bounded, StagedFiles};

/// File names inside the directory.
pub const JSON_NAME: &str = "field_records.json";
pub const CSV_NAME: &str = "field_records.csv";
/// `format` of the JSON.
const FORMAT: &str = "fog-field-records";
const VERSION: u32 = 1;
/// Largest JSON read, bytes (~250 bytes a record: 100,000 records).
const MAX_JSON_BYTES: u64 = 32 << 20;
/// The CSV header.
pub const CSV_HEADER: &str = "gyro_id,sequence,temp_c,temp_rate_cps,temp_accel_cps2,\
t_since_power_on_s,residual_bias_dph,model_crc32";

/// One record as kept on the host: the device's record and the gyro it came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredRecord {
    pub gyro_id: String,
    pub sequence: u32,
    pub temp_c: f32,
    pub temp_rate_cps: f32,
    pub temp_accel_cps2: f32,
    pub t_since_power_on_s: f32,
    pub residual_bias_dph: f32,
    pub model_crc32: Option<u32>,
}

impl StoredRecord {
    pub fn new(gyro_id: &str, r: &FieldRecord) -> Self {
        Self {
            gyro_id: gyro_id.to_string(),
            sequence: r.sequence,
            temp_c: r.temp_c,
            temp_rate_cps: r.temp_rate_cps,
            temp_accel_cps2: r.temp_accel_cps2,
            t_since_power_on_s: r.t_since_power_on_s,
            residual_bias_dph: r.residual_bias_dph,
            model_crc32: r.model_crc32,
        }
    }

    /// The device record (for its range checks).
    pub fn record(&self) -> FieldRecord {
        FieldRecord {
            sequence: self.sequence,
            temp_c: self.temp_c,
            temp_rate_cps: self.temp_rate_cps,
            temp_accel_cps2: self.temp_accel_cps2,
            t_since_power_on_s: self.t_since_power_on_s,
            residual_bias_dph: self.residual_bias_dph,
            model_crc32: self.model_crc32,
        }
    }
}

#[derive(Serialize, Deserialize)]
struct FileBody {
    format: String,
    version: u32,
    records: Vec<StoredRecord>,
}

pub fn json_path(dir: &Path) -> PathBuf {
    dir.join(JSON_NAME)
}

/// Reads `dir/field_records.json`; `Ok(empty)` if the directory has none.
pub fn read_dir_records(dir: &Path) -> Result<Vec<StoredRecord>> {
    let path = json_path(dir);
    if !path.exists() {
        return Ok(Vec::new());
    }
    let shown = path.display();
    let bytes = read_bounded(&path, MAX_JSON_BYTES).map_err(|e| anyhow::anyhow!("{shown}: {e}"))?;
    let body: FileBody = serde_json::from_slice(&bytes)
        .with_context(|| format!("{shown}: not a field-record file"))?;
    if body.format != FORMAT || body.version != VERSION {
        bail!(
            "{shown}: format {:?} version {} (expected {FORMAT:?} version {VERSION})",
            body.format,
            body.version
        );
    }
    for (i, r) in body.records.iter().enumerate() {
        if !r.record().is_plausible() {
            bail!(
                "{shown}: record {i} (sequence {}): values not finite or out of range",
                r.sequence
            );
        }
    }
    Ok(body.records)
}

/// Merges `new` into what `dir` holds (same gyro and sequence: the new one wins), writes
/// both files atomically and returns (records now in the directory, added).
pub fn merge_into_dir(dir: &Path, new: &[StoredRecord]) -> Result<(usize, usize)> {
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let mut all = read_dir_records(dir)?;
    let before = all.len();
    for r in new {
        all.retain(|o| !(o.gyro_id == r.gyro_id && o.sequence == r.sequence));
        all.push(r.clone());
    }
    all.sort_by(|a, b| (&a.gyro_id, a.sequence).cmp(&(&b.gyro_id, b.sequence)));
    let body = FileBody {
        format: FORMAT.to_string(),
        version: VERSION,
        records: all,
    };
    let json = serde_json::to_vec_pretty(&body)?;
    let mut csv = String::from(CSV_HEADER);
    csv.push('\n');
    for r in &body.records {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{}\n",
            r.gyro_id,
            r.sequence,
            r.temp_c,
            r.temp_rate_cps,
            r.temp_accel_cps2,
            r.t_since_power_on_s,
            r.residual_bias_dph,
            r.model_crc32.map_or(String::new(), |c| format!("{c:08x}"))
        ));
    }
    let mut staged = StagedFiles::default();
    staged.stage(&json_path(dir), &json)?;
    staged.stage(&dir.join(CSV_NAME), csv.as_bytes())?;
    staged.commit()?;
    let n = body.records.len();
    Ok((n, n.saturating_sub(before)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(seq: u32, bias: f32) -> StoredRecord {
        StoredRecord::new(
            "G1",
            &FieldRecord {
                sequence: seq,
                temp_c: 25.0,
                temp_rate_cps: 0.001,
                temp_accel_cps2: 0.0,
                t_since_power_on_s: 900.0,
                residual_bias_dph: bias,
                model_crc32: Some(7),
            },
        )
    }

    #[test]
    fn pulls_merge_by_sequence_and_bad_files_are_refused_whole() {
        let dir = std::env::temp_dir().join(format!("fogsim-field-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(
            merge_into_dir(&dir, &[rec(1, 0.1), rec(2, 0.2)]).unwrap(),
            (2, 2)
        );
        assert_eq!(
            merge_into_dir(&dir, &[rec(2, 0.2), rec(3, 0.3)]).unwrap(),
            (3, 1)
        );
        let back = read_dir_records(&dir).unwrap();
        assert_eq!(
            back.iter().map(|r| r.sequence).collect::<Vec<_>>(),
            [1, 2, 3]
        );
        let csv = std::fs::read_to_string(dir.join(CSV_NAME)).unwrap();
        assert_eq!(csv.lines().count(), 4);
        // A NaN bias anywhere: the whole file is refused, with the record named.
        let text = std::fs::read_to_string(json_path(&dir)).unwrap();
        let bad = text.replacen("0.3", "1e30", 1);
        std::fs::write(json_path(&dir), bad).unwrap();
        let e = read_dir_records(&dir).unwrap_err().to_string();
        assert!(e.contains("record 2 (sequence 3)"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
