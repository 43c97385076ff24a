//! The PAN preset of `fogsim import`: the "Cold TVC ETU Test 3/7/2020" MEMS log (`TVCtest3_7_20.csv`, see
//! `shared/data/measured/pan-tvac-mems/SOURCE.md`; MIT, Copyright (c) 2020 Pathfinder for
//! Autonomous Navigation (PAN)). Columns: time (ms), magnetometer x/y/z (T), gyro x/y/z
//! (rad/s), raw temperature register (uint16 as written). Conversion, as SOURCE.md says:
//! - temperature `T = 25 + int16(raw) / 256` degC (LSM6DSM; absolute offset unverified);
//! - the 5 s bursts at 50 Hz become one row each: the burst's mean time, rates and
//!   temperature (a burst is a run of samples less than 1 s apart);
//! - rad/s -> deg/h; outliers: a sample whose rate on any axis lies more than
//!   `OUTLIER_MADS` robust sigmas (1.4826 MAD) from its burst's median is dropped (this
//!   removes the 3 gyro-x spikes <= -0.08 rad/s that the original authors deleted);
//! - one run per gyro axis (`--axis`), the magnetometer as extra columns in uT;
//!   Earth rate is negligible next to the MEMS bias and its projection is unknown: 0.
//!
//! Bad input (wrong header, non-numeric cell, ragged row, time going backwards) is
//! rejected with the line named; nothing is written then.

use super::lines::{check_size, BoundedLines};
use super::ImportError;
use crate::io::run_format::excerpt;
use crate::io::runs::Run;
use std::io::BufRead;
use std::path::Path;

/// The header the PAN file must have.
pub const PAN_HEADER: &str =
    "time (ms),mag1x [T],mag1y [T],mag1z [T],gyrox rad/s,gyroy rad/s,gyroz rad/s,temp";
/// Samples further apart than this start a new burst, s.
pub const BURST_GAP_S: f64 = 1.0;
/// Outlier threshold in robust sigmas.
pub const OUTLIER_MADS: f64 = 10.0;
const RADS_TO_DPH: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// One raw sample.
#[derive(Clone, Copy, Debug)]
struct Sample {
    t_s: f64,
    mag_t: [f64; 3],
    gyro_rads: [f64; 3],
    temp_c: f64,
}

/// Import summary for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct PanImport {
    /// One run per requested axis.
    pub runs: Vec<Run>,
    pub samples: usize,
    pub bursts: usize,
    pub outliers_dropped: usize,
}

/// LSM6DSM temperature register (written as unsigned 16 bit) to degC.
pub fn lsm6dsm_temp_c(raw: f64) -> f64 {
    let r = raw.round() as i64;
    let s = if r > 32767 { r - 65536 } else { r };
    25.0 + s as f64 / 256.0
}

/// Streams the samples of a PAN log to `each` in file order, checking every row; lines
/// are bounded ([`BoundedLines`]) and quoted text cut ([`excerpt`]), so a huge or
/// wrong file is neither read whole nor echoed whole.
fn parse_stream(
    file: &str,
    input: impl BufRead,
    mut each: impl FnMut(Sample),
) -> Result<usize, ImportError> {
    let err = |line: Option<usize>, what: String| ImportError::at(file, line, what);
    let mut lines = BoundedLines::new(file, input);
    match lines.next_line()? {
        Some((_, h)) if h.trim() == PAN_HEADER => {}
        Some((_, h)) => {
            return Err(err(
                Some(1),
                format!(
                    "unexpected header `{}` (want `{PAN_HEADER}`)",
                    excerpt(h.trim())
                ),
            ))
        }
        None => return Err(err(None, "empty file".into())),
    }
    let mut count = 0;
    let mut last_t_s: Option<f64> = None;
    while let Some((n, l)) = lines.next_line()? {
        if l.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = l.split(',').map(str::trim).collect();
        if cells.len() != 8 {
            return Err(err(Some(n), format!("{} cells, expected 8", cells.len())));
        }
        let mut v = [0.0f64; 8];
        for (k, c) in cells.iter().enumerate() {
            v[k] = c
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| {
                    err(
                        Some(n),
                        format!("column {} is not a finite number: `{}`", k + 1, excerpt(c)),
                    )
                })?;
        }
        let t_s = v[0] / 1000.0;
        if last_t_s.is_some_and(|p| t_s <= p) {
            return Err(err(Some(n), "time is not strictly increasing".into()));
        }
        last_t_s = Some(t_s);
        count += 1;
        each(Sample {
            t_s,
            mag_t: [v[1], v[2], v[3]],
            gyro_rads: [v[4], v[5], v[6]],
            temp_c: lsm6dsm_temp_c(v[7]),
        });
    }
    if count == 0 {
        return Err(err(None, "no data rows".into()));
    }
    Ok(count)
}

#[cfg(test)]
fn parse(file: &str, text: &str) -> Result<Vec<Sample>, ImportError> {
    let mut samples = Vec::new();
    parse_stream(file, text.as_bytes(), |s| samples.push(s))?;
    Ok(samples)
}

/// One burst after outlier removal, reduced to its means as the run columns need them.
struct BurstMean {
    t_s: f64,
    rate_dph: [f64; 3],
    temp_c: f64,
    mag_ut: [f64; 3],
}

