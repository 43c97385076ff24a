//! Stage 1, input: turns fog-runs records into the checked, 10 s series `diagnose` works
//! on, with each column's derivative widths (`derivatives`).
//!
//! Required signals (`t_s`, `rate_dph`, `temp_c`) must be present, finite, of equal
//! length, with strictly increasing time: otherwise the whole campaign is refused.
//! Extra columns that cannot be used (missing in a run, NaN/inf, constant over the
//! campaign) are excluded with the reason stated, never silently dropped.
//! Raw-rate records are averaged into 10 s windows (the paper's protocol); slower
//! records (e.g. one mean per burst) are kept as they are.

pub mod derivatives;
pub mod rawrows;
pub mod window;

use super::error::DiagnoseError;
use crate::io::runs::Run;
use derivatives::WidthChoice;
use window::{window_bins, WINDOW_S};

/// One run as 10 s means: drift = rate - Earth rate, and every extra column.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub ambient_c: Option<f64>,
    pub latitude_deg: Option<f64>,
    pub t_s: Vec<f64>,
    pub drift_dph: Vec<f64>,
    pub temp_c: Vec<f64>,
    /// Usable extra columns, in `Campaign::extra_names` order.
    pub extras: Vec<Vec<f64>>,
}

/// A column left out of the analysis and why.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Exclusion {
    pub column: String,
    pub reason: String,
}

/// The checked campaign.
#[derive(Clone, Debug)]
pub struct Campaign {
    pub runs: Vec<Series>,
    pub extra_names: Vec<String>,
    pub exclusions: Vec<Exclusion>,
    /// Half-width of every derivative, chosen per column by leave-one-out validation
    /// (`derivatives::choose`): `temp_c` first, then the extras, rate before accel.
    pub derivative_widths: Vec<WidthChoice>,
}

impl Campaign {
    /// Total number of 10 s points.
    pub fn points(&self) -> usize {
        self.runs.iter().map(|r| r.t_s.len()).sum()
    }

    /// The validated half-width of the order-`order` derivative of `column`, s (two 10 s
    /// windows when the column could not be validated: too few samples; the fit then uses
    /// what the run has).
    pub fn half_width_s(&self, column: &str, order: usize) -> f64 {
        let derivative = if order == 1 { "rate" } else { "accel" };
        self.derivative_widths
            .iter()
            .find(|w| w.column == column && w.derivative == derivative)
            .map_or(2.0 * WINDOW_S, |w| w.half_width_s)
    }

    /// Index of an extra column by name.
    pub fn extra_index(&self, name: &str) -> Option<usize> {
        self.extra_names.iter().position(|n| n == name)
    }
}

/// Checks and converts the runs (see the module header for the rules).
pub fn prepare(runs: &[Run]) -> Result<Campaign, DiagnoseError> {
    if runs.is_empty() {
        return Err(DiagnoseError::NoRuns);
    }
    for run in runs {
        check_run(run)?;
    }
    let (extra_names, exclusions) = usable_extras(runs);
    let series: Vec<Series> = runs.iter().map(|r| to_series(r, &extra_names)).collect();
    let derivative_widths = choose_widths(&series, &extra_names);
    let campaign = Campaign {
        runs: series,
        extra_names,
        exclusions,
        derivative_widths,
    };
    for (name, pick) in [("temp_c", 0usize), ("rate_dph", 1)] {
        let all: Vec<f64> = campaign
            .runs
            .iter()
            .flat_map(|s| {
                if pick == 0 {
                    s.temp_c.iter()
                } else {
                    s.drift_dph.iter()
                }
            })
            .copied()
            .collect();
        if is_constant(&all) {
            return Err(DiagnoseError::ConstantRequired {
                column: name.to_owned(),
            });
        }
    }
    Ok(campaign)
}

/// Validated derivative half-widths of `temp_c` and every extra column (rate, accel).
fn choose_widths(series: &[Series], extra_names: &[String]) -> Vec<WidthChoice> {
    let mut out = Vec::new();
    let columns = std::iter::once(("temp_c", None)).chain(
        extra_names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.as_str(), Some(i))),
    );
    for (name, extra) in columns {
        let runs: Vec<(&[f64], &[f64])> = series
            .iter()
            .map(|s| {
                let x: &[f64] = match extra {
                    None => &s.temp_c,
                    Some(i) => &s.extras[i],
                };
                (s.t_s.as_slice(), x)
            })
            .collect();
        for order in [1, 2] {
            out.extend(derivatives::choose(name, &runs, order));
        }
    }
    out
}

fn check_run(run: &Run) -> Result<(), DiagnoseError> {
    let name = run.name();
    let t = run
        .column("t_s")
        .ok_or_else(|| DiagnoseError::MissingColumn {
            run: name.clone(),
            column: "t_s".into(),
        })?;
    for req in ["rate_dph", "temp_c"] {
        if run.column(req).is_none() {
            return Err(DiagnoseError::MissingColumn {
                run: name.clone(),
                column: req.into(),
            });
        }
    }
    if run.columns.len() != run.data.len() {
        return Err(DiagnoseError::MismatchedLength {
            run: name,
            column: "(header)".into(),
            expected: run.columns.len(),
            found: run.data.len(),
        });
    }
    for (col, values) in run.columns.iter().zip(&run.data) {
        if values.len() != t.len() {
            return Err(DiagnoseError::MismatchedLength {
                run: name.clone(),
                column: col.clone(),
                expected: t.len(),
                found: values.len(),
            });
        }
        let required = ["t_s", "rate_dph", "temp_c", "earth_dph"].contains(&col.as_str());
        if required {
            if let Some(row) = values.iter().position(|v| !v.is_finite()) {
                return Err(DiagnoseError::NotFinite {
                    run: name.clone(),
                    column: col.clone(),
                    row,
                });
            }
        }
    }
    if let Some(row) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(DiagnoseError::TimeNotIncreasing {
            run: name,
            row: row + 1,
        });
    }
    Ok(())
}

