//! `north-seek`'s own default model: trained on chamber runs at the seek's ambient, with as
//! many runs as it takes for the model not to carry its training runs' noise into the seeks.
//! The same recipe (`own_model_from_runs`) trains `reproduce`'s qualification model, one
//! global model on as many runs at every ambient of the campaign.
//!
//! Why: at one ambient every cold start follows nearly the same warm-up trajectory in
//! (T, dT/dt), so whatever the fitted model owes to its particular training runs (their
//! gyro and sensor noise, their run-to-run warm-up differences, and the shape validation
//! picked from them) comes back the same in every start: a systematic, per-seek azimuth
//! bias that no number of seeks averages out. With 3 runs it was the largest error of
//! seeks 1-3 (`docs/record/northfinder.md`, per-seek tables: -0.013 deg in seek 1 at 20 degC).
//!
//! How many runs: the whole chamber campaign, `CAMPAIGN_RUNS` (96 runs at the ambient,
//! 72 h of chamber time). What the model learns from its runs' noise is a different bias
//! in each seek, the same in every start, and its rms falls as 1/sqrt(runs). Measured over
//! 18 campaigns (-40, 20, +60 degC x seeds 1-6, 1,000 starts each; docs/record/northfinder.md,
//! "The own model's run count"): the rms of the per-seek mean errors was 0.00167 deg with
//! 48 runs (the Monte Carlo's own 0.0005 deg removed), 0.113 x the floor against the
//! budget's 0.125, and one cell's worst seek mean missed the 0.3 std target (0.32); with
//! 96 runs 0.00118 deg (0.71x, 1/sqrt(2)), 0.080 x the floor, and all 18 met the targets.
//! A half-split estimate of what the model owes to its training
//! runs is reported against a budget: the runs are split into two disjoint halves, a model
//! is fitted to each (the same inputs, the same validation), and the difference of their
//! predictions along the runs' own trajectories is scored as a seek sees it
//! (`seek_azimuth_rms_deg`). The halves' training sets are independent, so that rms is
//! sqrt(2) x a half model's training-set error, and the model on all runs has about half
//! its variance: error of the full model = half-split rms / 2, the mean over `SPLITS`
//! disjoint splits. It is a check, not a stopping rule: it measures variance only, and
//! with few runs both halves underfit alike (at +60 degC, seed 4, 6 runs: both halves and
//! the model got 0 centres, the estimate read 0.0014 deg, "met", and the Monte Carlo's seek
//! 1 was 1.17x the floor with a mean of 0.47 std). Stopping at the first run count that met
//! the budget (6, 12, 24 or 48 runs, the rule until 2026-11-26) trained 7 of 18
//! campaigns (3 ambients x 6 seeds) on fewer than 48 runs, and 5 of those 7 missed the
//! seek targets (docs/record/northfinder.md, "Six training campaigns per ambient"). Nor does it
//! tell one campaign's learned error from another's: over six campaigns at +60 degC it
//! read 0.0010-0.0015 deg while the Monte Carlo's per-seek means had an rms of 0.0008 to
//! 0.0027 deg, hardly in the same order (with the seek refit done in the halves as well it
//! read 0.0009-0.0029, the highest where the Monte Carlo had the lowest). So the run count
//! is fixed from the measured mean over campaigns, not grown per campaign.
//!
//! Linear terms in the RBF inputs (T, dT/dt, d2T/dt2 and the clock under the Gaussians) are
//! a shape choice, made by the held-out score of the plan's criterion like the trainer's
//! width and degree (`train --linear-inputs`; `train`'s default stays the paper's pure
//! RBF). Why they are offered: at one ambient every cold start warms along nearly one
//! trajectory, and the runs differ from it only by their dissipation (2 % 1-sigma in the
//! simulator), a thin tube; Gaussians fitted to the tube get the drift's change across it
//! (the Shupe and gradient terms are linear in the rates) only as well as the tube's few
//! runs at its edge allow, while a linear term extends it. Measured over six campaigns per
//! ambient (docs/record/northfinder.md): chosen this way the targets are met in 17 of 18 cells
//! (-40 degC 5 of 6), against 14 of 18 without linear terms (-40 degC 2 of 6) and 16 of 18
//! with them forced on every model.
//!
//! The clock input: every run of the campaign is a cold start from a soak at one ambient,
//! so the time since power-on is a state of the warm-up, and with T it tells a run that
//! heats faster (its dissipation, 2 % 1-sigma in the simulator) from a later row of an
//! average one. Without it the model follows only half of the dissipation's effect on the
//! drift in the first two minutes, which was the whole excess of seek 1 at -40 degC
//! (`examples/seek_input_noise`, docs/record/northfinder.md). It enters as fog-core's
//! `PowerOnDecay`, exp(-t / tau), with tau the campaign's own warm-up time: when its mean
//! temperature rise reaches 1 - 1/e of the rise over the run (`warmup_time_constant_s`).
//!
//! dT/dt is read as `train` reads it: in the clock the runs' warm-up follows
//! (`train::warmup_clock`; the slope where they follow exponential modes, as every
//! simulated campaign does, the diffusion law's clock where a coil heated from one face
//! warms as 1 - exp(-sqrt(t / tau))), unless the plan asks for the slope.
//!
//! With the clock, the input step ends with the derivative-free set (`t,rise`: T and the
//! rise since power-on) as the one to beat (`choose_derivative_free`): the estimated
//! derivatives stay only where they win by 2 standard errors run by run. On the independent
//! generator they do in a chamber whose air wanders after power-on, and not where the runs
//! warm along one family of curves (tests/own_model_derivative_free.rs).

