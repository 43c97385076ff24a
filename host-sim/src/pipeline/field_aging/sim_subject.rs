//! The project's simulator as the aging measurement's gyro under test: the delivered gyro
//! is `GyroParams::paper_default`, the laws are `laws::AgingLaw`'s, and the chamber model is
//! `north-seek`'s own default model (at several ambients: its inputs and run count, on the
//! runs of every ambient).

use anyhow::Result;

use super::{AgingLaw, AgingPlan, AgingSubject, Chamber};
use crate::pipeline::campaign::CampaignSpec;
use crate::pipeline::campaign_steps::{simulate_checked, train_with_config};
use crate::pipeline::north_seek::own_model::{train_own_model, OwnModelPlan, CAMPAIGN_RUNS};
use crate::pipeline::north_seek::{run_seeks, Arm, ArmOutcome, MonteCarloConfig};
use crate::sim::GyroParams;
use crate::train::seek_score::Criterion;

/// The project's simulator as the aging subject: `plan.laws` applied to
/// `GyroParams::paper_default`.
pub struct SimAging {
    laws: Vec<AgingLaw>,
    delivered: GyroParams,
    aged: Vec<GyroParams>,
}

impl SimAging {
    /// The delivered gyro and its aged variants, one per law.
    pub fn new(laws: &[AgingLaw]) -> Self {
        let delivered = GyroParams::paper_default();
        Self {
            laws: laws.to_vec(),
            aged: laws.iter().map(|l| l.age(&delivered)).collect(),
            delivered,
        }
    }
}

impl AgingSubject for SimAging {
    fn laws(&self) -> Vec<(String, String)> {
        self.laws
            .iter()
            .map(|l| (l.name().to_string(), l.amounts(&self.delivered)))
            .collect()
    }

    fn chamber(&self, plan: &AgingPlan) -> Result<Chamber> {
        let own_plan = own_model_plan(plan)?;
        let own = train_own_model(&self.delivered, &own_plan, CAMPAIGN_RUNS, None)?;
        if plan.ambients_c.len() == 1 {
            return Ok(Chamber {
                centres: own.trained.report.n_centers,
                runs: own.runs,
                model: own.trained.model,
            });
        }
        let trained = chamber_at_ambients(&self.delivered, plan, &own, &own_plan)?;
        Ok(Chamber {
            centres: trained.report.n_centers,
            runs: own.runs * plan.ambients_c.len(),
            model: trained.model,
        })
    }

    fn power_on(
        &self,
        law: usize,
        cfg: &MonteCarloConfig,
        arm: Arm<'_>,
        seed: u64,
    ) -> Result<ArmOutcome> {
        run_seeks(&self.aged[law], cfg, arm, seed)
    }
}

/// `north-seek`'s own-model plan at the plan's first ambient.
fn own_model_plan(plan: &AgingPlan) -> Result<OwnModelPlan> {
    let seek = MonteCarloConfig {
        latitude_deg: plan.latitude_deg,
        ..MonteCarloConfig::paper(plan.seed)
    };
    let dwell_s = seek.dwell_s as f64;
    Ok(OwnModelPlan {
        ambient_c: plan.ambients_c[0],
        latitude_deg: plan.latitude_deg,
        dwell_s,
        seed: plan.seed,
        criterion: Criterion::parse(
            crate::train::seek_score::DEFAULT_CRITERION_NAME,
            dwell_s,
            plan.latitude_deg,
        )
        .map_err(|e| anyhow::anyhow!("criterion: {e}"))?,
        inputs: crate::train::InputChoice::Auto,
        seek_timing: Some(seek),
        rate_clock: Default::default(),
    })
}

/// The chamber model at several ambients: `own`'s inputs and run count per ambient, on
/// runs of the delivered gyro at every ambient of the plan (the first ambient's runs are
/// the own model's, the same seed).
fn chamber_at_ambients(
    delivered: &GyroParams,
    plan: &AgingPlan,
    own: &crate::pipeline::north_seek::own_model::OwnModel,
    own_plan: &OwnModelPlan,
) -> Result<crate::train::TrainOutcome> {
    let campaign = simulate_checked(
        delivered,
        &CampaignSpec {
            ambients_c: plan.ambients_c.clone(),
            runs_per_ambient: own.runs,
            latitude_deg: plan.latitude_deg,
            ..CampaignSpec::paper(plan.seed)
        },
    )?;
    let runs: Vec<&crate::io::runs::Run> = campaign.iter().map(|c| &c.run).collect();
    train_with_config(
        &runs,
        &own.specs,
        &crate::pipeline::north_seek::own_model::train_config(own_plan, own.linear_inputs),
    )
}
