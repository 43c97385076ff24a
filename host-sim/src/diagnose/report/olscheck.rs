//! Cross-check with the project's own OLS trainer (`fog_sim::train`, the deployed
//! maths and fog-core's causal feature code): grouped cross-validation of the paper's
//! model and, when the named cause maps to a fog-core feature, of the extended model
//! with the cause as a linear-only input. Run by the command, not inside `diagnose`
//! (it retrains per fold and width, so it is slower than the fixed-basis screening).

use crate::diagnose::candidates::transforms::Transform;
use crate::diagnose::selection::cause::Cause;
use crate::io::runs::Run;
use crate::train::{cross_validate, dataset_from_runs_with_aux, TrainConfig};
use fog_core::model::format::{FeatureKind, FeatureSpec};
use serde::Serialize;

/// Held-out result of one trainer model.
#[derive(Clone, Debug, Serialize)]
pub struct OlsScore {
    pub inputs: Vec<String>,
    /// Pooled held-out std (each held-out run's mean removed), deg/h.
    pub heldout_std_dph: f64,
    pub mean_centres: f64,
}

/// Baseline and (if deployable) extended model as the project's trainer scores them.
#[derive(Clone, Debug, Serialize)]
pub struct OlsCheck {
    pub folds: usize,
    pub baseline: OlsScore,
    pub extended: Option<OlsScore>,
    /// Why the extended model was not scored, if it was not.
    pub note: Option<String>,
}

/// The cause as fog-core feature specs (and the aux columns they read), if the device
/// can compute it.
fn cause_specs(c: &Cause) -> Option<(Vec<FeatureSpec>, Vec<String>)> {
    let spec = |kind, tau_s: f32| FeatureSpec { kind, tau_s };
    let tau = c.tau_s.unwrap_or(0.0) as f32;
    if !c.is_plain() {
        return None;
    }
    match (c.column.as_str(), c.transform) {
        ("temp_c", Transform::Accel) => Some((vec![spec(FeatureKind::TempAccelCps2, 0.0)], vec![])),
        ("temp_c", Transform::Lag) => Some((vec![spec(FeatureKind::TempLagC, tau)], vec![])),
        ("t_s", Transform::Decay) => Some((vec![spec(FeatureKind::PowerOnDecay, tau)], vec![])),
        (col, Transform::Value) => Some((
            vec![spec(FeatureKind::AuxValue(0), 0.0)],
            vec![col.to_owned()],
        )),
        (col, Transform::Rate) => Some((
            vec![spec(FeatureKind::AuxRate(0), 0.0)],
            vec![col.to_owned()],
        )),
        (col, Transform::Harmonic) => Some((
            vec![
                spec(FeatureKind::AuxCos(0), 0.0),
                spec(FeatureKind::AuxSin(0), 0.0),
            ],
            vec![col.to_owned()],
        )),
        _ => None,
    }
}

fn score(
    runs: &[Run],
    specs: &[FeatureSpec],
    aux: &[String],
    linear_only: usize,
    folds: usize,
) -> anyhow::Result<OlsScore> {
    let aux_refs: Vec<&str> = aux.iter().map(String::as_str).collect();
    let ds = dataset_from_runs_with_aux(runs, specs, &aux_refs)?;
    let cfg = TrainConfig {
        linear_only_inputs: linear_only,
        folds,
        ..TrainConfig::default()
    };
    let cv = cross_validate(&ds, &cfg, folds)?;
    Ok(OlsScore {
        inputs: ds.input_names.clone(),
        heldout_std_dph: cv.best.heldout_std_dph,
        mean_centres: cv.best.mean_centers,
    })
}

/// Runs the cross-check (needs at least 4 runs).
pub fn ols_check(runs: &[Run], cause: Option<&Cause>) -> anyhow::Result<OlsCheck> {
    let folds = runs.len().min(5);
    anyhow::ensure!(folds >= 4, "the trainer cross-check needs at least 4 runs");
    let base_specs = fog_core::model::format::PAPER_INPUTS;
    let baseline = score(runs, &base_specs, &[], 0, folds)?;
    let (extended, note) = match cause.map(|c| (c, cause_specs(c))) {
        None => (None, None),
        Some((c, None)) => (
            None,
            Some(format!(
                "{} has no fog-core feature kind (not deployable as is)",
                c.label()
            )),
        ),
        Some((_, Some((specs, aux)))) => {
            let mut all = base_specs.to_vec();
            all.extend(specs.iter().copied());
            match score(runs, &all, &aux, specs.len(), folds) {
                Ok(s) => (Some(s), None),
                Err(e) => (None, Some(format!("extended model not scored: {e}"))),
            }
        }
    };
    Ok(OlsCheck {
        folds,
        baseline,
        extended,
        note,
    })
}