use anyhow::{anyhow, Result};
use fog_core::model::format::{FeatureKind, FeatureSpec};
use fog_core::seeking::northfinder::SeekMode;

use super::config::MonteCarloConfig;
use super::schedule::seek_schedule;
use super::summary::noise_floor_deg;
use crate::io::runs::Run;
use crate::pipeline::campaign::{CampaignRun, CampaignSpec, WarmRestarts};
use crate::pipeline::campaign_steps::{simulate_checked, train_with_config};
use crate::sim::GyroParams;
use crate::train::cold_start::{envelope_for, rises_by_time, significant_rise_c};
use crate::train::seek_refit::{refit_for_seeks, SeekRefit, SeekSchedule};
use crate::train::seek_score::{seek_azimuth_rms_deg, Criterion, SeekGeometry};
use crate::train::warmup_clock::{in_runs_clock, ClockChoice, RateClock};
use crate::train::{
    choose_in_order_with, choose_inputs_default, criterion_for, dataset_from_runs, predict_batch,
    EstimatorChoice, InputChoice, InputSelection, InputSet, TrainConfig, TrainOutcome,
};

/// Runs of the own model's chamber campaign at its ambient (45 min each: 72 h of chamber
/// time; why 96, the module notes).
pub const CAMPAIGN_RUNS: usize = 96;
/// Budget of the learned error (rms over a run's seeks), as a fraction of the seek's
/// white-noise floor. It comes from the product targets, not from the simulator: each
/// seek's mean error must stay within 0.3 of its std (about the floor); the learned error
/// is a different bias in each seek, roughly Gaussian over the seeks with this rms, and
/// the largest of a 45 min run's 12 seek pairs is about 2.4 rms, so the rms may be at most
/// 0.3 / 2.4 = 0.125 floor. (It then adds 0.8 % to the seek std in quadrature.) Checked
/// against the Monte Carlo: the rms of the per-seek mean errors of 300 starts matched the
/// estimate (0.0029 vs 0.0028 deg, 6 runs at 20 degC).
pub const LEARNED_SHARE_OF_FLOOR: f64 = 0.125;
/// Disjoint half-splits the learned error is averaged over (`learned_seek_error_deg`).
pub const SPLITS: usize = 3;

