//! The warm-up clock of a type's dT/dt input (`train::warmup_clock`), chosen from the runs'
//! own temperatures, on data the choice was not written on: the simulator's fleet (two
//! thermal modes behind a lagging sensor: the slope stays, so every simulated figure
//! stands), the independent fleet (a coil heated by diffusion: its clock, at about its
//! type's time constant), the same independent units as 1 Hz logger rows, and the
//! independent null twin (units identical: the same law, the same clock). The own-model
//! recipe (`north-seek`'s type-free recipe and default model) reads its rate as it chooses.

use crate::common::fleet_independent::{cold_start_rows, fleet, FleetLaw};
use fog_core::model::format::{FeatureKind, FeatureSpec};
use fog_sim::io::runs::Run;
use fog_sim::pipeline::campaign::CampaignSpec;
use fog_sim::pipeline::fleet::{simulate_fleet, FleetType};
use fog_sim::pipeline::north_seek::own_model::{own_model_from_runs, OwnModelPlan};
use fog_sim::sim::unit_spread::TypeSpread;
use fog_sim::sim::GyroParams;
use fog_sim::train::warmup_clock::{choose_warmup_clock, RateClock};
use fog_sim::train::{InputChoice, InputSet};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const AMBIENTS_C: [f64; 3] = [-40.0, 20.0, 60.0];

/// The simulator's fleet 81 (the paper gyro, the default unit spread): `units` units'
/// cold starts, `runs_per_ambient` at each of `ambients_c`.
fn simulated(units: usize, ambients_c: &[f64], runs_per_ambient: usize) -> Vec<Run> {
    let sim_type = FleetType::paper(TypeSpread::default_spread(), "default", 81);
    let plan = CampaignSpec {
        ambients_c: ambients_c.to_vec(),
        runs_per_ambient,
        ..CampaignSpec::paper(81)
    };
    simulate_fleet(&sim_type, units, &plan, None)
        .unwrap()
        .into_iter()
        .map(|c| c.run)
        .collect()
}

#[test]
fn the_simulators_fleet_keeps_the_slope_and_the_independent_one_takes_its_diffusion_clock() {
    let sim = simulated(3, &AMBIENTS_C, 1);
    let c = choose_warmup_clock(&sim);
    println!("simulator: {}", c.describe());
    assert_eq!(c.rate_input, FeatureSpec::plain(FeatureKind::TempRateCps));
    assert!(c.exponential.1 < c.diffusion.1, "{}", c.describe());

    for law in [FleetLaw::Type, FleetLaw::Identical] {
        let f = fleet(law, 3, &AMBIENTS_C, 1, 45, 1);
        let c = choose_warmup_clock(&f.runs);
        println!("independent {law:?}: {}", c.describe());
        assert_eq!(c.rate_input.kind, FeatureKind::TempRateDiffusionCps);
        let tau = c.rate_input.tau_s as f64;
        assert!((340.0..470.0).contains(&tau), "{law:?}: {}", c.describe());
    }

    // 1 Hz rows of the same law: the same choice (each row its own one-second window)
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let truth = fleet(FleetLaw::Type, 1, &AMBIENTS_C, 1, 1, 1).units[0];
    let rows: Vec<Run> = AMBIENTS_C
        .iter()
        .map(|&a| cold_start_rows(&truth, a, 45, &mut rng, 1))
        .collect();
    let c = choose_warmup_clock(&rows);
    println!("independent, 1 Hz rows: {}", c.describe());
    assert_eq!(c.rate_input.kind, FeatureKind::TempRateDiffusionCps);
}

/// The own-model recipe (`north-seek --type-units 0`, its default model, `reproduce`'s)
/// reads dT/dt as `train` does: an independent unit's 6 cold starts at one ambient (a coil
/// heated by diffusion) in the diffusion clock, said in its summary; the same runs with
/// `--warmup-clock slope` as the slope; the simulator's runs (exponential modes) as the
/// slope, the clock tried and not taken. The set is fixed to `t,rate` so the rate input is
/// in the model whatever the derivative-free step would choose.
#[test]
fn the_own_model_recipe_reads_dt_dt_in_the_clock_its_runs_choose() {
    let plan = |rate_clock| OwnModelPlan {
        inputs: InputChoice::Fixed(InputSet::TempRate),
        rate_clock,
        ..crate::common::seek_judge::plan(20.0)
    };
    let rate_kind = |runs: Vec<Run>, clock| {
        let own = own_model_from_runs(&GyroParams::paper_default(), runs, &plan(clock)).unwrap();
        let kinds: Vec<FeatureKind> = own.trained.model.inputs.iter().map(|s| s.kind).collect();
        (kinds[1], own.rate_clock.is_some(), own.summary())
    };
    let indep = || fleet(FleetLaw::Type, 1, &[20.0], 6, 45, 3).runs;
    let (kind, chosen, summary) = rate_kind(indep(), RateClock::Auto);
    assert_eq!(kind, FeatureKind::TempRateDiffusionCps, "{summary}");
    assert!(
        chosen && summary.contains("dT/dt read as the diffusion clock ("),
        "{summary}"
    );
    let (kind, chosen, summary) = rate_kind(indep(), RateClock::Slope);
    assert_eq!(kind, FeatureKind::TempRateCps, "{summary}");
    assert!(!chosen && !summary.contains("dT/dt read as"), "{summary}");

    let (kind, chosen, summary) = rate_kind(simulated(1, &[20.0], 6), RateClock::Auto);
    assert_eq!(kind, FeatureKind::TempRateCps, "{summary}");
    assert!(
        chosen && summary.contains("dT/dt read as the slope against time"),
        "{summary}"
    );
}
