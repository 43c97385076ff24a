//! `north-seek`'s own default model: trained on chamber runs at the seek's ambient, with as
//! many runs as it takes for the model not to carry its training runs' noise into the seeks.
//!
//! Why: at one ambient every cold start follows nearly the same warm-up trajectory in
//! (T, dT/dt), so whatever the fitted model owes to its particular training runs (their
//! gyro and sensor noise, their run-to-run warm-up differences, and the shape validation
//! picked from them) comes back the same in every start: a systematic, per-seek azimuth
//! bias that no number of seeks averages out. With 3 runs it was the largest error of
//! seeks 1-3 (`docs/northfinder.md`, per-seek tables: -0.013 deg in seek 1 at 20 degC).
//!
//! How many runs is measured, not assumed: the runs are split into two disjoint halves, a
//! model is fitted to each (the same inputs, the same validation), and the difference of
//! their predictions along the runs' own trajectories is scored as a seek sees it
//! (`seek_score::seek_azimuth_rms_deg`). The halves' training sets are independent, so
//! that rms is sqrt(2) x a half model's training-set error, and the model on all runs
//! (twice the runs) has about half its variance: error of the full model = half-split
//! rms / 2. The run count doubles from `FIRST_RUNS` until that estimate is at most
//! `LEARNED_SHARE_OF_FLOOR` x the seek's white-noise floor, or `MAX_RUNS` is reached (then
//! the report says the budget was not met). No held-out gyro noise enters the estimate,
//! so it resolves errors far below the floor; it does not see a misfit both halves share.

use anyhow::{anyhow, Result};
use fog_core::model::format::FeatureSpec;
use fog_core::seeking::northfinder::SeekMode;
use serde::Serialize;

use super::campaign::{CampaignRun, CampaignSpec};
use super::campaign_steps::{simulate_checked, train_with};
use super::northseek::noise_floor_deg;
use crate::io::runs::Run;
use crate::sim::GyroParams;
use crate::train::seek_score::{seek_azimuth_rms_deg, Criterion};
use crate::train::{
    choose_inputs_default, dataset_from_runs, predict_batch, InputSelection, InputSet, TrainConfig,
    TrainOutcome,
};

/// Runs of the first step: two halves of 3, the fewest grouped 3-fold validation takes.
pub const FIRST_RUNS: usize = 6;
/// Most runs tried (one ambient, 45 min each: 36 h of chamber time).
pub const MAX_RUNS: usize = 48;
/// Budget of the learned error (rms over a run's seeks), as a fraction of the seek's
/// white-noise floor. It comes from the product targets, not from the simulator: each
/// seek's mean error must stay within 0.3 of its std (about the floor); the learned error
/// is a different bias in each seek, roughly Gaussian over the seeks with this rms, and
/// the largest of a 45 min run's 12 seek pairs is about 2.4 rms, so the rms may be at most
/// 0.3 / 2.4 = 0.125 floor. (It then adds 0.8 % to the seek std in quadrature.) Checked
/// against the Monte Carlo: the rms of the per-seek mean errors of 300 starts matched the
/// estimate (0.0029 vs 0.0028 deg, 6 runs at 20 degC).
pub const LEARNED_SHARE_OF_FLOOR: f64 = 0.125;

/// What the own model is trained for: the seek's site, ambient, dwell and gyro noise.
#[derive(Clone, Debug)]
pub struct OwnModelPlan {
    pub ambient_c: f64,
    pub latitude_deg: f64,
    pub dwell_s: f64,
    pub seed: u64,
    pub criterion: Criterion,
}

/// One step of the run count search.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunCountStep {
    pub runs: usize,
    /// Estimated per-seek azimuth bias the model on all `runs` owes to its training set, deg
    /// (half-split rms / 2, at |sin psi| = 1).
    pub learned_seek_deg: f64,
}

/// The trained own model and how its run count was chosen.
pub struct OwnModel {
    pub trained: TrainOutcome,
    pub selection: InputSelection,
    pub runs: usize,
    pub steps: Vec<RunCountStep>,
    /// The budget, deg (`LEARNED_SHARE_OF_FLOOR` x the floor at |sin psi| = 1).
    pub budget_deg: f64,
    /// Whether the last step met the budget (false: `MAX_RUNS` reached first).
    pub budget_met: bool,
}

impl OwnModel {
    /// One line per step and the decision, for people.
    pub fn summary(&self) -> String {
        let mut s = String::from(
            "runs at the ambient chosen by the half-split learned seek error (model on all runs):\n",
        );
        for st in &self.steps {
            s += &format!(
                "  {:>3} runs  learned {:.4} deg{}\n",
                st.runs,
                st.learned_seek_deg,
                if st.runs == self.runs {
                    "  <- used"
                } else {
                    ""
                }
            );
        }
        s += &format!(
            "  budget {:.4} deg ({} x the white-noise floor): {}\n",
            self.budget_deg,
            LEARNED_SHARE_OF_FLOOR,
            if self.budget_met {
                "met"
            } else {
                "NOT met at the most runs tried"
            }
        );
        s
    }
}

