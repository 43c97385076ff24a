//! Runs written as one lab logger's log: what `fogsim import` exists to read, produced
//! from a simulated campaign so the whole path (docs/workflow.md) starts from a logger
//! file whose truth is known. One long file, power-ons one after another with the gyro
//! off `OFF_GAP_S` between them (the import splits there), in a layout a European lab
//! logger writes: semicolon delimited, decimal comma, ISO 8601 UTC time stamps with a
//! decimal comma (`2026-01-05T08:00:10,000Z`), the rate in deg/s and the coil
//! temperature in degF (units `fogsim import` must be told).
//!
//! Header: `timestamp;rate_dps;coil_temp_f`. Each run's rows are its `t_s`, `rate_dph`
//! and `temp_c` columns; the logger's first row of a run is its first 10 s mean, so an
//! import (which takes the first row as power-on) counts time from there.

use std::io;
use std::path::Path;

use super::{write_atomic_with, Run};
use crate::io::utc::format_utc_ms;

/// Gyro off between two power-ons, s (a cold start needs the coil back at ambient).
pub const OFF_GAP_S: f64 = 4.0 * 3600.0;
/// The first power-on: 2026-01-05T08:00:00Z, ms since the Unix epoch.
const FIRST_POWER_ON_MS: i64 = 1_767_600_000_000;

/// The column a run must have, or why it cannot be logged.
fn column<'a>(run: &'a Run, name: &str) -> io::Result<&'a [f64]> {
    run.column(name).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}: no `{name}` column to log", run.path.display()),
        )
    })
}

/// Writes `runs` as one logger log at `path` (atomically: all or nothing).
pub fn write_logger_csv(path: &Path, runs: &[&Run]) -> io::Result<()> {
    write_atomic_with(path, |w| {
        writeln!(w, "timestamp;rate_dps;coil_temp_f")?;
        let mut power_on_s = 0.0;
        for run in runs {
            let (t, rate, temp) = (
                column(run, "t_s")?,
                column(run, "rate_dph")?,
                column(run, "temp_c")?,
            );
            for i in 0..t.len() {
                let ms = FIRST_POWER_ON_MS + ((power_on_s + t[i]) * 1000.0).round() as i64;
                let line = format!(
                    "{};{:.10};{:.5}",
                    format_utc_ms(ms),
                    rate[i] / 3600.0,
                    temp[i] * 9.0 / 5.0 + 32.0
                );
                writeln!(w, "{}", line.replace('.', ","))?;
            }
            power_on_s += t.last().copied().unwrap_or(0.0) + OFF_GAP_S;
        }
        Ok(())
    })
}