/// What the own model is trained for: the seek's site, ambient, dwell and gyro noise.
#[derive(Clone, Debug)]
pub struct OwnModelPlan {
    pub ambient_c: f64,
    pub latitude_deg: f64,
    pub dwell_s: f64,
    pub seed: u64,
    pub criterion: Criterion,
    /// The input sets the recipe's input step chooses from (`auto`: `train`'s defaults;
    /// a fixed set is taken as given, the clock and linear terms still by the recipe).
    pub inputs: InputChoice,
    /// The Monte Carlo whose seeks the final model's output layer is refitted to
    /// (`train::seek_refit`), their timing measured with the trained model
    /// (`seek_schedule`); None: the model as trained.
    pub seek_timing: Option<MonteCarloConfig>,
    /// How the model reads dT/dt (`train --warmup-clock`): in the clock its runs choose
    /// (`Auto`, the default) or as the slope.
    pub rate_clock: RateClock,
}

impl OwnModelPlan {
    /// The seeks the model is scored and refitted for: the forward seek of the plan's
    /// dwell and latitude, or the time-symmetric one when the criterion scores those.
    pub fn seek_geometry(&self) -> SeekGeometry {
        let symmetric = matches!(self.criterion, Criterion::Seek(g) if g.symmetric);
        SeekGeometry {
            symmetric,
            ..SeekGeometry::forward(self.dwell_s, self.latitude_deg)
        }
    }
}

/// The trained own model and how its run count was chosen.
pub struct OwnModel {
    pub trained: TrainOutcome,
    pub selection: InputSelection,
    /// The clock its dT/dt is read in, and why (None: the slope, not chosen).
    pub rate_clock: Option<ClockChoice>,
    /// The clock input's time constant, s (None: the runs show no warm-up to clock).
    pub clock_tau_s: Option<f64>,
    /// The model's inputs: the selection's, then the clock input when there is one.
    pub specs: Vec<FeatureSpec>,
    /// Whether the model has linear terms in its RBF inputs (chosen by the held-out score).
    pub linear_inputs: bool,
    /// The held-out scores (the plan's criterion) without and with those linear terms.
    pub linear_scores: [f64; 2],
    pub runs: usize,
    /// Estimated per-seek azimuth bias the model owes to its training set, deg (half-split
    /// rms / 2, at |sin psi| = 1; `learned_seek_error_deg`).
    pub learned_seek_deg: f64,
    /// The budget, deg (`LEARNED_SHARE_OF_FLOOR` x the floor at |sin psi| = 1).
    pub budget_deg: f64,
    /// Whether the estimate is within the budget.
    pub budget_met: bool,
    /// The seek refit of the final model (None: the plan has no seek schedule).
    pub seek_refit: Option<SeekRefit>,
}

impl OwnModel {
    /// One line per step and the decision, for people.
    pub fn summary(&self) -> String {
        let mut s = self
            .rate_clock
            .as_ref()
            .map_or(String::new(), |c| format!("{}\n", c.describe()));
        s += &match self.clock_tau_s {
            Some(tau) => format!(
                "clock input: time since power-on, exp(-t / {tau:.0} s) (the runs' warm-up time)\n"
            ),
            None => "clock input: none (the runs show no warm-up)\n".into(),
        };
        s += &format!(
            "linear terms in the RBF inputs: {} (held-out {:.5} with, {:.5} without)\n",
            if self.linear_inputs { "yes" } else { "no" },
            self.linear_scores[1],
            self.linear_scores[0]
        );
        s += &format!(
            "training runs: {} (the chamber campaign); training-set error (half-split, mean of {SPLITS} splits) {:.4} deg, budget {:.4} deg ({} x the white-noise floor): {}\n",
            self.runs,
            self.learned_seek_deg,
            self.budget_deg,
            LEARNED_SHARE_OF_FLOOR,
            if self.budget_met {
                "met"
            } else {
                "NOT met: a larger campaign would lower it"
            }
        );
        if let Some(r) = &self.seek_refit {
            s += &r.summary();
            s.push('\n');
        }
        s += &crate::train::cold_start::summary(self.trained.model.cold_start.as_ref());
        s.push('\n');
        s
    }
}

