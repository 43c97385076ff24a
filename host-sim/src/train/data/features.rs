//! From fog-runs records to a training `Dataset`: model inputs per 10 s point computed
//! by fog-core's own feature code (so trained and deployed inputs are identical) and the
//! target drift = rate_dph - earth_dph.

use crate::io::runs::Run;
use crate::train::data::dataset::Dataset;
use crate::train::error::{Result, TrainError};
use fog_core::compensation::features::{features_for_series, FeatureVector};
use fog_core::compensation::label::feature_label;
use fog_core::model::format::{FeatureKind, FeatureSpec, MAX_INPUTS};

/// The paper's inputs: gyro temperature and its rate.
pub fn default_specs() -> Vec<FeatureSpec> {
    fog_core::model::format::PAPER_INPUTS.to_vec()
}

/// Report name of an input, `<column>:<transform>` as in the fog-runs format notes.
pub fn feature_name(spec: &FeatureSpec) -> String {
    match spec.kind {
        FeatureKind::TempC => "temp_c:value".into(),
        FeatureKind::TempRateCps => "temp_c:rate".into(),
        FeatureKind::TempRateDiffusionCps => {
            feature_label("temp_c", "rate_diffusion", Some(f64::from(spec.tau_s))).to_string()
        }
        FeatureKind::TempAccelCps2 => "temp_c:accel".into(),
        FeatureKind::TempAccelFlatStartCps2 => "temp_c:accel_flat_start".into(),
        FeatureKind::TempRiseC => "temp_c:rise".into(),
        FeatureKind::TempLagC => {
            feature_label("temp_c", "lag", Some(f64::from(spec.tau_s))).to_string()
        }
        FeatureKind::PowerOnDecay => {
            feature_label("t_s", "decay", Some(f64::from(spec.tau_s))).to_string()
        }
        FeatureKind::PowerOnDecayStretch => {
            feature_label("t_s", "decay_stretch", Some(f64::from(spec.tau_s))).to_string()
        }
        FeatureKind::AuxValue(n) => format!("aux{n}:value"),
        FeatureKind::AuxRate(n) => format!("aux{n}:rate"),
        FeatureKind::AuxCos(n) => format!("aux{n}:cos"),
        FeatureKind::AuxSin(n) => format!("aux{n}:sin"),
    }
}

/// One group per run (in the given order); rows are the 10 s points at which fog-core's
/// feature code has every input ready (rate estimators need a few rows first).
/// Specs using aux channels need `dataset_from_runs_with_aux`.
pub fn dataset_from_runs(runs: &[Run], specs: &[FeatureSpec]) -> Result<Dataset> {
    dataset_from_runs_with_aux(runs, specs, &[])
}

/// As `dataset_from_runs`, with aux channel n of the specs read from column
/// `aux_columns[n]` of every run.
pub fn dataset_from_runs_with_aux(
    runs: &[Run],
    specs: &[FeatureSpec],
    aux_columns: &[&str],
) -> Result<Dataset> {
    let names = specs
        .iter()
        .map(|s| feature_name_with_aux(s, aux_columns))
        .collect();
    let mut ds = Dataset::with_specs(specs.to_vec(), names)?;
    for run in runs {
        let name = run.name();
        let fail = |why: String| TrainError::Features {
            run: name.clone(),
            why,
        };
        let aux: Vec<Vec<f32>> = aux_columns
            .iter()
            .map(|&c| {
                run.column(c)
                    .map(|v| v.iter().map(|&x| x as f32).collect())
                    .ok_or_else(|| TrainError::MissingColumn {
                        run: name.clone(),
                        column: c.to_string(),
                    })
            })
            .collect::<Result<_>>()?;
        let aux_refs: Vec<&[f32]> = aux.iter().map(Vec::as_slice).collect();
        let temp: Vec<f32> = run.temp_c().iter().map(|&x| x as f32).collect();
        let mut vectors = vec![
            FeatureVector {
                values: [0.0; MAX_INPUTS],
                len: 0,
                ready: false
            };
            run.len()
        ];
        features_for_series(specs, run.t_s(), &temp, &aux_refs, &mut vectors)
            .map_err(|e| fail(e.to_string()))?;
        let drift = run.drift_dph();
        let mut rows = Vec::new();
        let mut targets = Vec::new();
        let mut times = Vec::new();
        for (i, v) in vectors.iter().enumerate().filter(|(_, v)| v.ready) {
            rows.push(v.as_slice().iter().map(|&x| f64::from(x)).collect());
            targets.push(drift[i]);
            times.push(run.t_s()[i]);
        }
        let id = ds
            .push_group(&name, &rows, &targets, &times)
            .map_err(|e| fail(e.to_string()))?;
        ds.set_group_ambient(id, run.ambient_c());
    }
    if ds.is_empty() {
        return Err(TrainError::EmptyDataset);
    }
    Ok(ds)
}

/// `feature_name`, with aux channels named by their run column.
pub fn feature_name_with_aux(spec: &FeatureSpec, aux_columns: &[&str]) -> String {
    let col = |n: u8| {
        aux_columns
            .get(n as usize)
            .map_or_else(|| format!("aux{n}"), |c| c.to_string())
    };
    match spec.kind {
        FeatureKind::AuxValue(n) => format!("{}:value", col(n)),
        FeatureKind::AuxRate(n) => format!("{}:rate", col(n)),
        FeatureKind::AuxCos(n) => format!("{}:cos", col(n)),
        FeatureKind::AuxSin(n) => format!("{}:sin", col(n)),
        _ => feature_name(spec),
    }
}
