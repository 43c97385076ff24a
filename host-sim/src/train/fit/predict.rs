//! Batch prediction with fog-core's deployed RBF maths, so every rms the trainer reports
//! is the rms the device would achieve on the same inputs.

use crate::train::error::{Result, TrainError};
use fog_core::model::format::RbfModel;

/// Predicted drift (deg/h) for each row of raw inputs (in `model.inputs` order).
pub fn predict_batch<'r>(
    model: &RbfModel,
    rows: impl IntoIterator<Item = &'r [f64]>,
) -> Result<Vec<f64>> {
    let mut x = [0.0f32; fog_core::model::format::MAX_INPUTS];
    rows.into_iter()
        .enumerate()
        .map(|(i, row)| {
            if row.len() != model.inputs.len() {
                return Err(TrainError::InputCount {
                    expected: model.inputs.len(),
                    found: row.len(),
                    row: i,
                });
            }
            for (xj, &v) in x.iter_mut().zip(row) {
                *xj = v as f32;
            }
            fog_core::model::rbf::predict_f32(model, &x[..row.len()])
                .map(f64::from)
                .map_err(|e| TrainError::Predict {
                    row: i,
                    why: e.to_string(),
                })
        })
        .collect()
}

/// `model`'s residual on `ds`, deg/h: each row's drift less its prediction.
pub fn residuals_dph(model: &RbfModel, ds: &crate::train::Dataset) -> Result<Vec<f64>> {
    let pred = predict_batch(model, ds.rows())?;
    Ok(ds
        .targets_dph
        .iter()
        .zip(&pred)
        .map(|(y, p)| y - p)
        .collect())
}