/// Simulates runs at the plan's ambient and trains the own model on as many as the budget
/// needs (see the module notes).
pub fn train_own_model(params: &GyroParams, plan: &OwnModelPlan) -> Result<OwnModel> {
    let floor_deg = noise_floor_deg(
        params.noise.arw_dpsh,
        SeekMode::TwoPosition,
        plan.latitude_deg,
        90.0,
        plan.dwell_s,
    );
    let budget_deg = LEARNED_SHARE_OF_FLOOR * floor_deg;
    let mut steps = Vec::new();
    let mut n = FIRST_RUNS;
    loop {
        let campaign = simulate_checked(
            params,
            &CampaignSpec {
                ambients_c: vec![plan.ambient_c],
                runs_per_ambient: n,
                latitude_deg: plan.latitude_deg,
                ..CampaignSpec::paper(plan.seed)
            },
        )?;
        let runs: Vec<Run> = campaign.into_iter().map(|c: CampaignRun| c.run).collect();
        // `train`'s defaults, with the plan's criterion choosing the d2T/dt2 estimator as
        // well as the shape.
        let cfg = TrainConfig {
            criterion: plan.criterion,
            ..TrainConfig::default()
        };
        let (selection, _) = choose_inputs_default(&runs, &InputSet::ALL, &cfg)
            .map_err(|e| anyhow!("choosing the own model's inputs: {e}"))?;
        let specs = selection.chosen.specs();
        let learned = learned_seek_error_deg(&runs, &specs, plan)?;
        steps.push(RunCountStep {
            runs: n,
            learned_seek_deg: learned,
        });
        let budget_met = learned <= budget_deg;
        if budget_met || 2 * n > MAX_RUNS {
            let refs: Vec<&Run> = runs.iter().collect();
            let trained = train_with(&refs, &specs, "sim", plan.criterion)?;
            return Ok(OwnModel {
                trained,
                selection,
                runs: n,
                steps,
                budget_deg,
                budget_met,
            });
        }
        n *= 2;
    }
}

/// Half-split estimate of the seek error a model on all `runs` owes to its training set:
/// models on the even and on the odd runs, their prediction difference along every run
/// scored as seeks (`seek_azimuth_rms_deg`), halved.
pub fn learned_seek_error_deg(
    runs: &[Run],
    specs: &[FeatureSpec],
    plan: &OwnModelPlan,
) -> Result<f64> {
    let half = |parity: usize| -> Vec<&Run> {
        runs.iter()
            .enumerate()
            .filter(|(i, _)| i % 2 == parity)
            .map(|(_, r)| r)
            .collect()
    };
    let a = train_with(&half(0), specs, "sim", plan.criterion)?;
    let b = train_with(&half(1), specs, "sim", plan.criterion)?;
    let ds = dataset_from_runs(runs, specs).map_err(|e| anyhow!("half-split: {e}"))?;
    let pa = predict_batch(&a.model, ds.rows()).map_err(|e| anyhow!("half-split: {e}"))?;
    let pb = predict_batch(&b.model, ds.rows()).map_err(|e| anyhow!("half-split: {e}"))?;
    let diff: Vec<f64> = pa.iter().zip(&pb).map(|(x, y)| x - y).collect();
    Ok(0.5 * seek_azimuth_rms_deg(&diff, &ds.groups, &ds.t_s, plan.dwell_s, plan.latitude_deg))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan() -> OwnModelPlan {
        OwnModelPlan {
            ambient_c: 20.0,
            latitude_deg: crate::sim::DEFAULT_LATITUDE_DEG,
            dwell_s: 110.0,
            seed: 1,
            criterion: Criterion::seek_default(),
        }
    }

    fn runs(params: &GyroParams, n: usize) -> Vec<Run> {
        simulate_checked(
            params,
            &CampaignSpec {
                ambients_c: vec![20.0],
                runs_per_ambient: n,
                ..CampaignSpec::paper(1)
            },
        )
        .unwrap()
        .into_iter()
        .map(|c| c.run)
        .collect()
    }

    fn with_noise_scaled(params: &GyroParams, k: f64) -> GyroParams {
        let mut p = params.clone();
        p.noise.arw_dpsh *= k;
        p.noise.bias_instability_dph *= k;
        p.noise.rrw_dph_per_sqrt_h *= k;
        p
    }

    #[test]
    fn the_learned_error_follows_the_gyro_noise_and_vanishes_without_it() {
        let specs = crate::train::default_specs();
        let paper = GyroParams::paper_default();
        let learned = |k: f64| {
            learned_seek_error_deg(&runs(&with_noise_scaled(&paper, k), 6), &specs, &plan())
                .unwrap()
        };
        let (base, loud) = (learned(1.0), learned(3.0));
        // Twin with 3x the gyro noise terms: the halves learn more of it.
        assert!(loud > 1.5 * base, "3x noise {loud:.5} deg vs {base:.5} deg");
        // Null twin: identical runs (no gyro or sensor noise, no run-to-run variation),
        // so both halves fit the same data and nothing differs between them.
        let mut same = with_noise_scaled(&paper, 0.0);
        same.noise.quantization_arcsec = 0.0;
        same.sensor.noise_c = 0.0;
        same.variation.power_sigma_frac = 0.0;
        same.variation.start_temp_sigma_c = 0.0;
        let null = learned_seek_error_deg(&runs(&same, 6), &specs, &plan()).unwrap();
        assert!(
            null < 0.05 * base,
            "identical runs {null:.6} deg vs {base:.5} deg"
        );
    }
}
