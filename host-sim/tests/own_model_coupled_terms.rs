//! The own model's third shape, linear terms whose coefficients change with temperature
//! (`LinearShape::LinearByT`: fog-core's `linear_by_t`), tried where it is meant to help:
//! one global model over soaked cold starts at ambients from -40 to +60 degC, on the
//! independent generator (tests/common/soaked.rs, nothing shared with the simulator), and
//! judged by the seeks of a fresh campaign of the same unit at the coldest ambient (the
//! range's end, where Gaussians of one width fit worst). Three laws: a Shupe coefficient
//! linear in T (the planted one), its twin whose coefficient steps across 0 degC (a law no
//! linear change with T follows), and the null twin (a constant Shupe coefficient).
//!
//! `cargo test --release -p fog-sim --test own_model_coupled_terms -- --nocapture` prints
//! every figure.

#[allow(dead_code)] // the test files share the generator, each uses some of its laws
#[path = "common/soaked.rs"]
mod soaked;

use fog_core::model::format::{FeatureSpec, RbfModel};
use fog_sim::io::runs::Run;
use fog_sim::pipeline::own_model::{
    choose_linear_terms, clock_spec, warmup_time_constant_s, LinearShape, OwnModelPlan,
};
use fog_sim::train::seek_score::{seek_azimuth_rms_deg, Criterion, SeekGeometry};
use fog_sim::train::{dataset_from_runs, predict_batch, InputSet};
use soaked::{soaked_campaign_over, SoakedLaw, Tube};

const LATITUDE_DEG: f64 = 40.0;
const DWELL_S: f64 = 110.0;
/// The campaign: 6 ambients across the qualification range, 8 cold starts at each.
const AMBIENTS_C: [f64; 6] = [-40.0, -20.0, 0.0, 20.0, 40.0, 60.0];
const RUNS_PER_AMBIENT: usize = 8;
/// The simulator's Shupe coefficient changes by 0.6 % per degC; the generator's by 0.8 %.
const SHUPE_CHANGE_PER_C: f64 = -0.008;

fn plan() -> OwnModelPlan {
    OwnModelPlan {
        ambient_c: 20.0,
        latitude_deg: LATITUDE_DEG,
        dwell_s: DWELL_S,
        seed: 1,
        criterion: Criterion::Seek(SeekGeometry {
            dwell_s: DWELL_S,
            latitude_deg: LATITUDE_DEG,
        }),
    }
}

/// The own model's inputs on these runs: T, dT/dt and the clock of their warm-up.
fn specs(runs: &[Run]) -> Vec<FeatureSpec> {
    let mut specs = InputSet::TempRate.specs();
    let tau_s = warmup_time_constant_s(runs)
        .unwrap()
        .expect("soaked cold starts have a warm-up");
    specs.push(clock_spec(tau_s));
    specs
}

/// Seek azimuth rms, deg, of `model`'s residuals on `runs`.
fn seek_rms_deg(model: &RbfModel, runs: &[Run], specs: &[FeatureSpec]) -> f64 {
    let ds = dataset_from_runs(runs, specs).unwrap();
    let pred = predict_batch(model, ds.rows()).unwrap();
    let res: Vec<f64> = ds
        .targets_dph
        .iter()
        .zip(&pred)
        .map(|(y, p)| y - p)
        .collect();
    seek_azimuth_rms_deg(&res, &ds.groups, &ds.t_s, DWELL_S, LATITUDE_DEG)
}

/// The choice on a campaign of `law`, and every shape's seek rms on a fresh campaign's
/// runs at the coldest ambient.
struct Outcome {
    chosen: LinearShape,
    heldout: [f64; 3],
    fresh_coldest: [f64; 3],
}

fn outcome(law: SoakedLaw, seed: u64) -> Outcome {
    let campaign = |s| soaked_campaign_over(law, Tube::Thin, s, &AMBIENTS_C, RUNS_PER_AMBIENT);
    let runs = campaign(seed);
    let coldest: Vec<Run> = campaign(seed + 1000)
        .into_iter()
        .take(RUNS_PER_AMBIENT)
        .collect();
    let specs = specs(&runs);
    let choice = choose_linear_terms(&runs, &specs, &plan()).unwrap();
    let fresh: Vec<f64> = choice
        .trained
        .iter()
        .map(|t| seek_rms_deg(&t.model, &coldest, &specs))
        .collect();
    let o = Outcome {
        chosen: choice.shape,
        heldout: choice.scores,
        fresh_coldest: [fresh[0], fresh[1], fresh[2]],
    };
    println!(
        "{law:?} seed {seed}: chosen {:?}; held-out seek pure / linear / T-coupled {:.5} / {:.5} / {:.5} deg; fresh campaign at {} degC {:.5} / {:.5} / {:.5} deg",
        o.chosen,
        o.heldout[0],
        o.heldout[1],
        o.heldout[2],
        AMBIENTS_C[0],
        o.fresh_coldest[0],
        o.fresh_coldest[1],
        o.fresh_coldest[2],
    );
    o
}

/// A Shupe coefficient linear in T: the coefficients that change with T are chosen, and on
/// a fresh campaign's coldest runs they beat the constant linear terms.
#[test]
fn a_shupe_coefficient_linear_in_t_gets_coefficients_that_change_with_t() {
    let o = outcome(SoakedLaw::LaggedShupeLinearInT(SHUPE_CHANGE_PER_C), 1);
    assert_eq!(o.chosen, LinearShape::LinearByT);
    assert!(
        o.fresh_coldest[2] < o.fresh_coldest[1],
        "T-coupled {:.5} deg against linear {:.5} deg at the coldest ambient",
        o.fresh_coldest[2],
        o.fresh_coldest[1]
    );
}

/// The twin (a step in T) and the null twin (a constant coefficient): whichever shape is
/// chosen does as well on the fresh campaign's coldest runs as the best of the three
/// (within 3 %).
#[test]
fn on_other_laws_the_chosen_shape_does_as_well_as_the_best() {
    for law in [SoakedLaw::LaggedShupeStepInT(0.4), SoakedLaw::LaggedNull] {
        let o = outcome(law, 1);
        let chosen = o.fresh_coldest[o.chosen as usize];
        let best = o
            .fresh_coldest
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        assert!(
            chosen <= 1.03 * best,
            "{law:?}: chosen {:?} gives {chosen:.5} deg at the coldest ambient, the best {best:.5}",
            o.chosen
        );
    }
}
