//! The results CSV: an export of the registry's seek results, written through the one
//! atomic writer (a reader sees the old file or the new one, never half of one).

use std::io::Write;
use std::path::Path;

use super::SeekRecord;

/// Header of the exported results CSV (and of one `monitor --csv` row).
pub const RESULTS_CSV_HEADER: &str =
    "received_utc,gyro_id,sequence,t_end_s,azimuth_deg,sigma_deg,verdict,\
observed_latitude_deg,model_crc32,temp_c,latitude_deg,pitch_deg,roll_deg,positions,duration_s";

/// One CSV line of a result, with its newline.
pub fn csv_line(s: &SeekRecord) -> String {
    let opt = |v: Option<f64>, prec: usize| v.map_or(String::new(), |v| format!("{v:.prec$}"));
    format!(
        "{},{},{},{:.3},{:.6},{:.6},{},{},{},{},{},{:.4},{:.4},{},{:.1}\n",
        s.received_utc,
        s.gyro_id,
        s.sequence,
        s.t_end_s,
        s.azimuth_deg,
        s.sigma_deg,
        s.verdict,
        opt(s.observed_latitude_deg, 3),
        s.model_crc32
            .map_or(String::new(), |c| format!("0x{c:08X}")),
        opt(s.temp_c, 2),
        opt(s.latitude_deg, 4),
        s.pitch_deg,
        s.roll_deg,
        s.positions,
        s.duration_s
    )
}

/// Writes `results` (header first) to `path` atomically.
pub fn write_results_csv(path: &Path, results: &[SeekRecord]) -> std::io::Result<()> {
    crate::io::write_atomic_with(path, |w: &mut dyn Write| {
        writeln!(w, "{RESULTS_CSV_HEADER}")?;
        for r in results {
            w.write_all(csv_line(r).as_bytes())?;
        }
        Ok(())
    })
}