/// Simulates the chamber campaign at the plan's ambient (`campaign_runs` power-ons, cold
/// starts unless `warm_restarts`; `CAMPAIGN_RUNS` is the default) and trains the own model
/// on it, with the training-set error checked against the budget (see the module notes).
pub fn train_own_model(
    params: &GyroParams,
    plan: &OwnModelPlan,
    campaign_runs: usize,
    warm_restarts: Option<WarmRestarts>,
) -> Result<OwnModel> {
    let campaign = simulate_checked(
        params,
        &CampaignSpec {
            ambients_c: vec![plan.ambient_c],
            runs_per_ambient: campaign_runs,
            latitude_deg: plan.latitude_deg,
            warm_restarts,
            ..CampaignSpec::paper(plan.seed)
        },
    )?;
    let runs: Vec<Run> = campaign.into_iter().map(|c: CampaignRun| c.run).collect();
    own_model_from_runs(params, runs, plan)
}

/// The own model's recipe on any campaign of cold starts (one ambient for `north-seek`,
/// every ambient for `reproduce`'s qualification model): `train`'s input choice, the clock
/// of the runs' warm-up when they have one, linear terms in the RBF inputs when the
/// held-out score wants them, and the half-split training-set error against its budget
/// (`LEARNED_SHARE_OF_FLOOR` of the seek's white-noise floor for `params`' gyro).
pub fn own_model_from_runs(
    params: &GyroParams,
    runs: Vec<Run>,
    plan: &OwnModelPlan,
) -> Result<OwnModel> {
    let floor_deg = noise_floor_deg(
        params.noise.arw_dpsh,
        SeekMode::TwoPosition,
        plan.latitude_deg,
        90.0,
        plan.dwell_s,
    );
    let budget_deg = LEARNED_SHARE_OF_FLOOR * floor_deg;
    // `train`'s defaults, with the plan's criterion choosing the d2T/dt2 estimator as well
    // as the shape. (Scoring each set with the clock beside it was tried and not kept:
    // docs/record/northfinder.md, "The one global model over training campaigns".)
    // dT/dt in the clock the runs' warm-up follows (`train::warmup_clock`), as `train` reads it
    let (cfg, rate_clock) = in_runs_clock(&runs, &train_config(plan, false));
    let candidates = plan.inputs.candidates();
    let (mut selection, _) = choose_inputs_default(&runs, &candidates, &cfg)
        .map_err(|e| anyhow!("choosing the own model's inputs: {e}"))?;
    let clock_tau_s = warmup_time_constant_s(&runs)?;
    if let (InputChoice::Auto, Some(tau_s)) = (plan.inputs, clock_tau_s) {
        let choice = choose_derivative_free(&runs, selection.chosen, tau_s, &cfg)?;
        selection.chosen = choice.chosen;
        selection.derivative_free = Some(choice.scores);
    }
    let specs: Vec<FeatureSpec> = selection
        .chosen
        .specs_reading_rate(cfg.rate_input)
        .into_iter()
        .chain(clock_tau_s.map(clock_spec))
        .collect();
    let mut shape = choose_linear_terms(&runs, &specs, plan)?;
    let learned_seek_deg = learned_seek_error_deg(&runs, &specs, plan, shape.linear_inputs)?;
    let seek_refit = match &plan.seek_timing {
        Some(seeks) => {
            // At the plan's ambient, inside the model's trained range (elsewhere its
            // windows are out of range and the finder takes none).
            let at_ambient = MonteCarloConfig {
                ambient_c: plan.ambient_c,
                ..seeks.clone()
            };
            let schedule = seek_schedule(params, &at_ambient, Some(&shape.trained.model))?;
            let r = refit_to_seeks(&runs, &specs, &shape.trained.model, plan, &schedule)?;
            shape.trained.model = r.model.clone();
            Some(r)
        }
        None => None,
    };
    // The device's check that a power-on is one of these cold starts (`train::cold_start`).
    shape.trained.model.cold_start = envelope_for(&runs, &specs)?;
    Ok(OwnModel {
        seek_refit,
        trained: shape.trained,
        selection,
        rate_clock,
        clock_tau_s,
        specs,
        linear_inputs: shape.linear_inputs,
        linear_scores: shape.scores,
        runs: runs.len(),
        learned_seek_deg,
        budget_deg,
        budget_met: learned_seek_deg <= budget_deg,
    })
}

