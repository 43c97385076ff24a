//! The between-run stage's data: the run offsets the chosen base leaves, and the
//! run-level library (one feature vector per run: circular-mean harmonics of angle
//! columns, run means of the other columns, the ambient, every metadata key as its type
//! allows (`candidates::metadata`) and the runs' order), each tagged with the family
//! of operators it comes from so the report can say how many each family contributed.

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::candidates::generic::few_levels;
use crate::diagnose::candidates::metadata::{MetaColumn, MetaKind};
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::folds::Folds;
use crate::stats::mean_or_zero;
use serde::Serialize;

/// One run-level candidate: `features[r]` holds run r's feature values.
#[derive(Clone, Debug)]
pub struct RunCandidate {
    pub label: String,
    pub column: String,
    pub family: Family,
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

/// Which operator made a run-level candidate (the report counts candidates per family).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    ColumnRunMean,
    Harmonic,
    Ambient,
    MetaNumber,
    MetaTime,
    MetaVersion,
    MetaLevels,
    RunOrder,
}

/// Every family, in the report's order.
pub const FAMILIES: [Family; 8] = [
    Family::ColumnRunMean,
    Family::Harmonic,
    Family::Ambient,
    Family::MetaNumber,
    Family::MetaTime,
    Family::MetaVersion,
    Family::MetaLevels,
    Family::RunOrder,
];

impl Family {
    /// The family's name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Self::ColumnRunMean => "column run means",
            Self::Harmonic => "angle harmonics",
            Self::Ambient => "ambient",
            Self::MetaNumber => "metadata numbers",
            Self::MetaTime => "metadata times",
            Self::MetaVersion => "metadata versions",
            Self::MetaLevels => "metadata levels",
            Self::RunOrder => "run order",
        }
    }

    fn of(kind: MetaKind) -> Self {
        match kind {
            MetaKind::Number => Self::MetaNumber,
            MetaKind::Time => Self::MetaTime,
            MetaKind::Version => Self::MetaVersion,
            MetaKind::Category => Self::MetaLevels,
        }
    }
}

/// How many run-level candidates a family contributed.
#[derive(Clone, Debug, Serialize)]
pub struct FamilyCount {
    pub family: &'static str,
    pub candidates: usize,
}

/// Candidates per family, every family listed (zero included).
pub fn family_counts(cands: &[RunCandidate]) -> Vec<FamilyCount> {
    FAMILIES
        .iter()
        .map(|f| FamilyCount {
            family: f.name(),
            candidates: cands.iter().filter(|c| c.family == *f).count(),
        })
        .collect()
}

/// Run-level candidates: the harmonic (cos, sin of the run's circular mean) of every
/// `*_deg` column, the run mean of every other extra column, the ambient, every
/// metadata key (number, days, version rank, or indicators of all but its commonest
/// level) and the runs' order; those that do not vary between runs are dropped.
pub fn enumerate(c: &Campaign, meta: &[MetaColumn]) -> Vec<RunCandidate> {
    let mut out: Vec<RunCandidate> = c
        .extra_names
        .iter()
        .enumerate()
        .map(|(j, name)| column_feature(c, j, name))
        .collect();
    if c.runs.iter().all(|s| s.ambient_c.is_some()) {
        out.push(RunCandidate {
            label: "ambient_c:run_value".into(),
            column: "ambient_c".into(),
            family: Family::Ambient,
            features: c
                .runs
                .iter()
                .map(|s| vec![s.ambient_c.unwrap_or(0.0)])
                .collect(),
        });
    }
    let meta: Vec<&MetaColumn> = meta
        .iter()
        .filter(|m| m.run_values.len() == c.runs.len())
        .collect();
    out.extend(meta.iter().map(|m| meta_feature(m)));
    out.push(run_order(c.runs.len(), &meta));
    out.retain(|c| varies(&c.features));
    out
}

