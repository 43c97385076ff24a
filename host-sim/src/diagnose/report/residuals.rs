//! Where the baseline's held-out residual has structure: by time since power-on, per
//! ambient temperature, and against each signal (within-run correlation).

use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::folds::{demeaned_by_run, Folds};
use serde::Serialize;

/// Ambients closer than this belong to one group, degC.
pub const AMBIENT_GAP_C: f64 = 3.0;
/// Time-since-power-on bins, s.
pub const TIME_BINS_S: [f64; 7] = [0.0, 120.0, 300.0, 600.0, 1200.0, 2700.0, f64::INFINITY];

/// Residual statistics over one slice of the data.
#[derive(Clone, Debug, Serialize)]
pub struct Slice {
    pub label: String,
    pub n: usize,
    pub mean_dph: f64,
    pub rms_dph: f64,
}

/// Residual against one signal.
#[derive(Clone, Debug, Serialize)]
pub struct SignalLink {
    pub signal: String,
    /// Pearson correlation of within-run deviations.
    pub correlation: f64,
}

/// The residual's structure.
#[derive(Clone, Debug, Serialize)]
pub struct Structure {
    pub by_time: Vec<Slice>,
    pub by_ambient: Vec<Slice>,
    pub by_signal: Vec<SignalLink>,
}

fn slice(label: String, r: impl Iterator<Item = f64>) -> Slice {
    let v: Vec<f64> = r.collect();
    let n = v.len();
    let mean = v.iter().sum::<f64>() / n.max(1) as f64;
    let rms = (v.iter().map(|x| x * x).sum::<f64>() / n.max(1) as f64).sqrt();
    Slice {
        label,
        n,
        mean_dph: mean,
        rms_dph: rms,
    }
}

/// Within-run Pearson correlation.
pub fn within_run_correlation(folds: &Folds, a: &[f64], b: &[f64]) -> f64 {
    let a = demeaned_by_run(&folds.run_rows, a);
    let b = demeaned_by_run(&folds.run_rows, b);
    let ab: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    let aa: f64 = a.iter().map(|x| x * x).sum();
    let bb: f64 = b.iter().map(|x| x * x).sum();
    if aa <= 0.0 || bb <= 0.0 {
        0.0
    } else {
        ab / (aa * bb).sqrt()
    }
}

/// Runs grouped by ambient temperature: sorted, a new group wherever the gap to the
/// previous ambient exceeds `AMBIENT_GAP_C`. Runs without an ambient are left out.
fn ambient_groups(c: &Campaign) -> Vec<(String, Vec<usize>)> {
    let mut idx: Vec<(usize, f64)> = c
        .runs
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.ambient_c.map(|a| (i, a)))
        .collect();
    idx.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut groups: Vec<Vec<(usize, f64)>> = Vec::new();
    for (i, a) in idx {
        match groups.last_mut() {
            Some(g) if g.last().is_some_and(|l| a - l.1 <= AMBIENT_GAP_C) => g.push((i, a)),
            _ => groups.push(vec![(i, a)]),
        }
    }
    groups
        .into_iter()
        .map(|g| {
            let mean = g.iter().map(|x| x.1).sum::<f64>() / g.len() as f64;
            (
                format!("{mean:.1} degC ({} runs)", g.len()),
                g.into_iter().map(|x| x.0).collect(),
            )
        })
        .collect()
}

/// Builds the structure tables for `residual` (stacked, one per row).
pub fn structure(c: &Campaign, folds: &Folds, st: &Stacked, residual: &[f64]) -> Structure {
    let by_time = TIME_BINS_S
        .windows(2)
        .filter_map(|w| {
            let s = slice(
                if w[1].is_finite() {
                    format!("{:.0}-{:.0} min", w[0] / 60.0, w[1] / 60.0)
                } else {
                    format!(">{:.0} min", w[0] / 60.0)
                },
                st.t_s
                    .iter()
                    .zip(residual)
                    .filter(|(t, _)| **t >= w[0] && **t < w[1])
                    .map(|(_, r)| *r),
            );
            (s.n > 0).then_some(s)
        })
        .collect();
    let by_ambient = ambient_groups(c)
        .into_iter()
        .map(|(label, members)| {
            let rows = members.iter().flat_map(|&i| folds.run_rows[i].clone());
            slice(label, rows.map(|i| residual[i]))
        })
        .collect();
    let mut by_signal = vec![
        SignalLink {
            signal: "t_s".into(),
            correlation: within_run_correlation(folds, &st.t_s, residual),
        },
        SignalLink {
            signal: "temp_c".into(),
            correlation: within_run_correlation(folds, &st.temp_c, residual),
        },
        SignalLink {
            signal: "temp_c:rate".into(),
            correlation: within_run_correlation(folds, &st.temp_rate_cps, residual),
        },
    ];
    for (i, name) in c.extra_names.iter().enumerate() {
        let v: Vec<f64> = c
            .runs
            .iter()
            .flat_map(|s| s.extras[i].iter().copied())
            .collect();
        by_signal.push(SignalLink {
            signal: name.clone(),
            correlation: within_run_correlation(folds, &v, residual),
        });
    }
    Structure {
        by_time,
        by_ambient,
        by_signal,
    }
}
