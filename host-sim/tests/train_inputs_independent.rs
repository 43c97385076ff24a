//! `fogsim train --inputs auto` on independent generators (nothing shared with the
//! project's simulator), the 1 Hz rows going through the command as a user gives them.
//!
//! Whether d2T/dt2 at all (tests/common/independent.rs: its own critically damped thermal
//! law under a cycling chamber, quantised thermometer): with a d2T/dt2 drift term planted
//! (3 noise sigmas) the choice must be t,rate,accel with a clearly lower held-out rms; on
//! the null twin (the same cycling campaign, nothing planted) d2T/dt2 must not look
//! materially better.
//!
//! Which d2T/dt2 estimator (tests/common/soaked.rs: 48 soaked cold starts at one
//! ambient, the own model's layout): on the twin whose thermometer sits on the heated
//! node (slope largest at power-on, a kink the flat prior gets wrong) the seek-scored
//! step must keep the plain d2T/dt2 and score the flat start worse; where the thermometer
//! lags the heat (the series flat at power-on, the flat prior's picture) d2T/dt2 must be
//! chosen and the flat start must cost nothing. Measured there (seeds 1-3): the flat start
//! ties the plain fit (held-out seek 0.00731 / 0.00629 / 0.00606 deg against 0.00719 /
//! 0.00653 / 0.00609), it does not win significantly, so this generator does not support
//! a claim that it must be chosen (docs/record/northfinder.md). On the null twin (lagged, nothing
//! in d2T/dt2) no d2T/dt2 at all.

use crate::app_support;
use crate::common::independent;
#[allow(dead_code)] // the test files share the generator, each uses some of its laws
use crate::common::soaked;

use app_support::{fogsim, scratch_dir, stderr};
use fog_sim::io::runs::{write_run, Run};
use independent::{campaign, Hidden};
use soaked::{soaked_campaign, SoakedLaw};

/// The `input_selection` of `fogsim train`'s JSON report on `runs` (written as 1 Hz files).
fn selection(runs: &[Run], tag: &str) -> serde_json::Value {
    let dir = scratch_dir(&format!("train-indep-{tag}"));
    std::fs::create_dir_all(dir.join("runs")).unwrap();
    for (i, r) in runs.iter().enumerate() {
        write_run(dir.join(format!("runs/run{i:02}.csv")), r).unwrap();
    }
    let o = fogsim(
        &dir,
        &[
            "train", "runs", "--out", "m.bin", "--json", "r.json", "--force",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    r["input_selection"].clone()
}

/// (chosen, held-out rms of t,rate, of t,rate,accel) of `fogsim train --inputs auto`.
fn choose(hidden: Hidden, seed: u64, tag: &str) -> (String, f64, f64) {
    let (runs, _) = campaign(hidden, seed);
    let sel = &selection(&runs, tag);
    let score = |i: usize| sel["scores"][i]["score"].as_f64().unwrap();
    eprintln!(
        "independent {tag} (seed {seed}): chosen {}, held-out rms t,rate {:.5}, t,rate,accel {:.5} deg/h",
        sel["chosen"],
        score(0),
        score(1)
    );
    (
        sel["chosen"].as_str().unwrap().to_owned(),
        score(0),
        score(1),
    )
}

#[test]
fn a_planted_accel_term_is_chosen_on_the_independent_generator() {
    let (chosen, two, three) = choose(Hidden::TempAccel(3.0), 11, "accel");
    assert_eq!(chosen, "t,rate,accel");
    assert!(three < 0.9 * two, "{three} vs {two}");
}

#[test]
fn its_null_twin_gains_nothing_material_from_accel() {
    let (_, two, three) = choose(Hidden::TempAccel(0.0), 11, "null");
    assert!(three > 0.95 * two, "{three} vs {two}");
}

/// `fogsim train`'s input selection on a soaked campaign, with every figure printed.
fn soaked_choice(law: SoakedLaw, seed: u64, tag: &str) -> serde_json::Value {
    let sel = selection(&soaked_campaign(law, seed), tag);
    let figures = |scores: &serde_json::Value| -> String {
        scores
            .as_array()
            .into_iter()
            .flatten()
            .map(|s| {
                let v = s["score"].as_f64().unwrap_or(f64::NAN);
                format!("{} {v:.5}", s["set"].as_str().unwrap_or("?"))
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    eprintln!(
        "soaked {law:?} (seed {seed}): chosen {}; inputs by 10 s rms: {}; estimator by seek: {}",
        sel["chosen"],
        figures(&sel["scores"]),
        figures(&sel["estimator"]["scores"])
    );
    sel
}

/// The held-out seek score of the plain and of the flat-start d2T/dt2 (estimator step).
fn estimator_scores(sel: &serde_json::Value) -> (f64, f64) {
    let score = |i: usize| sel["estimator"]["scores"][i]["score"].as_f64().unwrap();
    (score(0), score(1))
}

/// The third input chosen on top of T and dT/dt. Step 2 also weighs the rise since
/// power-on as a reading of the third state; on these soaked starts (one warm-up shape per
/// run) it wins by the seek score, so the tests below judge the d2T/dt2 estimators by their
/// own scores and only require that some third input is chosen.
fn has_third_input(sel: &serde_json::Value) -> bool {
    let chosen = sel["chosen"].as_str().unwrap();
    ["t,rate,accel", "t,rate,accel_flat", "t,rate,rise"].contains(&chosen)
}

#[test]
fn a_lagged_soaked_thermometer_gets_a_third_input_and_the_flat_start_costs_nothing() {
    let sel = soaked_choice(SoakedLaw::LaggedGradient(3.0), 1, "soaked-lagged");
    let (plain, flat) = estimator_scores(&sel);
    assert!(has_third_input(&sel), "{}", sel["chosen"]);
    assert!(flat < 1.05 * plain, "flat {flat} vs plain {plain}");
}

#[test]
fn a_thermometer_on_the_heated_node_never_gets_the_flat_start() {
    let sel = soaked_choice(SoakedLaw::UnlaggedTwoMode(3.0), 1, "soaked-unlagged");
    let (plain, flat) = estimator_scores(&sel);
    assert!(has_third_input(&sel), "{}", sel["chosen"]);
    assert_ne!(sel["chosen"], "t,rate,accel_flat");
    assert!(flat > 1.05 * plain, "flat {flat} vs plain {plain}");
}

#[test]
fn the_soaked_null_twin_gets_no_d2t_dt2() {
    let sel = soaked_choice(SoakedLaw::LaggedNull, 1, "soaked-null");
    assert_eq!(sel["chosen"], "t,rate");
}
