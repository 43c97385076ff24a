//! `fogsim train --inputs auto` on the independent generator (tests/common/independent.rs:
//! its own critically damped thermal law under a cycling chamber, 1 Hz rows, quantised
//! thermometer), nothing shared with the project's simulator: with a d2T/dt2 drift term
//! planted (3 noise sigmas) the choice must be t,rate,accel with a clearly lower held-out
//! rms; on the null twin (the same cycling campaign, nothing planted) d2T/dt2 must not
//! look materially better. The 1 Hz rows go through the command as a user gives them.

mod app_support;
#[path = "common/independent.rs"]
#[allow(dead_code)] // the heading variants are used by diagnose_between
mod independent;

use app_support::{fogsim, scratch_dir, stderr};
use fog_sim::io::runs::write_run;
use independent::{campaign, Hidden};

/// (chosen, held-out rms of t,rate, of t,rate,accel) of `fogsim train --inputs auto`.
fn choose(hidden: Hidden, seed: u64, tag: &str) -> (String, f64, f64) {
    let dir = scratch_dir(&format!("train-indep-{tag}"));
    let (runs, _) = campaign(hidden, seed);
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
    let sel = &r["input_selection"];
    let score = |i: usize| sel["scores"][i]["score"].as_f64().unwrap();
    eprintln!(
        "independent {tag} (seed {seed}): chosen {}, held-out rms t,rate {:.5}, t,rate,accel {:.5} deg/h",
        sel["chosen"],
        score(0),
        score(1)
    );
    let _ = std::fs::remove_dir_all(&dir);
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