/// The harmonic of an angle column's circular run mean, or another column's run mean.
fn column_feature(c: &Campaign, j: usize, name: &str) -> RunCandidate {
    if !name.ends_with("_deg") {
        return RunCandidate {
            label: format!("{name}:run_mean"),
            column: name.to_owned(),
            family: Family::ColumnRunMean,
            features: c
                .runs
                .iter()
                .map(|s| vec![mean_or_zero(&s.extras[j])])
                .collect(),
        };
    }
    let features = c
        .runs
        .iter()
        .map(|s| {
            let mean_of = |f: fn(f64) -> f64| {
                mean_or_zero(
                    &s.extras[j]
                        .iter()
                        .map(|a| f(a.to_radians()))
                        .collect::<Vec<_>>(),
                )
            };
            let ang = mean_of(f64::sin).atan2(mean_of(f64::cos));
            vec![ang.cos(), ang.sin()]
        })
        .collect();
    RunCandidate {
        label: format!("{name}:run_harmonic"),
        column: name.to_owned(),
        family: Family::Harmonic,
        features,
    }
}

/// A metadata key's run-level feature: its value (number, days, version rank) or
/// indicators of all but its commonest level.
fn meta_feature(m: &MetaColumn) -> RunCandidate {
    let levels = (m.kind == MetaKind::Category)
        .then(|| few_levels(m.run_values.iter().copied()))
        .flatten();
    let features = match levels {
        Some(l) => {
            let count = |v: f64| m.run_values.iter().filter(|x| **x == v).count();
            let reference = l.iter().copied().max_by_key(|v| count(*v)).unwrap_or(0.0);
            let shown: Vec<f64> = l.into_iter().filter(|v| *v != reference).collect();
            m.run_values
                .iter()
                .map(|x| shown.iter().map(|v| f64::from(u8::from(x == v))).collect())
                .collect()
        }
        None => m.run_values.iter().map(|x| vec![*x]).collect(),
    };
    RunCandidate {
        label: format!("# {}:{}", m.key, m.kind.run_operator()),
        column: m.key.clone(),
        family: Family::of(m.kind),
        features,
    }
}

/// The runs' order (0 = first): by the first time key when there is one (ties in input
/// order), else the input order. A drift that ages from run to run is linear in it when
/// no metadata says when a run was made.
fn run_order(runs: usize, meta: &[&MetaColumn]) -> RunCandidate {
    let mut by: Vec<usize> = (0..runs).collect();
    if let Some(t) = meta.iter().find(|m| m.kind == MetaKind::Time) {
        by.sort_by(|a, b| t.run_values[*a].total_cmp(&t.run_values[*b]));
    }
    let mut rank = vec![0.0; runs];
    for (k, r) in by.into_iter().enumerate() {
        rank[r] = k as f64;
    }
    RunCandidate {
        label: "run_order".into(),
        column: "run_order".into(),
        family: Family::RunOrder,
        features: rank.into_iter().map(|x| vec![x]).collect(),
    }
}

fn varies(f: &[Vec<f64>]) -> bool {
    let k = f.first().map_or(0, Vec::len);
    (0..k).any(|j| {
        let v: Vec<f64> = f.iter().map(|x| x[j]).collect();
        let m = mean_or_zero(&v);
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() > 1e-12 * (1.0 + m * m) * v.len() as f64
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_run_order_follows_the_first_time_key_else_the_input() {
        let order = |meta: &[&MetaColumn]| -> Vec<f64> {
            run_order(4, meta).features.into_iter().flatten().collect()
        };
        assert_eq!(order(&[]), vec![0.0, 1.0, 2.0, 3.0]);
        let lot = MetaColumn {
            key: "lot".into(),
            run_values: vec![1.0, 0.0, 1.0, 1.0],
            kind: MetaKind::Category,
        };
        let days = MetaColumn {
            key: "start_time".into(),
            run_values: vec![30.0, 0.0, 2.5, 0.5],
            kind: MetaKind::Time,
        };
        assert_eq!(order(&[&lot]), vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(order(&[&lot, &days]), vec![3.0, 0.0, 2.0, 1.0]);
        let f = meta_feature(&days);
        assert_eq!(
            (f.label.as_str(), f.family),
            ("# start_time:days", Family::MetaTime)
        );
        let f = meta_feature(&lot);
        assert_eq!(
            (f.label.as_str(), f.features[0].clone()),
            ("# lot:levels", vec![0.0])
        );
    }
}
