//! `north-seek --type-units N --unit-runs K`: the seeking gyro's model as a production line
//! would make it, from a type learnt on N other units of its design and K of its own cold
//! starts (`train::type_unit`), or with N = 0 from its K runs alone (the type-free recipe:
//! the own-model recipe on those runs).
//!
//! The fleet is the simulator's (`pipeline::fleet`, the paper's gyro as the type, the
//! default unit spread, drawn from the Monte Carlo's seed): the seeking unit is U1 and the
//! type's units are U2..U(N+1), so the seeking unit is never among them and the same U1 is
//! calibrated whatever N. The type's units each run `type_unit_runs` cold starts spread
//! over the type ambients in turn; the unit's K runs are spread over the unit ambients in turn (run i
//! at ambient i mod n). The Monte Carlo then seeks with the unit's own parameters.

use anyhow::{anyhow, Result};
use fog_core::model::format::RbfModel;

use super::own_model::{own_model_from_runs, train_config, OwnModelPlan};
use super::schedule::seek_schedule;
use super::MonteCarloConfig;
use crate::io::runs::Run;
use crate::pipeline::campaign::{CampaignSpec, PAPER_MINUTES};
use crate::pipeline::fleet::{fleet_runs, unit_id, FleetType};
use crate::sim::{GyroParams, TypeSpread};
use crate::train::cold_start::envelope_for;
use crate::train::type_unit::calibrate::DEFAULT_SEEK_PERIOD_S;
use crate::train::type_unit::terms::Fit;
use crate::train::type_unit::type_model::learn_type;
use crate::train::type_unit::{
    calibrate_unit, choose_own, ordinary_model, resolve_shape, train_shared, ShapeScoring,
    SharedModel, TypeModel, TypeShape, UnitCalibration, UnitPlan,
};

/// Ambients of the type's and the unit's chamber runs by default, degC.
pub const RECIPE_AMBIENTS_C: [f64; 3] = [-40.0, 20.0, 60.0];
/// Cold starts of each type unit by default: 6 a unit at each of the three ambients. With
/// 18, a type of 10 units met 120 of 120 simulated cells (fleets 81-120 x -40/20/+60 degC,
/// 6 unit runs, Thue-Morse, 1,000 starts; fleet 111 at -40 degC at 16,000) against 113 of
/// 118 with 6, where two runs a unit and ambient chose the law's clocks by chance; on the
/// independent fleet 5 of 15 against 4, no unit refused against one
/// (docs/record/fleet.md). A type is learnt once per design.
pub const DEFAULT_TYPE_UNIT_RUNS: usize = 18;
/// Most type units (every unit's runs are held in memory).
pub const MAX_TYPE_UNITS: usize = 60;
/// Most unit runs.
pub const MAX_UNIT_RUNS: usize = 96;
/// Index of the seeking unit in the fleet (U1).
pub const SEEKING_UNIT: usize = 0;

/// The recipe asked for.
#[derive(Clone, Debug)]
pub struct UnitRecipe {
    /// Units the type is learnt from (0: no type, the unit's runs alone).
    pub type_units: usize,
    /// Cold starts of each type unit, spread over `type_ambients_c` in turn.
    pub type_unit_runs: usize,
    pub type_ambients_c: Vec<f64>,
    pub unit_runs: usize,
    pub unit_ambients_c: Vec<f64>,
    /// The fleet's seed (units and runs).
    pub seed: u64,
    /// The form of the type's shared model.
    pub type_shape: TypeShape,
    /// How the type reads its units and the unit is calibrated.
    pub unit_fit: Fit,
    /// How the fleet's units differ, and its label (`default`, `none`, `file NAME`).
    pub unit_spread: (TypeSpread, String),
    /// The unit step's terms and prior weight when fixed (`--unit-terms`,
    /// `--unit-prior-weight`; None: chosen by leave-one-run-out).
    pub unit_terms: Option<usize>,
    pub unit_prior_weight: Option<f64>,
}

/// The seeking unit's model and where it came from.
pub struct RecipeModel {
    pub model: RbfModel,
    /// The seeking unit's parameters (what the Monte Carlo seeks with).
    pub unit_params: GyroParams,
    pub type_model: Option<TypeModel>,
    pub calibration: Option<UnitCalibration>,
    pub type_runs: usize,
    /// Chamber hours of the type (all its units) and of the unit, soaks not counted.
    pub type_chamber_h: f64,
    pub unit_chamber_h: f64,
    pub summary: String,
}

