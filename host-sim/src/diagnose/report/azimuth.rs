//! What a residual bias does to north seeking: in a two-position seek the bias change
//! db between the two dwells gives an azimuth error db / (2 Omega_H |sin psi|). The
//! held-out residual (what compensation leaves) is cut into back-to-back dwell pairs
//! and the rms of db is turned into azimuth error at psi = 90 deg (the best case).

use crate::diagnose::validation::folds::Folds;
use fog_core::consts::EARTH_RATE_DPH;
use serde::Serialize;

/// Dwell per position, s (the paper's 4 min 56 s seek holds two of about this length).
pub const DWELL_S: f64 = 148.0;
/// Latitude used when the runs do not state one, deg (the simulator's, one value for all).
pub use crate::sim::DEFAULT_LATITUDE_DEG;

/// Azimuth effect of a residual.
#[derive(Clone, Debug, Serialize)]
pub struct AzimuthEffect {
    pub latitude_deg: f64,
    pub dwell_s: f64,
    pub pairs: usize,
    /// rms bias change between the two dwells, deg/h.
    pub db_rms_dph: f64,
    /// Resulting 1-sigma azimuth error at psi = 90 deg, deg.
    pub azimuth_sigma_deg: f64,
}

/// Azimuth effect of `residual` (stacked; `t_s` likewise).
pub fn azimuth_effect(
    folds: &Folds,
    t_s: &[f64],
    residual: &[f64],
    latitude_deg: f64,
) -> AzimuthEffect {
    let mut db = Vec::new();
    for r in &folds.run_rows {
        let t = &t_s[r.clone()];
        let e = &residual[r.clone()];
        let t0 = t.first().copied().unwrap_or(0.0);
        let mean_in = |a: f64, b: f64| {
            let v: Vec<f64> = t
                .iter()
                .zip(e)
                .filter(|(x, _)| **x >= a && **x < b)
                .map(|(_, y)| *y)
                .collect();
            (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        };
        let mut start = t0;
        while start + 2.0 * DWELL_S <= t.last().copied().unwrap_or(0.0) + 1e-9 {
            if let (Some(a), Some(b)) = (
                mean_in(start, start + DWELL_S),
                mean_in(start + DWELL_S, start + 2.0 * DWELL_S),
            ) {
                db.push(b - a);
            }
            start += 2.0 * DWELL_S;
        }
    }
    let db_rms = (db.iter().map(|x| x * x).sum::<f64>() / db.len().max(1) as f64).sqrt();
    let omega_h = EARTH_RATE_DPH * latitude_deg.to_radians().cos();
    AzimuthEffect {
        latitude_deg,
        dwell_s: DWELL_S,
        pairs: db.len(),
        db_rms_dph: db_rms,
        azimuth_sigma_deg: (db_rms / (2.0 * omega_h.abs().max(1e-9))).to_degrees(),
    }
}
