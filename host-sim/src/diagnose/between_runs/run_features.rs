//! The between-run stage's data: the run offsets the chosen base leaves, and the
//! run-level library (one feature vector per run: circular-mean harmonics of angle
//! columns, run means of the other columns, metadata values and levels).

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::candidates::generic::{few_levels, MetaColumn};
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::folds::Folds;
use crate::stats::mean_or_zero;

/// One run-level candidate: `features[r]` holds run r's feature values.
#[derive(Clone, Debug)]
pub struct RunCandidate {
    pub label: String,
    pub column: String,
    pub harmonic: bool,
    pub features: Vec<Vec<f64>>,
}

/// Run offsets left by the base fitted on every run: mean over the run of drift minus
/// the base's prediction (the base itself carries no offset).
pub fn run_offsets(folds: &Folds, st: &Stacked, base: &BaseFit) -> Vec<f64> {
    let design = base.raw_design();
    let w = base
        .prepared
        .fit_all(folds, &[])
        .map(|(w, _)| w)
        .unwrap_or_default();
    let mut row = vec![0.0; design.width()];
    folds
        .run_rows
        .iter()
        .map(|r| {
            let resid: Vec<f64> = r
                .clone()
                .map(|i| {
                    design.row(i, &mut row);
                    st.y[i] - row.iter().zip(&w).map(|(c, wj)| c * wj).sum::<f64>()
                })
                .collect();
            mean_or_zero(&resid)
        })
        .collect()
}

/// Run-level candidates: the harmonic (cos, sin of the run's circular mean) of every
/// `*_deg` column, the run mean of every other extra column, the ambient, and every
/// metadata key (value, or indicators of all but its commonest level).
pub fn enumerate(c: &Campaign, meta: &[MetaColumn]) -> Vec<RunCandidate> {
    let mut out = Vec::new();
    for (j, name) in c.extra_names.iter().enumerate() {
        if name.ends_with("_deg") {
            let f = c
                .runs
                .iter()
                .map(|s| {
                    let cs = mean_or_zero(
                        &s.extras[j]
                            .iter()
                            .map(|a| a.to_radians().cos())
                            .collect::<Vec<_>>(),
                    );
                    let sn = mean_or_zero(
                        &s.extras[j]
                            .iter()
                            .map(|a| a.to_radians().sin())
                            .collect::<Vec<_>>(),
                    );
                    let ang = sn.atan2(cs);
                    vec![ang.cos(), ang.sin()]
                })
                .collect();
            out.push(RunCandidate {
                label: format!("{name}:run_harmonic"),
                column: name.clone(),
                harmonic: true,
                features: f,
            });
        } else {
            out.push(RunCandidate {
                label: format!("{name}:run_mean"),
                column: name.clone(),
                harmonic: false,
                features: c
                    .runs
                    .iter()
                    .map(|s| vec![mean_or_zero(&s.extras[j])])
                    .collect(),
            });
        }
    }
    if c.runs.iter().all(|s| s.ambient_c.is_some()) {
        out.push(RunCandidate {
            label: "ambient_c:run_value".into(),
            column: "ambient_c".into(),
            harmonic: false,
            features: c
                .runs
                .iter()
                .map(|s| vec![s.ambient_c.unwrap_or(0.0)])
                .collect(),
        });
    }
    for m in meta.iter().filter(|m| m.run_values.len() == c.runs.len()) {
        let levels = m
            .categorical
            .then(|| few_levels(m.run_values.iter().copied()))
            .flatten();
        let (label, features) = match levels {
            Some(l) => {
                let count = |v: f64| m.run_values.iter().filter(|x| **x == v).count();
                let reference = l.iter().copied().max_by_key(|v| count(*v)).unwrap_or(0.0);
                let shown: Vec<f64> = l.into_iter().filter(|v| *v != reference).collect();
                (
                    format!("# {}:levels", m.key),
                    m.run_values
                        .iter()
                        .map(|x| shown.iter().map(|v| f64::from(u8::from(x == v))).collect())
                        .collect(),
                )
            }
            None => (
                format!("# {}:run_value", m.key),
                m.run_values.iter().map(|x| vec![*x]).collect(),
            ),
        };
        out.push(RunCandidate {
            label,
            column: m.key.clone(),
            harmonic: false,
            features,
        });
    }
    out.retain(|c| varies(&c.features));
    out
}

fn varies(f: &[Vec<f64>]) -> bool {
    let k = f.first().map_or(0, Vec::len);
    (0..k).any(|j| {
        let v: Vec<f64> = f.iter().map(|x| x[j]).collect();
        let m = mean_or_zero(&v);
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() > 1e-12 * (1.0 + m * m) * v.len() as f64
    })
}