/// What `choose_derivative_free` chose, and every set's held-out figure.
pub struct DerivativeFreeChoice {
    pub chosen: InputSet,
    pub scores: EstimatorChoice,
}

/// On soaked cold starts with a warm-up clock, the derivative-free set (T and the rise
/// since power-on, `InputSet::TempRise`) against `chosen` (the input step's set), both
/// with the clock, scored by `cfg`'s criterion on the rows both can use (dT/dt read as
/// `cfg.rate_input`); `chosen`
/// replaces the derivative-free set only when it is significantly better run by run
/// (`SIGNIFICANT_GAIN_SE`).
///
/// Why the derivative-free set is the one to beat: for a soaked unit the first reading is
/// its ambient and the clock its time since power-on, so T, the rise and the clock name
/// the warm-up's state as dT/dt and d2T/dt2 do wherever the runs warm along one family of
/// curves; the derivatives are then estimates of the same state from the first few noisy
/// rows, whose noise the 10 s rows hardly weigh and the first seek turns into azimuth
/// scatter (the global model's seek 1 at -40 degC: 1.21x the floor with d2T/dt2, 1.11x
/// without; docs/record/northfinder.md, "Without dT/dt"). Where the runs' warm-ups differ in
/// ways the rise and clock do not name (time constants spread run to run), the
/// derivatives carry information and win by more than the runs' scatter.
pub fn choose_derivative_free(
    runs: &[Run],
    chosen: InputSet,
    tau_s: f64,
    cfg: &TrainConfig,
) -> Result<DerivativeFreeChoice> {
    let criterion = criterion_for(cfg);
    let order = [InputSet::TempRise, chosen];
    let (chosen, tried) = choose_in_order_with(runs, &order, &[clock_spec(tau_s)], cfg, criterion)
        .map_err(|e| anyhow!("derivative-free inputs: {e}"))?;
    Ok(DerivativeFreeChoice {
        chosen,
        scores: EstimatorChoice {
            criterion: criterion.describe().into(),
            scores: tried,
        },
    })
}

/// The final model's output layer refitted to the seeks of `schedule` on its own training
/// runs (`train::seek_refit`; runs grouped by their first temperature reading).
fn refit_to_seeks(
    runs: &[Run],
    specs: &[FeatureSpec],
    model: &fog_core::model::format::RbfModel,
    plan: &OwnModelPlan,
    schedule: &SeekSchedule,
) -> Result<SeekRefit> {
    let ds = dataset_from_runs(runs, specs).map_err(|e| anyhow!("seek refit: {e}"))?;
    let start_c: Vec<f64> = runs
        .iter()
        .map(|r| r.temp_c().first().copied().unwrap_or(f64::NAN))
        .collect();
    refit_for_seeks(model, &ds, &start_c, schedule, plan.seek_geometry())
        .map_err(|e| anyhow!("seek refit: {e}"))
}

/// The model of `choose_linear_terms`: trained with or without linear terms in its RBF
/// inputs, and the held-out scores that chose.
pub struct LinearTermsChoice {
    pub trained: TrainOutcome,
    pub linear_inputs: bool,
    /// The held-out scores (the plan's criterion) without and with the linear terms.
    pub scores: [f64; 2],
}

