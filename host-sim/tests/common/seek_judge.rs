//! How the own-model tests on the soaked generator judge a model: the recipe's plan at the
//! generator's site (seek criterion, 110 s dwell, 40 deg latitude) and the seek azimuth rms
//! of a model's residuals on runs it did not see.

use fog_core::model::format::{FeatureSpec, RbfModel};
use fog_sim::io::runs::Run;
use fog_sim::pipeline::north_seek::own_model::OwnModelPlan;
use fog_sim::train::seek_score::{seek_azimuth_rms_deg, Criterion, SeekGeometry};
use fog_sim::train::{dataset_from_runs, residuals_dph, Dataset};

pub const LATITUDE_DEG: f64 = 40.0;
pub const DWELL_S: f64 = 110.0;

/// The own model's plan for campaigns at `ambient_c`: `auto` inputs, the seek criterion,
/// no seek refit.
pub fn plan(ambient_c: f64) -> OwnModelPlan {
    OwnModelPlan {
        ambient_c,
        latitude_deg: LATITUDE_DEG,
        dwell_s: DWELL_S,
        seed: 1,
        criterion: Criterion::Seek(SeekGeometry::forward(DWELL_S, LATITUDE_DEG)),
        inputs: fog_sim::train::InputChoice::Auto,
        seek_timing: None,
        rate_clock: Default::default(),
    }
}

/// `model`'s residual (drift less prediction, deg/h) on `runs` read with `specs`, and the
/// rows it was read on.
pub fn residual_dph(model: &RbfModel, runs: &[Run], specs: &[FeatureSpec]) -> (Dataset, Vec<f64>) {
    let ds = dataset_from_runs(runs, specs).unwrap();
    let res = residuals_dph(model, &ds).unwrap();
    (ds, res)
}

/// Seek azimuth rms, deg, of `model`'s residuals on `runs`.
pub fn seek_rms_deg(model: &RbfModel, runs: &[Run], specs: &[FeatureSpec]) -> f64 {
    let (ds, res) = residual_dph(model, runs, specs);
    seek_azimuth_rms_deg(
        &res,
        &ds.groups,
        &ds.t_s,
        SeekGeometry::forward(DWELL_S, LATITUDE_DEG),
    )
}