impl UnitRecipe {
    pub fn check(&self) -> Result<()> {
        if self.type_units > MAX_TYPE_UNITS || self.type_units == 1 || self.type_units == 2 {
            return Err(anyhow!(
                "--type-units {}: must be 0 (no type) or 3..={MAX_TYPE_UNITS} (a type's spread needs 3 units)",
                self.type_units
            ));
        }
        if !(2..=MAX_UNIT_RUNS).contains(&self.unit_runs) {
            return Err(anyhow!(
                "--unit-runs {}: must be within 2..={MAX_UNIT_RUNS} (one run is held out)",
                self.unit_runs
            ));
        }
        // Without a type the unit's runs are trained as any model is: grouped validation
        // over whole runs, `TrainConfig`'s folds.
        let own_folds = crate::train::TrainConfig::default().folds;
        if self.type_units == 0 {
            for (flag, given) in [
                ("--unit-terms", self.unit_terms.is_some()),
                ("--unit-prior-weight", self.unit_prior_weight.is_some()),
            ] {
                if given {
                    return Err(anyhow!(
                        "{flag}: --type-units 0 calibrates no unit against a type"
                    ));
                }
            }
        }
        if let Some(w) = self.unit_prior_weight {
            crate::train::type_unit::calibrate::check_prior_weight(w)?;
        }
        if self.type_units == 0 && self.unit_runs < own_folds {
            return Err(anyhow!(
                "--unit-runs {}: --type-units 0 trains the unit on its own runs alone, and grouped validation needs at least {own_folds}",
                self.unit_runs
            ));
        }
        if !(2..=48).contains(&self.type_unit_runs) {
            return Err(anyhow!(
                "--type-unit-runs {}: must be within 2..=48 (a type unit's error is measured by leaving one run out)",
                self.type_unit_runs
            ));
        }
        for (flag, list) in [
            ("--unit-ambients-c", &self.unit_ambients_c),
            ("--type-ambients-c", &self.type_ambients_c),
        ] {
            if list.is_empty()
                || list
                    .iter()
                    .any(|a| !(a.is_finite() && (-60.0..=100.0).contains(a)))
            {
                return Err(anyhow!(
                    "{flag}: one or more ambients within -60..=100 degC"
                ));
            }
        }
        Ok(())
    }
}

/// The runs of unit `u`: `count` cold starts spread over `ambients` in turn.
fn unit_runs(
    fleet: &FleetType,
    u: usize,
    ambients: &[f64],
    count: usize,
    seed: u64,
) -> Result<Vec<Run>> {
    let n = ambients.len();
    let plan = CampaignSpec {
        ambients_c: ambients.to_vec(),
        runs_per_ambient: count.div_ceil(n),
        seed,
        ..CampaignSpec::paper(seed)
    };
    let runs = fleet_runs(fleet, u, &plan, None).map_err(|e| anyhow!("{e}"))?;
    // file order is ambient-major: run r at ambient a is index a * per + r
    let per = plan.runs_per_ambient;
    Ok((0..count)
        .map(|i| runs[(i % n) * per + i / n].run.clone())
        .collect())
}

/// The recipe's fleet: the paper's gyro as the type, the recipe's unit spread, drawn from
/// the recipe's seed.
fn recipe_fleet(recipe: &UnitRecipe) -> FleetType {
    let (spread, label) = &recipe.unit_spread;
    FleetType::paper(spread.clone(), label, recipe.seed)
}

/// The default unit spread (docs/explain/simulator.md, "Fleets") with its label.
pub fn default_unit_spread() -> (TypeSpread, String) {
    (TypeSpread::default_spread(), "default".into())
}

/// The seeking unit's parameters (what the Monte Carlo seeks with).
pub fn seeking_unit_params(recipe: &UnitRecipe) -> Result<GyroParams> {
    recipe_fleet(recipe)
        .unit(SEEKING_UNIT)
        .map_err(|e| anyhow!("{e}"))
}

/// Chamber hours of `runs` cold starts (soaks not counted).
pub fn chamber_h(runs: usize) -> f64 {
    runs as f64 * PAPER_MINUTES / 60.0
}

/// A type learnt from the recipe's type units (U2..U(N+1)), and how it was learnt.
pub struct RecipeType {
    pub type_model: TypeModel,
    pub type_runs: usize,
    pub summary: String,
}

