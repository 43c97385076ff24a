//! From fog-runs records to a training `Dataset`: model inputs per 10 s point computed
//! by fog-core's own feature code (so trained and deployed inputs are identical) and the
//! target drift = rate_dph - earth_dph.

use super::dataset::Dataset;
use super::error::{Result, TrainError};
use crate::runs::Run;
use fog_core::model::{FeatureKind, FeatureSpec};

/// The paper's inputs: gyro temperature and its rate.
pub fn default_specs() -> Vec<FeatureSpec> {
    vec![
        FeatureSpec { kind: FeatureKind::TempC, tau_s: 0.0 },
        FeatureSpec { kind: FeatureKind::TempRateCps, tau_s: 0.0 },
    ]
}

/// Report name of an input, `<column>:<transform>` as in the fog-runs format notes.
pub fn feature_name(spec: &FeatureSpec) -> String {
    match spec.kind {
        FeatureKind::TempC => "temp_c:value".into(),
        FeatureKind::TempRateCps => "temp_c:rate".into(),
        FeatureKind::TempAccelCps2 => "temp_c:accel".into(),
        FeatureKind::TempLagC => format!("temp_c:lag(tau_s={})", spec.tau_s),
        FeatureKind::PowerOnDecay => format!("t_s:decay(tau_s={})", spec.tau_s),
        FeatureKind::AuxValue(n) => format!("aux{n}:value"),
        FeatureKind::AuxRate(n) => format!("aux{n}:rate"),
        FeatureKind::AuxCos(n) => format!("aux{n}:cos"),
        FeatureKind::AuxSin(n) => format!("aux{n}:sin"),
    }
}

/// One group per run (in the given order); rows are the 10 s points at which fog-core's
/// feature code yields every input.
pub fn dataset_from_runs(runs: &[Run], specs: &[FeatureSpec]) -> Result<Dataset> {
    let names = specs.iter().map(feature_name).collect();
    let mut ds = Dataset::with_specs(specs.to_vec(), names)?;
    for run in runs {
        let name = run.name();
        let drift = run.drift_dph();
        let inputs = TEMP_inputs(run, specs).map_err(|why| TrainError::Features { run: name.clone(), why })?;
        let mut rows = Vec::new();
        let mut targets = Vec::new();
        let mut times = Vec::new();
        for (i, row) in inputs.into_iter().enumerate() {
            if let Some(row) = row {
                rows.push(row);
                targets.push(drift[i]);
                times.push(run.t_s()[i]);
            }
        }
        ds.push_group(&name, &rows, &targets, &times)
            .map_err(|e| TrainError::Features { run: name.clone(), why: e.to_string() })?;
    }
    if ds.is_empty() {
        return Err(TrainError::EmptyDataset);
    }
    Ok(ds)
}

#[allow(non_snake_case)]
fn TEMP_inputs(run: &Run, specs: &[FeatureSpec]) -> std::result::Result<Vec<Option<Vec<f64>>>, String> {
    let t = run.t_s();
    let temp = run.temp_c();
    Ok((0..run.len())
        .map(|i| {
            if i < 3 {
                return None;
            }
            let slope = (temp[i] - temp[i - 3]) / (t[i] - t[i - 3]);
            Some(
                specs
                    .iter()
                    .map(|s| match s.kind {
                        FeatureKind::TempC => temp[i],
                        _ => slope,
                    })
                    .collect(),
            )
        })
        .collect())
}