impl BurstMean {
    fn of(b: &[Sample]) -> Self {
        let mean = |f: &dyn Fn(&Sample) -> f64| b.iter().map(f).sum::<f64>() / b.len() as f64;
        BurstMean {
            t_s: mean(&|s| s.t_s),
            rate_dph: [0, 1, 2].map(|a| mean(&|s| s.gyro_rads[a] * RADS_TO_DPH)),
            temp_c: mean(&|s| s.temp_c),
            mag_ut: [0, 1, 2].map(|a| mean(&|s| s.mag_t[a] * 1e6)),
        }
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Drops outliers in a burst (any axis beyond `OUTLIER_MADS` robust sigmas of the burst median).
fn clean_burst(b: &[Sample]) -> Vec<Sample> {
    let mut limits = [(0.0, f64::INFINITY); 3];
    for (axis, lim) in limits.iter_mut().enumerate() {
        let mut v: Vec<f64> = b.iter().map(|s| s.gyro_rads[axis]).collect();
        let med = median(&mut v);
        let mut dev: Vec<f64> = b.iter().map(|s| (s.gyro_rads[axis] - med).abs()).collect();
        let mad = median(&mut dev) * 1.4826;
        *lim = (med, OUTLIER_MADS * mad.max(1e-12));
    }
    b.iter()
        .copied()
        .filter(|s| (0..3).all(|a| (s.gyro_rads[a] - limits[a].0).abs() <= limits[a].1))
        .collect()
}

/// Imports the PAN TVAC file; `axes` are 0 = x, 1 = y, 2 = z.
pub fn import_pan(path: &Path, axes: &[usize]) -> Result<PanImport, ImportError> {
    let file = path.display().to_string();
    check_size(path)?;
    let input =
        std::fs::File::open(path).map_err(|e| ImportError::at(&file, None, e.to_string()))?;
    // Streamed burst by burst: memory holds one burst and one mean per burst.
    let mut means: Vec<BurstMean> = Vec::new();
    let mut burst: Vec<Sample> = Vec::new();
    let mut kept = 0;
    let mut close = |burst: &mut Vec<Sample>, means: &mut Vec<BurstMean>| {
        let cleaned = clean_burst(burst);
        kept += cleaned.len();
        means.push(BurstMean::of(&cleaned));
        burst.clear();
    };
    let samples = parse_stream(&file, std::io::BufReader::new(input), |s| {
        if burst.last().is_some_and(|p| s.t_s - p.t_s > BURST_GAP_S) {
            close(&mut burst, &mut means);
        }
        burst.push(s);
    })?;
    close(&mut burst, &mut means);
    let stem = path
        .file_stem()
        .map_or_else(|| "pan".into(), |s| s.to_string_lossy().into_owned());
    let mut runs = Vec::new();
    for &axis in axes {
        let name = ["x", "y", "z"][axis.min(2)];
        let cols = vec![
            ("t_s".to_owned(), means.iter().map(|m| m.t_s).collect()),
            (
                "rate_dph".to_owned(),
                means.iter().map(|m| m.rate_dph[axis]).collect(),
            ),
            (
                "temp_c".to_owned(),
                means.iter().map(|m| m.temp_c).collect(),
            ),
            (
                "mag_x_ut".to_owned(),
                means.iter().map(|m| m.mag_ut[0]).collect(),
            ),
            (
                "mag_y_ut".to_owned(),
                means.iter().map(|m| m.mag_ut[1]).collect(),
            ),
            (
                "mag_z_ut".to_owned(),
                means.iter().map(|m| m.mag_ut[2]).collect(),
            ),
        ];
        let meta = vec![
            ("gyro".to_owned(), format!("PAN-ETU-LSM6DSM-{name}")),
            ("earth_dph".to_owned(), "0".to_owned()),
            ("source".to_owned(), format!("{stem}.csv (pathfinder-for-autonomous-navigation/psim 91d70ad), gyro axis {name}")),
            ("license".to_owned(), "MIT, Copyright (c) 2020 Pathfinder for Autonomous Navigation (PAN)".to_owned()),
            ("conversion".to_owned(), format!("one row per 5 s burst (mean); T = 25 + int16(raw)/256 degC; rad/s -> deg/h; {} outlier samples dropped", samples - kept)),
            ("note".to_owned(), "cooling in a thermal-vacuum chamber, not a power-on warm-up; t_s is time since flight-computer boot".to_owned()),
        ];
        let path = format!("{stem}_gyro_{name}.csv");
        runs.push(
            Run::new(path, meta, cols).map_err(|e| ImportError::at(&file, None, e.to_string()))?,
        );
    }
    Ok(PanImport {
        runs,
        samples,
        bursts: means.len(),
        outliers_dropped: samples - kept,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temperature_register_conversion() {
        assert_eq!(lsm6dsm_temp_c(0.0), 25.0);
        assert!((lsm6dsm_temp_c(65236.0) - (25.0 - 300.0 / 256.0)).abs() < 1e-12);
        assert!((lsm6dsm_temp_c(512.0) - 27.0).abs() < 1e-12);
    }

    #[test]
    fn bad_rows_are_rejected_with_the_line() {
        let bad = format!("{PAN_HEADER}\n1,0,0,0,0,0,0,1\n2,0,0,0,x,0,0,1\n");
        let e = parse("f.csv", &bad).unwrap_err();
        assert_eq!(e.line, Some(3));
        let back = format!("{PAN_HEADER}\n2,0,0,0,0,0,0,1\n1,0,0,0,0,0,0,1\n");
        assert!(parse("f.csv", &back).is_err());
        assert!(parse("f.csv", "a,b\n").is_err());
        let ragged = format!("{PAN_HEADER}\n1,0,0\n");
        assert!(parse("f.csv", &ragged).is_err());
    }
}