/// Learns the recipe's type (`recipe.type_units` >= 3; see the module notes); `plan` is
/// the own-model recipe's plan.
pub fn learn_recipe_type(recipe: &UnitRecipe, plan: &OwnModelPlan) -> Result<RecipeType> {
    recipe.check()?;
    if recipe.type_units == 0 {
        return Err(anyhow!(
            "--type-units 0: the type-free recipe learns no type"
        ));
    }
    let fleet = recipe_fleet(recipe);
    let per_unit = recipe.type_unit_runs;
    let mut pooled = Vec::with_capacity(recipe.type_units * per_unit);
    for u in 1..=recipe.type_units {
        pooled.extend(unit_runs(
            &fleet,
            u,
            &recipe.type_ambients_c,
            per_unit,
            recipe.seed,
        )?);
    }
    let type_runs = pooled.len();
    // The shared model without the seek refit: its output layer is the unit terms' to fit
    // (a refit to pooled seeks trades the 10 s fit the backfitting needs for seek bias
    // averaged over units, and chose the grid's largest weight). The network is `train`'s,
    // as `train --type-out` makes it.
    let cfg = train_config(plan, false);
    let candidates = plan.inputs.candidates();
    // the shapes scored by what the unit step makes of units left out, its seeks those
    // of the type's own parameters (the seeking unit is not the type's to know)
    let scoring = ShapeScoring {
        cfg: &cfg,
        candidates: &candidates,
        fit: recipe.unit_fit,
        plan: unit_step_plan(recipe, &fleet.params, plan)?,
    };
    let (shape, choice) = resolve_shape(recipe.type_shape, &pooled, &scoring)?;
    // every round's shared model, to report the one the type kept
    let mut rounds: Vec<SharedModel> = Vec::new();
    let ty = learn_type(&pooled, None, recipe.unit_fit, &mut |runs| {
        let shared = train_shared(shape, &runs, &cfg, &candidates)?;
        let model = shared.model().clone();
        rounds.push(shared);
        Ok(model)
    })?;
    drop(pooled);
    let shared_text = rounds
        .into_iter()
        .find(|r| r.model() == &ty.model)
        .ok_or_else(|| anyhow!("the type's shared model is none of the rounds'"))?
        .describe();
    let shared_text = format!(
        "{}{shared_text}",
        choice.map_or(String::new(), |c| c.summary())
    );
    let summary = format!(
        "type: {} units x {per_unit} runs ({:.1} chamber h); {}{}",
        recipe.type_units,
        chamber_h(type_runs),
        shared_text,
        ty.summary(),
    );
    Ok(RecipeType {
        type_model: ty,
        type_runs,
        summary,
    })
}

/// Makes the seeking unit's model by `recipe` (see the module notes); `plan` is the
/// own-model recipe's plan (the seek's ambient, dwell, criterion and seek timing).
pub fn recipe_model(recipe: &UnitRecipe, plan: &OwnModelPlan) -> Result<RecipeModel> {
    recipe.check()?;
    match recipe.type_units {
        0 => type_free_model(recipe, plan),
        _ => unit_model(recipe, learn_recipe_type(recipe, plan)?, plan),
    }
}

/// The recipe checked, its fleet, the seeking unit's parameters and its own runs.
fn seeking_unit_runs(recipe: &UnitRecipe) -> Result<(FleetType, GyroParams, Vec<Run>)> {
    recipe.check()?;
    let fleet = recipe_fleet(recipe);
    let unit_params = seeking_unit_params(recipe)?;
    let own = unit_runs(
        &fleet,
        SEEKING_UNIT,
        &recipe.unit_ambients_c,
        recipe.unit_runs,
        recipe.seed,
    )?;
    Ok((fleet, unit_params, own))
}

/// Time from one of `plan`'s seeks to the next, s: measured on the seek schedule of its
/// seek timing (the finder's own state machine on the unit), else the calibration's
/// default (`DEFAULT_SEEK_PERIOD_S`).
fn seek_period_s(unit_params: &GyroParams, plan: &OwnModelPlan) -> Result<f64> {
    Ok(match &plan.seek_timing {
        Some(seeks) => {
            let at_ambient = MonteCarloConfig {
                ambient_c: plan.ambient_c,
                ..seeks.clone()
            };
            seek_schedule(unit_params, &at_ambient, None)?.period_s
        }
        None => DEFAULT_SEEK_PERIOD_S,
    })
}

/// The unit step's plan: `recipe`'s terms and prior weight, the seeks of `plan` on a gyro
/// of `params` (their period and sequence).
fn unit_step_plan(
    recipe: &UnitRecipe,
    params: &GyroParams,
    plan: &OwnModelPlan,
) -> Result<UnitPlan> {
    Ok(UnitPlan {
        terms: recipe.unit_terms,
        prior_weight: recipe.unit_prior_weight,
        seek_period_s: seek_period_s(params, plan)?,
        symmetric_seeks: match &plan.seek_timing {
            Some(seeks) => seeks.mode.is_symmetric(),
            None => plan.criterion.seek_geometry().symmetric,
        },
    })
}