/// Linear terms in the RBF inputs under the Gaussians, or not: a shape choice, made as the
/// trainer makes its width and degree, by the lower held-out score of the plan's criterion
/// over whole runs; a tie keeps the paper's pure RBF.
pub fn choose_linear_terms(
    runs: &[Run],
    specs: &[FeatureSpec],
    plan: &OwnModelPlan,
) -> Result<LinearTermsChoice> {
    let refs: Vec<&Run> = runs.iter().collect();
    let plain = train_with_config(&refs, specs, &train_config(plan, false))?;
    let linear = train_with_config(&refs, specs, &train_config(plan, true))?;
    let score = |t: &TrainOutcome| t.report.cross_validation.best.score_for(plan.criterion);
    let scores = [score(&plain), score(&linear)];
    let linear_inputs = scores[1] < scores[0];
    Ok(LinearTermsChoice {
        trained: if linear_inputs { linear } else { plain },
        linear_inputs,
        scores,
    })
}

/// The own model's trainer configuration: `train`'s defaults with the plan's criterion and
/// clock, and linear terms in the RBF inputs when `linear_inputs`.
pub fn train_config(plan: &OwnModelPlan, linear_inputs: bool) -> TrainConfig {
    TrainConfig {
        gyro_id: "sim".into(),
        criterion: plan.criterion,
        rate_clock: plan.rate_clock,
        linear_on_rbf_inputs: linear_inputs,
        ..TrainConfig::default()
    }
}

/// The clock input of a campaign whose warm-up time is `tau_s` (`warmup_time_constant_s`):
/// fog-core's `PowerOnDecay`, exp(-t / tau).
pub fn clock_spec(tau_s: f64) -> FeatureSpec {
    FeatureSpec {
        kind: FeatureKind::PowerOnDecay,
        tau_s: tau_s as f32,
    }
}

/// The campaign's warm-up time, s since power-on: when the mean over the runs of the
/// temperature rise since each run's first row reaches 1 - 1/e of its rise at the last
/// row common to them. None when that rise is not `train::cold_start::WARMUP_SIGNIFICANCE_SE`
/// standard errors of the runs' own rises above zero (no warm-up to clock: a unit that
/// does not heat, or runs that start warm).
pub fn warmup_time_constant_s(runs: &[Run]) -> Result<Option<f64>> {
    let rises = rises_by_time(runs)?;
    let Some(total) = significant_rise_c(&rises) else {
        return Ok(None);
    };
    let level = (1.0 - (-1.0f64).exp()) * total;
    let mean = |r: &[f64]| r.iter().sum::<f64>() / r.len() as f64;
    Ok(rises
        .iter()
        .find(|(_, r)| mean(r) >= level)
        .map(|&(t, _)| t))
}

