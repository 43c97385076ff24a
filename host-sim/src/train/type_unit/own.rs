//! The unit's own model beside its unit calibration: when a unit's own runs say more about
//! it than its type does, it leaves the type.
//!
//! The unit step corrects the type's shared model by a few unit terms; where a unit differs
//! from its type in a way those terms cannot carry (measured on the independent fleet:
//! with 48 runs the unit's runs alone met 8 of 9 cells, the type + unit recipe 2 of 9, both
//! reading dT/dt as the slope), more runs never help it. So the unit's own model (the caller's ordinary training, the
//! type-free recipe) is scored the way the unit step scored its candidates: trained
//! without some of the unit's runs, read on each run left out in the windows of the first
//! `calibrate::SCORED_SEEKS` seeks, each window less what the seek cancels. It is taken only when the
//! mean of the per-run differences (the unit step's chosen candidate, left out one run at a
//! time, less the own model's) is above zero at one-sided `OWN_ALPHA` (Student's t over the
//! unit's runs): the unit step chose its candidate on those same scores, so the comparison
//! leans to the type, and the level is the misfit test's. With 6 runs the own model wins
//! nowhere tried (the independent fleet: t -1.1 to -3.5; 40 simulated fleets: t -4.9 to
//! 2.5, the critical t at 5 degrees of freedom 3.4); with 48 runs of a unit its type cannot
//! carry, it does (t 4.7-6.7).

use anyhow::{anyhow, bail, Result};
use fog_core::model::format::RbfModel;
use serde::Serialize;

use super::calibrate::{seek_windows_mean_square, UnitCalibration, UnitPlan};
use crate::io::runs::Run;
use crate::stats::student_t::upper_quantile;
use crate::stats::{mean, mean_or_zero, std_dev};
use crate::train::warmup_clock::in_runs_clock;
use crate::train::{
    choose_inputs_default, dataset_from_runs, residuals_dph, train_model, InputSet, TrainConfig,
};

/// Folds of the unit's runs the own model is trained without (at most; one run a fold
/// below that): each fold is one training.
pub const OWN_FOLDS: usize = 6;
/// The own model is taken when the unit step's held-out score exceeds its own at this
/// one-sided level (paired over the unit's runs; the misfit test's family-wise level).
pub const OWN_ALPHA: f64 = 0.01;
/// Fewest runs the comparison is made on (fewer: the unit calibration, for want of power).
pub const OWN_MIN_RUNS: usize = 3;

/// The comparison and its outcome.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OwnChoice {
    pub runs: usize,
    pub folds: usize,
    /// Held-out rms over the unit's runs, deg/h: the unit calibration's chosen candidate
    /// (left out one run at a time) and the own model (left out one fold at a time).
    pub unit_step_dph: f64,
    pub own_dph: f64,
    /// Mean paired difference (unit step less own, (deg/h)^2) over its standard error, and
    /// the t it must exceed (`OWN_ALPHA`, runs - 1 degrees of freedom).
    pub t: f64,
    pub critical_t: f64,
    pub taken: bool,
}

impl OwnChoice {
    pub fn summary(&self) -> String {
        if self.folds == 0 {
            return format!(
                "unit's own model: not compared ({} runs are too few to train it without some of them: no test power); the unit calibration\n",
                self.runs
            );
        }
        format!(
            "unit's own model: held-out drift rms {:.4} deg/h against the unit calibration's {:.4} over {} runs ({} folds), t = {:.1}, critical {:.1} (one-sided {OWN_ALPHA}); {}\n",
            self.own_dph,
            self.unit_step_dph,
            self.runs,
            self.folds,
            self.t,
            self.critical_t,
            if self.taken {
                "its own runs say more than its type: the unit's own model"
            } else {
                "the unit calibration"
            }
        )
    }
}

/// Compares `cal` (the unit calibration of `runs`, scored with `plan`) with the unit's own
/// model, trained by `train` on all but one fold of `runs` at a time. `min_train_runs`:
/// the fewest runs `train` takes (below that with a fold left out: not compared).
pub fn choose_own(
    cal: &UnitCalibration,
    runs: &[Run],
    plan: &UnitPlan,
    min_train_runs: usize,
    train: &mut dyn FnMut(&[Run]) -> Result<RbfModel>,
) -> Result<OwnChoice> {
    let n = runs.len();
    let folds = n.min(OWN_FOLDS);
    let powered = n >= OWN_MIN_RUNS && n - n.div_ceil(folds.max(1)) >= min_train_runs;
    let chosen = cal
        .candidates
        .iter()
        .find(|c| c.terms == cal.terms && c.prior_weight == cal.prior_weight)
        .ok_or_else(|| {
            anyhow!("the unit calibration's chosen candidate is not among its scores")
        })?;
    if chosen.per_run.len() != n {
        bail!(
            "{} held-out scores for {n} runs: the calibration is not of these runs",
            chosen.per_run.len()
        );
    }
    // per-run scores are mean squares: their rms is the root of their mean
    let rms = |v: &[f64]| mean_or_zero(v).sqrt();
    let mut own = vec![f64::NAN; n];
    if powered {
        for k in 0..folds {
            let rest: Vec<Run> = (0..n)
                .filter(|r| r % folds != k)
                .map(|r| runs[r].clone())
                .collect();
            let model = train(&rest)?;
            for r in (0..n).filter(|r| r % folds == k) {
                let ds = dataset_from_runs(std::slice::from_ref(&runs[r]), &model.inputs)?;
                let res = residuals_dph(&model, &ds)?;
                own[r] = seek_windows_mean_square(
                    &res,
                    &ds.t_s,
                    plan.seek_period_s,
                    plan.symmetric_seeks,
                );
            }
        }
    }
    let pairs: Vec<f64> = chosen
        .per_run
        .iter()
        .zip(&own)
        .map(|(a, b)| a - b)
        .filter(|d| d.is_finite())
        .collect();
    let t = paired_t(&pairs);
    let critical_t = upper_quantile(OWN_ALPHA, pairs.len().saturating_sub(1).max(1) as f64);
    let taken = powered && pairs.len() >= 2 && t > critical_t;
    Ok(OwnChoice {
        runs: n,
        folds: if powered { folds } else { 0 },
        unit_step_dph: rms(&chosen.per_run),
        own_dph: rms(&own),
        t,
        critical_t,
        taken,
    })
}

/// Mean over its standard error; 0 with fewer than two values or no spread.
fn paired_t(d: &[f64]) -> f64 {
    let se = std_dev(d) / (d.len() as f64).sqrt();
    if se > 0.0 {
        mean(d) / se
    } else {
        0.0
    }
}

/// The unit's own model as `train` trains it without a type: dT/dt in the clock the runs
/// choose (`cfg.rate_clock`), its input choice over `candidates`, then its network, with
/// `cfg`.
pub fn ordinary_model(
    runs: &[Run],
    candidates: &[InputSet],
    cfg: &TrainConfig,
) -> Result<RbfModel> {
    let (cfg, _) = in_runs_clock(runs, cfg);
    let (_, ds) = choose_inputs_default(runs, candidates, &cfg)?;
    Ok(train_model(&ds, &cfg)?.model)
}