fn is_constant(v: &[f64]) -> bool {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    let tol = 1e-12 * (1.0 + hi.abs().max(lo.abs()));
    (hi - lo).partial_cmp(&tol) != Some(std::cmp::Ordering::Greater)
}

/// Extra columns usable in every run, plus the stated exclusions.
fn usable_extras(runs: &[Run]) -> (Vec<String>, Vec<Exclusion>) {
    let mut names: Vec<String> = Vec::new();
    for run in runs {
        for (n, _) in run.extra_columns() {
            if !names.iter().any(|x| x == n) {
                names.push(n.to_owned());
            }
        }
    }
    let mut keep = Vec::new();
    let mut excl = Vec::new();
    for n in names {
        let missing: Vec<String> = runs
            .iter()
            .filter(|r| r.column(&n).is_none())
            .map(Run::name)
            .collect();
        if !missing.is_empty() {
            excl.push(Exclusion {
                column: n,
                reason: format!("missing in run(s) {}", missing.join(", ")),
            });
            continue;
        }
        let bad = runs.iter().find_map(|r| {
            r.column(&n)
                .unwrap_or(&[])
                .iter()
                .position(|v| !v.is_finite())
                .map(|row| (r.name(), row))
        });
        if let Some((run, row)) = bad {
            excl.push(Exclusion {
                column: n,
                reason: format!("NaN or infinite value (run {run}, row {row})"),
            });
            continue;
        }
        let all: Vec<f64> = runs
            .iter()
            .flat_map(|r| r.column(&n).unwrap_or(&[]).iter().copied())
            .collect();
        if is_constant(&all) {
            excl.push(Exclusion {
                column: n,
                reason: "constant over the whole campaign".into(),
            });
            continue;
        }
        keep.push(n);
    }
    (keep, excl)
}

fn to_series(run: &Run, extra_names: &[String]) -> Series {
    let t = run.t_s();
    let drift = run.drift_dph();
    let temp = run.temp_c();
    let extras: Vec<&[f64]> = extra_names
        .iter()
        .map(|n| run.column(n).unwrap_or(&[]))
        .collect();
    let bins = window_bins(t);
    let mean_of = |v: &[f64]| -> Vec<f64> {
        bins.iter()
            .map(|b| v[b.0..b.1].iter().sum::<f64>() / (b.1 - b.0) as f64)
            .collect()
    };
    Series {
        name: run.name(),
        ambient_c: run.ambient_c(),
        latitude_deg: run.latitude_deg(),
        t_s: mean_of(t),
        drift_dph: mean_of(&drift),
        temp_c: mean_of(temp),
        extras: extras.iter().map(|v| mean_of(v)).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(name: &str, cols: Vec<(&str, Vec<f64>)>) -> Run {
        Run {
            path: name.into(),
            meta: vec![],
            columns: cols.iter().map(|c| c.0.to_owned()).collect(),
            data: cols.into_iter().map(|c| c.1).collect(),
        }
    }

    #[test]
    fn raw_samples_become_10s_means() {
        let t: Vec<f64> = (0..100).map(|i| 0.5 + i as f64).collect();
        let r = run(
            "a",
            vec![
                ("t_s", t.clone()),
                ("rate_dph", t.clone()),
                ("temp_c", t.iter().map(|x| x * 0.1).collect()),
            ],
        );
        let c = prepare(&[r]).unwrap();
        assert_eq!(c.runs[0].t_s.len(), 10);
        assert!((c.runs[0].drift_dph[0] - 5.0).abs() < 1e-12);
    }

    #[test]
    fn bad_input_is_named() {
        let t = vec![10.0, 20.0, 30.0];
        let short = run(
            "s",
            vec![
                ("t_s", t.clone()),
                ("rate_dph", vec![1.0, 2.0]),
                ("temp_c", t.clone()),
            ],
        );
        assert!(matches!(
            prepare(&[short]),
            Err(DiagnoseError::MismatchedLength { .. })
        ));
        let nan = run(
            "n",
            vec![
                ("t_s", t.clone()),
                ("rate_dph", vec![1.0, f64::NAN, 2.0]),
                ("temp_c", t.clone()),
            ],
        );
        assert!(matches!(
            prepare(&[nan]),
            Err(DiagnoseError::NotFinite { row: 1, .. })
        ));
        let extra = run(
            "e",
            vec![
                ("t_s", t.clone()),
                ("rate_dph", vec![1.0, 3.0, 2.0]),
                ("temp_c", t.clone()),
                ("k", vec![1.0; 3]),
                ("q", vec![0.0, f64::NAN, 1.0]),
            ],
        );
        let c = prepare(&[extra]).unwrap();
        assert!(c.extra_names.is_empty());
        assert_eq!(c.exclusions.len(), 2);
        assert!(prepare(&[]).is_err());
    }
}