/// Half-split estimate of the seek error a model on all `runs` owes to its training set:
/// for each of `SPLITS` disjoint splits (alternate runs, first and second half, runs
/// 0, 3, 4, 7, 8... against 1, 2, 5, 6...), models on the two halves, their prediction difference along every run scored
/// as seeks (`seek_azimuth_rms_deg`), halved; the mean over the splits.
pub fn learned_seek_error_deg(
    runs: &[Run],
    specs: &[FeatureSpec],
    plan: &OwnModelPlan,
    linear_inputs: bool,
) -> Result<f64> {
    let cfg = train_config(plan, linear_inputs);
    let n = runs.len();
    let side = |split: usize, i: usize| match split {
        0 => i % 2,
        1 => usize::from(2 * i >= n),
        _ => (i + i / 2) % 2,
    };
    let ds = dataset_from_runs(runs, specs).map_err(|e| anyhow!("half-split: {e}"))?;
    let mut sum = 0.0;
    for split in 0..SPLITS {
        let half = |h: usize| -> Vec<&Run> {
            runs.iter()
                .enumerate()
                .filter(|(i, _)| side(split, *i) == h)
                .map(|(_, r)| r)
                .collect()
        };
        let a = train_with_config(&half(0), specs, &cfg)?;
        let b = train_with_config(&half(1), specs, &cfg)?;
        let pa = predict_batch(&a.model, ds.rows()).map_err(|e| anyhow!("half-split: {e}"))?;
        let pb = predict_batch(&b.model, ds.rows()).map_err(|e| anyhow!("half-split: {e}"))?;
        let diff: Vec<f64> = pa.iter().zip(&pb).map(|(x, y)| x - y).collect();
        sum += 0.5 * seek_azimuth_rms_deg(&diff, &ds.groups, &ds.t_s, plan.seek_geometry());
    }
    Ok(sum / SPLITS as f64)
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
            inputs: InputChoice::Auto,
            seek_timing: None,
            rate_clock: RateClock::Auto,
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
            learned_seek_error_deg(
                &runs(&with_noise_scaled(&paper, k), 6),
                &specs,
                &plan(),
                false,
            )
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
        let null = learned_seek_error_deg(&runs(&same, 6), &specs, &plan(), false).unwrap();
        assert!(
            null < 0.05 * base,
            "identical runs {null:.6} deg vs {base:.5} deg"
        );
    }

    #[test]
    fn a_fixed_input_set_reaches_the_model_with_the_clock_beside_it() {
        let fixed = OwnModelPlan {
            inputs: InputChoice::Fixed(crate::train::InputSet::TempRise),
            ..plan()
        };
        let own = own_model_from_runs(
            &GyroParams::paper_default(),
            runs(&GyroParams::paper_default(), 6),
            &fixed,
        )
        .unwrap();
        let kinds: Vec<FeatureKind> = own.trained.model.inputs.iter().map(|s| s.kind).collect();
        assert_eq!(
            kinds,
            [
                FeatureKind::TempC,
                FeatureKind::TempRiseC,
                FeatureKind::PowerOnDecay
            ]
        );
        assert!(
            own.selection.derivative_free.is_none(),
            "a given set is not re-chosen"
        );
        // The default ends with the derivative-free step on these soaked cold starts: the
        // rise against the input step's set, both with the clock, and the model carries
        // the set it chose.
        let auto = own_model_from_runs(
            &GyroParams::paper_default(),
            runs(&GyroParams::paper_default(), 6),
            &plan(),
        )
        .unwrap();
        let step = auto
            .selection
            .derivative_free
            .as_ref()
            .expect("a warm-up clock");
        let tried: Vec<InputSet> = step.scores.iter().map(|s| s.set).collect();
        assert_eq!(tried.len(), 2);
        assert_eq!(tried[0], InputSet::TempRise);
        assert!(tried.contains(&auto.selection.chosen));
        let expected: Vec<FeatureKind> = auto
            .selection
            .chosen
            .specs()
            .iter()
            .map(|s| s.kind)
            .chain([FeatureKind::PowerOnDecay])
            .collect();
        let kinds: Vec<FeatureKind> = auto.trained.model.inputs.iter().map(|s| s.kind).collect();
        assert_eq!(kinds, expected);
    }

    #[test]
    fn the_warmup_time_follows_the_heat_capacity_and_is_none_without_heat() {
        let paper = GyroParams::paper_default();
        let tau = |p: &GyroParams| warmup_time_constant_s(&runs(p, 4)).unwrap();
        let base = tau(&paper).expect("a cold start warms up");
        assert!((60.0..2700.0).contains(&base), "warm-up time {base} s");
        // Twin with twice the heat capacities (another physical law of the same form):
        // a slower warm-up.
        let mut slow = paper.clone();
        slow.thermal.coil_heat_capacity_j_per_k *= 2.0;
        slow.thermal.housing_heat_capacity_j_per_k *= 2.0;
        let slower = tau(&slow).expect("it still warms up");
        assert!(slower > 1.3 * base, "{slower} s vs {base} s");
        // Null twin: no dissipation, no TEC: the thermometer reads the soak and its noise.
        let mut cold = paper.clone();
        cold.thermal.power_w = 0.0;
        cold.thermal.tec_w_per_k = 0.0;
        assert_eq!(tau(&cold), None);
    }
}
