//! `fogsim heading-cal --from-runs`: the heading harmonic a cos(alpha) + b sin(alpha)
//! fitted from runs recorded at several input axis azimuths (`campaign --headings-deg`,
//! or imported logs with a `heading_deg` column). Each run is replayed through fog-core's
//! compensator with the model, so its warm-up drift is removed as the device removes it;
//! the run's mean compensated rate (Earth rate added back, so the fit subtracts its own
//! Earth model) is one dwell at its heading, with the standard error of its 10 s windows.
//! The fit itself is fog-core's (`seeking::heading_cal::calibrate`, weighted least
//! squares, covariance scaled by the reduced chi-square): the same code the device's
//! calibration uses.

use anyhow::{bail, Result};
use fog_core::model::format::RbfModel;
use fog_core::model::heading::HeadingHarmonic;
use fog_core::seeking::heading_cal::{calibrate, HeadingDwell};
use fog_core::seeking::tilt::Tilt;

use crate::io::runs::Run;
use crate::pipeline::compensate::compensate_all;

/// A heading may vary this much within one run and still be one dwell, deg.
pub const HEADING_TOLERANCE_DEG: f64 = 0.01;

/// A number as a short, readable text (`1e-320` stays `1.000e-320`, never 320 digits).
pub fn short_number(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

/// One run as a dwell: where it came from and what it measured.
#[derive(Clone, Debug, PartialEq)]
pub struct RunDwell {
    pub file: String,
    pub heading_deg: f64,
    pub mean_rate_dph: f64,
    pub sigma_dph: f64,
    pub windows: usize,
}

/// The fit and the dwells it used.
#[derive(Clone, Debug)]
pub struct HeadingFit {
    pub harmonic: HeadingHarmonic,
    pub bias_dph: f64,
    pub latitude_deg: f64,
    pub dwells: Vec<RunDwell>,
}

/// The run's one heading, deg, or why it has none.
fn run_heading(run: &Run) -> Result<f64> {
    let file = run.path.display();
    let Some(h) = run.column("heading_deg") else {
        bail!("{file}: no heading_deg column; each run must be recorded at one known heading");
    };
    let (lo, hi) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), &x| {
            (l.min(x), u.max(x))
        });
    if !(lo.is_finite() && hi.is_finite()) || hi - lo > HEADING_TOLERANCE_DEG {
        bail!(
            "{file}: heading_deg varies within the run ({} to {} deg); one dwell needs one heading",
            short_number(lo),
            short_number(hi)
        );
    }
    if lo.abs() > 360.0 * 1e3 {
        bail!("{file}: heading_deg {} is out of range", short_number(lo));
    }
    Ok(lo)
}

/// The site latitude every run states (metadata `latitude_deg`), the same for all.
fn common_latitude(runs: &[Run]) -> Result<f64> {
    let mut lat: Option<(f64, String)> = None;
    for run in runs {
        let file = run.path.display().to_string();
        let Some(l) = run.latitude_deg() else {
            bail!("{file}: no latitude_deg metadata; the Earth rate on the axis needs the site latitude");
        };
        if !(l.is_finite() && l.abs() < 90.0) {
            bail!(
                "{file}: latitude_deg {} is out of range (-90, 90)",
                short_number(l)
            );
        }
        match &lat {
            None => lat = Some((l, file)),
            Some((l0, f0)) if (l - l0).abs() > 1e-6 => bail!(
                "{file}: latitude_deg {} differs from {f0}'s {}; one calibration needs one site",
                short_number(l),
                short_number(*l0)
            ),
            _ => {}
        }
    }
    lat.map(|(l, _)| l)
        .ok_or_else(|| anyhow::anyhow!("no runs to calibrate from"))
}

/// Fits the heading harmonic from `runs` compensated with `model` (table zero at north,
/// level: the runs' `heading_deg` is the input axis azimuth).
pub fn fit_from_runs(runs: &[Run], model: &RbfModel) -> Result<HeadingFit> {
    let latitude_deg = common_latitude(runs)?;
    let headings: Vec<f64> = runs.iter().map(run_heading).collect::<Result<_>>()?;
    let (_, series) = compensate_all(runs, model)?;
    let mut dwells = Vec::with_capacity(runs.len());
    for ((run, s), &heading_deg) in runs.iter().zip(&series).zip(&headings) {
        let n = s.after_dph.len();
        if n < 2 {
            bail!(
                "{}: {n} compensated 10 s window(s); a dwell needs at least 2",
                run.path.display()
            );
        }
        let earth = run.earth_dph();
        let earth_mean = earth.iter().sum::<f64>() / earth.len() as f64;
        let mean = s.after_dph.iter().sum::<f64>() / n as f64;
        let var = s.after_dph.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        dwells.push(RunDwell {
            file: run.path.display().to_string(),
            heading_deg,
            mean_rate_dph: mean + earth_mean,
            sigma_dph: (var / n as f64).sqrt().max(1e-9),
            windows: n,
        });
    }
    let core: Vec<HeadingDwell> = dwells
        .iter()
        .map(|d| HeadingDwell {
            heading_deg: d.heading_deg as f32,
            mean_rate_dph: d.mean_rate_dph,
            sigma_dph: d.sigma_dph,
        })
        .collect();
    let (harmonic, bias_dph) =
        calibrate(&core, 0.0, latitude_deg, Tilt::LEVEL).map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(HeadingFit {
        harmonic,
        bias_dph,
        latitude_deg,
        dwells,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_quoted_short() {
        let tiny = short_number(1e-320);
        assert!(tiny.len() < 12 && tiny.contains("e-32"), "{tiny}");
        assert_eq!(short_number(0.05), "0.0500");
        assert_eq!(short_number(-3e300), "-3.000e300");
        assert!(short_number(f64::NAN).len() < 8);
    }
}
