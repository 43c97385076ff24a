//! The own model's choice of linear terms in its RBF inputs
//! (`pipeline::own_model::choose_linear_terms`), tried on an independent generator
//! (tests/common/soaked.rs: 48 soaked cold starts at one ambient, nothing shared with the
//! simulator) and judged by what it is for: the seeks of 48 more power-ons of the same
//! unit. Three laws: the drift linear in T and dT/dt (a temperature coefficient and a
//! Shupe term: the runs' warm-ups form a tube the linear terms extend exactly), its twin
//! with a bump in T (nothing linear), and the null twin (the turn-on offset alone).
//!
//! `cargo test --release -p fog-sim --test own_model_linear_terms -- --nocapture` prints
//! every figure.

use crate::common::seek_judge;
#[allow(dead_code)] // the test files share the generator, each uses some of its laws
use crate::common::soaked;

use fog_sim::pipeline::north_seek::own_model::choose_linear_terms;
use seek_judge::{plan, seek_rms_deg};
use soaked::{clocked_specs, soaked_campaign_over, SoakedLaw, Tube, AMBIENT_C, RUNS};

/// The choice on a campaign of `law`, and both shapes' seek rms on a fresh campaign.
struct Outcome {
    linear_chosen: bool,
    heldout: [f64; 2],
    fresh: [f64; 2],
}

fn outcome(law: SoakedLaw, tube: Tube, seed: u64) -> Outcome {
    // One unit (its coefficients and lag are drawn per campaign): the first RUNS power-ons
    // train, the next RUNS are the fresh campaign.
    let mut runs = soaked_campaign_over(law, tube, seed, &[AMBIENT_C], 2 * RUNS);
    let fresh = runs.split_off(RUNS);
    let specs = clocked_specs(&runs);
    let plan = plan(AMBIENT_C);
    let choice = choose_linear_terms(&runs, &specs, &plan).unwrap();
    let other = fog_sim::pipeline::campaign_steps::train_with_config(
        &runs.iter().collect::<Vec<_>>(),
        &specs,
        &fog_sim::pipeline::north_seek::own_model::train_config(&plan, !choice.linear_inputs),
    )
    .unwrap();
    let (pure, linear) = if choice.linear_inputs {
        (&other.model, &choice.trained.model)
    } else {
        (&choice.trained.model, &other.model)
    };
    let o = Outcome {
        linear_chosen: choice.linear_inputs,
        heldout: choice.scores,
        fresh: [
            seek_rms_deg(pure, &fresh, &specs),
            seek_rms_deg(linear, &fresh, &specs),
        ],
    };
    println!(
        "{law:?} {tube:?} seed {seed}: linear terms {}; held-out seek {:.5} pure / {:.5} linear deg; fresh campaign {:.5} / {:.5} deg",
        if o.linear_chosen { "chosen" } else { "not chosen" },
        o.heldout[0],
        o.heldout[1],
        o.fresh[0],
        o.fresh[1]
    );
    o
}

/// The turn-on offset alone: nothing for linear terms to follow, and the pure RBF (the
/// tie's side) is kept. Measured: held-out seek 0.00431 / 0.00432 deg (seed 1), pure /
/// linear; seed 2 (0.00412 / 0.00413) was run too and dropped from the suite: one seed
/// fails on the regression this guards (linear terms taken on a tie), at half the time.
#[test]
fn the_null_twin_keeps_the_pure_rbf() {
    let o = outcome(SoakedLaw::LaggedOffsetOnly, Tube::Thin, 1);
    assert!(
        !o.linear_chosen,
        "linear terms chosen on a drift that follows nothing"
    );
}

/// On the law linear in T and dT/dt and on its twin with a bump in T, the shape chosen by
/// the held-out score does as well on a fresh campaign as the better of the two (within
/// 2 %). Measured (thin tube, seed 1; the same unit's fresh power-ons, seek rms pure /
/// linear): linear law 0.00432 / 0.00429 deg, pure kept; bump 0.00430 / 0.00432 deg, linear
/// chosen. On this generator the two shapes are within 1 % of each other on every law in
/// the thin tube (3 % in the wide one): its
/// warm-ups are smooth enough for the Gaussians alone, unlike the simulator's -40 degC
/// campaign (docs/record/northfinder.md).
#[test]
fn the_chosen_shape_does_as_well_on_a_fresh_campaign() {
    for law in [SoakedLaw::LaggedNull, SoakedLaw::LaggedTemperatureBump(3.0)] {
        let o = outcome(law, Tube::Thin, 1);
        let chosen = o.fresh[usize::from(o.linear_chosen)];
        let best = o.fresh[0].min(o.fresh[1]);
        assert!(
            chosen <= 1.02 * best,
            "{law:?}: chosen shape {chosen:.5} deg on a fresh campaign, the other {best:.5}"
        );
    }
}
