//! `diagnose` on the project's own simulated campaigns (`fogsim campaign`, issue 18 item
//! 7): it must name nothing, within or between runs, and every measured / simulator ratio
//! must be within 2 stated sigma of 1, because the calibrated model class contains the
//! simulator's own physics (its two thermal modes seen through the thermometer's lag,
//! Shupe with its cold gain, the gradient-rate term). Several seeds and two ambient sets;
//! default seeds 7 and 8 at a small size (6 and 12 runs, 1 Hz raw rows), more via
//! `DIAG_SEEDS=7,8,9,...`. No allowance beyond the stated 2 sigma (the jackknife over runs
//! on the t scale, `diagnose/uncertainty/jackknife.rs`; its coverage over 20 seeds per
//! ambient set is in docs/record/diagnose.md, "honest sigmas": about 1 ratio in 20 falls outside,
//! so extra seeds will show an occasional FAIL line by design). And with every random part
//! switched off (`sim::quiet`), the ratios must be within 2 % of 1: a bias of the
//! estimators that the noisy campaigns' 2 sigma would hide.

use crate::app_support;

use std::path::Path;

use crate::common::seeds;

fn fogsim(args: &[&str]) {
    app_support::fogsim_ok(args);
}

/// `fogsim diagnose CAMP --json JSON`, and the report it wrote.
fn diagnose_json(camp: &Path, json: &Path) -> serde_json::Value {
    fogsim(&[
        "diagnose",
        camp.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

/// One campaign and its verdict line; true when it passes.
fn case(dir: &Path, seed: u64, ambient: &str, runs: &str) -> (bool, String) {
    let camp = dir.join(format!("c{seed}_{}", ambient.replace(',', "_")));
    let json = dir.join(format!("c{seed}_{}.json", ambient.replace(',', "_")));
    let seed_s = seed.to_string();
    fogsim(&[
        "campaign",
        "--out",
        camp.to_str().unwrap(),
        "--runs",
        runs,
        "--seed",
        &seed_s,
        &format!("--ambient-c={ambient}"),
        "--raw-rate-hz",
        "1",
    ]);
    let v = diagnose_json(&camp, &json);
    let within = v["named_cause"].clone();
    let between = v["between_run"]["named"].clone();
    let mut ok = within.is_null() && between.is_null();
    let mut line = format!(
        "seed {seed} ambient {ambient} x{runs}: named within {within}, between {between}; levels {} {}; ratios",
        v["base"]["levels"]["base"], v["base"]["levels"]["law"]
    );
    for r in v["uncertainty"]["ratios"].as_array().unwrap() {
        let name = r["name"].as_str().unwrap();
        let value = r["ratio"]["value"].as_f64().unwrap();
        let sigma = r["ratio"]["plus_minus"].as_f64().unwrap();
        let allowed = 2.0 * sigma;
        let fine = (value - 1.0).abs() <= allowed;
        ok &= fine;
        line += &format!(
            " {name} {value:.3} +/- {sigma:.3}{}",
            if fine { "" } else { " (!)" }
        );
    }
    (ok, line)
}

#[test]
fn the_simulators_own_campaigns_name_nothing_and_recover_its_physics() {
    let dir = std::env::temp_dir().join(format!("fog-diag-self-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let seeds = std::env::var("DIAG_SEEDS")
        .ok()
        .map(|_| seeds::seeds())
        .unwrap_or_else(|| vec![7, 8]);
    let mut lines = Vec::new();
    for seed in seeds {
        lines.push(case(&dir, seed, "-20,20,50", "2"));
        lines.push(case(&dir, seed, "-40,-20,0,20,40,60", "2"));
    }
    let _ = std::fs::remove_dir_all(&dir);
    for (ok, l) in &lines {
        println!("{} {l}", if *ok { "ok  " } else { "FAIL" });
    }
    assert!(lines.iter().all(|(ok, _)| *ok), "see the FAIL lines above");
}

/// With every random part of the simulator switched off (`sim::quiet`), nothing is left
/// for the estimators' noise to hide: every measured / simulator ratio of the physics
/// must come out within 2 % of 1 (over seeds 1-30 at -10 / 25 / 55 degC, 3 runs each,
/// they read 0.994-1.009 for the d2T/dt2 coefficient, docs/record/diagnose.md). This
/// guards a bias of the estimators that the noisy campaigns above cannot see below
/// their 2 sigma (a d2T/dt2 ratio of 0.9 would pass there).
#[test]
fn a_noise_free_campaign_gives_the_simulators_physics_to_two_percent() {
    use fog_sim::pipeline::campaign::{simulate_campaign, write_campaign, CampaignSpec};
    use fog_sim::sim::{GyroParams, RandomPart};
    let dir = std::env::temp_dir().join(format!("fog-diag-quiet-{}", std::process::id()));
    let camp = dir.join("quiet");
    let json = dir.join("quiet.json");
    let quiet = RandomPart::ALL
        .iter()
        .fold(GyroParams::paper_default(), |p, &r| p.without(r));
    let mut spec = CampaignSpec::paper(9);
    spec.ambients_c = vec![-10.0, 25.0, 55.0];
    spec.runs_per_ambient = 3;
    write_campaign(&camp, &simulate_campaign(&quiet, &spec).unwrap()).unwrap();
    let v = diagnose_json(&camp, &json);
    let _ = std::fs::remove_dir_all(&dir);
    let ratios: Vec<(String, f64)> = v["uncertainty"]["ratios"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let name = r["name"].as_str().unwrap().to_string();
            (name, r["ratio"]["value"].as_f64().unwrap())
        })
        .collect();
    let lines: Vec<String> = ratios.iter().map(|(n, v)| format!("{n} {v:.4}")).collect();
    println!("{}", lines.join("; "));
    // the ARW ratio is the row noise over the simulator's ARW, which is switched off here
    let physics: Vec<f64> = ratios
        .iter()
        .filter(|(n, _)| !n.contains("ARW"))
        .map(|&(_, v)| v)
        .collect();
    assert!(physics.len() >= 3, "{lines:?}");
    for value in physics {
        assert!((value - 1.0).abs() <= 0.02, "{lines:?}");
    }
}