/// The type-free recipe: the seeking unit's own runs alone, by the own-model recipe.
pub fn type_free_model(recipe: &UnitRecipe, plan: &OwnModelPlan) -> Result<RecipeModel> {
    let (fleet, unit_params, own) = seeking_unit_runs(recipe)?;
    let trained = own_model_from_runs(&fleet.params, own, plan)?;
    let summary = format!(
        "type-free recipe: unit {} trained on its own {} runs ({:.1} chamber h)\n{}",
        unit_id(SEEKING_UNIT),
        recipe.unit_runs,
        chamber_h(recipe.unit_runs),
        trained.summary()
    );
    Ok(RecipeModel {
        model: trained.trained.model,
        unit_params,
        type_model: None,
        calibration: None,
        type_runs: 0,
        type_chamber_h: 0.0,
        unit_chamber_h: chamber_h(recipe.unit_runs),
        summary,
    })
}

/// The seeking unit calibrated from its own runs with `learnt` (the recipe's type, just
/// learnt or kept from an earlier run with the same recipe) as the prior, its held-out
/// score read as `plan`'s seeks see the drift (their period and sequence).
pub fn unit_model(
    recipe: &UnitRecipe,
    learnt: RecipeType,
    plan: &OwnModelPlan,
) -> Result<RecipeModel> {
    let (_, unit_params, own) = seeking_unit_runs(recipe)?;
    let unit_plan = unit_step_plan(recipe, &unit_params, plan)?;
    let ty = learnt.type_model;
    let cal = calibrate_unit(&ty, &own, &unit_id(SEEKING_UNIT), &unit_plan)?;
    let mut summary = format!("{}{}", learnt.summary, cal.summary());
    // the unit's own model beside it, trained as `train` trains it (`train --type`)
    let mut model = cal.model.clone();
    if recipe.unit_terms.is_none() && recipe.unit_prior_weight.is_none() {
        let cfg = train_config(plan, false);
        let candidates = plan.inputs.candidates();
        let mut train = |runs: &[Run]| ordinary_model(runs, &candidates, &cfg);
        let own_choice = choose_own(&cal, &own, &unit_plan, cfg.folds.max(2), &mut train)?;
        summary += &own_choice.summary();
        if own_choice.taken {
            model = train(&own)?;
            model.cold_start = envelope_for(&own, &model.inputs)?;
        }
    }
    Ok(RecipeModel {
        model,
        unit_params,
        type_model: Some(ty),
        calibration: Some(cal),
        type_runs: learnt.type_runs,
        type_chamber_h: chamber_h(learnt.type_runs),
        unit_chamber_h: chamber_h(recipe.unit_runs),
        summary,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recipe(unit_spread: (TypeSpread, String)) -> UnitRecipe {
        UnitRecipe {
            type_units: 3,
            type_unit_runs: 2,
            type_ambients_c: RECIPE_AMBIENTS_C.to_vec(),
            unit_runs: 2,
            unit_ambients_c: RECIPE_AMBIENTS_C.to_vec(),
            seed: 4,
            type_shape: TypeShape::Law,
            unit_fit: Fit::WithinRuns,
            unit_spread,
            unit_terms: None,
            unit_prior_weight: None,
        }
    }

    #[test]
    fn the_recipes_unit_spread_draws_the_seeking_unit() {
        let paper = GyroParams::paper_default();
        // no spread: the seeking unit is the type; the default spread: it is not
        let none = seeking_unit_params(&recipe((TypeSpread::none(), "none".into()))).unwrap();
        assert_eq!(none.drift.shupe_dph_per_cps, paper.drift.shupe_dph_per_cps);
        assert_eq!(none.thermal.power_w, paper.thermal.power_w);
        let drawn = seeking_unit_params(&recipe(default_unit_spread())).unwrap();
        assert_ne!(drawn.drift.shupe_dph_per_cps, paper.drift.shupe_dph_per_cps);
        // one parameter's spread moves that parameter only
        let shupe = TypeSpread::none()
            .with("drift.shupe_dph_per_cps", 0.1)
            .unwrap();
        let one = seeking_unit_params(&recipe((shupe, "file shupe".into()))).unwrap();
        assert_ne!(one.drift.shupe_dph_per_cps, paper.drift.shupe_dph_per_cps);
        assert_eq!(one.thermal.power_w, paper.thermal.power_w);
    }
}
