//! Fleets (`fogsim campaign --units`, `pipeline::fleet`): same seed, same bytes; a unit is
//! the same gyro whatever the fleet's size; each unit's own Shupe coefficient reaches its
//! data (a judge that knows neither generator reads it back, on the project's fleet and
//! on an independent one, its twin with one unit outside the type and its null twin);
//! `none` gives the type itself; bad options get one line and no output.

use crate::app_support;
use crate::common::fleet_independent::{fleet, FleetLaw, UNIT_HALF_WIDTH};
use crate::common::fleet_judge::{correlation, robust_z, shupe_by_unit, std_dev};

use fog_sim::io::runs::{read_runs, Run};
use fog_sim::pipeline::campaign::{simulate_campaign, CampaignSpec};
use fog_sim::pipeline::fleet::{fleet_runs, unit_index_of, unit_seed, FleetType};
use fog_sim::sim::TypeSpread;
use std::path::{Path, PathBuf};

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fog_sim_fleet_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn fogsim(args: &[&str]) -> std::process::Output {
    app_support::fogsim(&std::env::temp_dir(), args)
}

/// `fogsim campaign` of `units` units into `out` (1 run at 20 degC, 2 min, raw 10 Hz).
fn fleet_campaign(out: &Path, units: &str) -> std::process::Output {
    fogsim(&[
        "campaign",
        "--out",
        out.to_str().unwrap(),
        "--ambient-c",
        "20",
        "--runs",
        "1",
        "--duration-min",
        "2",
        "--raw-rate-hz",
        "10",
        "--seed",
        "4",
        "--units",
        units,
        "--type-seed",
        "7",
    ])
}

#[test]
fn same_seed_same_bytes_and_unit_3_is_the_same_gyro_in_a_fleet_of_3_or_5() {
    let (three, five) = (scratch("three"), scratch("five"));
    for (dir, n) in [(&three, "3"), (&five, "5")] {
        let r = fleet_campaign(dir, n);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    let names =
        |d: &Path| -> Vec<String> { read_runs(&[d]).unwrap().iter().map(Run::name).collect() };
    assert_eq!(
        names(&three),
        [
            "u001_amb00_p020c_run1.csv",
            "u002_amb00_p020c_run1.csv",
            "u003_amb00_p020c_run1.csv"
        ]
    );
    assert_eq!(names(&five).len(), 5);
    let bytes = |d: &Path, u: usize| {
        std::fs::read(d.join(format!("u{u:03}_amb00_p020c_run1.csv"))).unwrap()
    };
    for u in 1..=3 {
        assert_eq!(
            bytes(&three, u),
            bytes(&five, u),
            "unit {u} differs between the fleets"
        );
    }
    assert_ne!(bytes(&five, 4), bytes(&five, 5));
    for (i, run) in read_runs(&[&five]).unwrap().iter().enumerate() {
        assert_eq!(unit_index_of(run), Some(i));
        assert_eq!(run.meta_value("type_id"), Some("paper_default"));
        assert_eq!(run.meta_value("type_seed"), Some("7"));
        assert_eq!(run.meta_value("unit_spread"), Some("default"));
    }
    std::fs::remove_dir_all(three).unwrap();
    std::fs::remove_dir_all(five).unwrap();
}

/// A 30 min cold start at 20 degC per unit, raw 10 Hz.
fn plan() -> CampaignSpec {
    CampaignSpec {
        ambients_c: vec![20.0],
        runs_per_ambient: 1,
        minutes: 30.0,
        raw_rate_hz: 10.0,
        ..CampaignSpec::paper(21)
    }
}

/// The project's fleet of `units` units of `spread`, and each unit's true Shupe coefficient.
fn project_fleet(spread: TypeSpread, units: usize) -> (Vec<Run>, Vec<f64>) {
    let fleet = FleetType::paper(spread, "test", 3);
    let runs = (0..units)
        .flat_map(|u| fleet_runs(&fleet, u, &plan(), None).unwrap())
        .map(|c| c.run)
        .collect();
    let truth = (0..units)
        .map(|u| fleet.unit(u).unwrap().drift.shupe_dph_per_cps)
        .collect();
    (runs, truth)
}

fn ln_estimates(runs: &[Run]) -> Vec<f64> {
    shupe_by_unit(runs).iter().map(|(_, k)| k.ln()).collect()
}

#[test]
fn each_simulated_unit_carries_its_own_shupe_coefficient_and_none_is_the_type() {
    let spread = TypeSpread::none()
        .with("drift.shupe_dph_per_cps", 0.10)
        .unwrap();
    let (runs, truth) = project_fleet(spread, 12);
    let ln_truth: Vec<f64> = truth.iter().map(|k| k.ln()).collect();
    let ln_est = ln_estimates(&runs);
    let r = correlation(&ln_est, &ln_truth);
    let (sd_est, sd_truth) = (std_dev(&ln_est), std_dev(&ln_truth));
    println!("project fleet: r = {r:.4}, sd ln k: data {sd_est:.4}, drawn {sd_truth:.4}");
    assert!(r > 0.95, "r = {r}");
    assert!(
        (sd_est / sd_truth - 1.0).abs() < 0.15,
        "{sd_est} vs {sd_truth}"
    );
    // the null twin: no spread, units differ only in their runs (noise, turn-on, soak)
    let (none_runs, none_truth) = project_fleet(TypeSpread::none(), 12);
    let sd_none = std_dev(&ln_estimates(&none_runs));
    println!("project fleet without spread: sd ln k {sd_none:.4}");
    assert!(none_truth.iter().all(|&k| k == 14.0));
    // the judge's own scatter (one 30 min run per unit) is 0.029 here
    assert!(sd_none < 0.5 * sd_truth, "{sd_none} vs {sd_truth}");
    // ... and each unit is the type run from the unit's seed
    let fleet = FleetType::paper(TypeSpread::none(), "none", 3);
    let u2 = fleet_runs(&fleet, 2, &plan(), None).unwrap();
    let single = CampaignSpec {
        seed: unit_seed(plan().seed, 2),
        ..plan()
    };
    let typ = simulate_campaign(&fleet.params, &single).unwrap();
    assert_eq!(u2[0].run.data, typ[0].run.data);
}

#[test]
fn the_judge_reads_the_independent_fleets_spread_its_odd_unit_and_its_null_twin() {
    let make = |law| fleet(law, 16, &[-10.0, 30.0], 2, 40, 5);
    let typ = make(FleetLaw::Type);
    let ln_truth: Vec<f64> = typ.units.iter().map(|u| u.shupe_dph_per_cps.ln()).collect();
    let ln_est = ln_estimates(&typ.runs);
    let r = correlation(&ln_est, &ln_truth);
    let (sd_est, sd_truth) = (std_dev(&ln_est), std_dev(&ln_truth));
    println!(
        "independent fleet: r = {r:.4}, sd ln k: data {sd_est:.4}, drawn {sd_truth:.4} (law {:.4})",
        UNIT_HALF_WIDTH / 3f64.sqrt()
    );
    assert!(r > 0.95, "r = {r}");
    assert!(
        (sd_est / sd_truth - 1.0).abs() < 0.15,
        "{sd_est} vs {sd_truth}"
    );
    let z_typ = robust_z(
        &shupe_by_unit(&typ.runs)
            .iter()
            .map(|u| u.1)
            .collect::<Vec<_>>(),
    );
    let odd = make(FleetLaw::OddUnit);
    let z_odd = robust_z(
        &shupe_by_unit(&odd.runs)
            .iter()
            .map(|u| u.1)
            .collect::<Vec<_>>(),
    );
    let worst = |z: &[f64]| z.iter().copied().fold(0.0, f64::max);
    println!(
        "robust z: type's largest {:.2}, odd unit {:.2}",
        worst(&z_typ),
        z_odd[15]
    );
    assert!(worst(&z_typ) < 4.0, "{z_typ:?}");
    assert!(z_odd[15] > 10.0 && worst(&z_odd[..15]) < 4.0, "{z_odd:?}");
    let null = make(FleetLaw::Identical);
    let sd_null = std_dev(&ln_estimates(&null.runs));
    println!("null twin: sd ln k {sd_null:.4}");
    assert!(sd_null < 0.25 * sd_truth, "{sd_null} vs {sd_truth}");
}

#[test]
fn bad_fleet_options_fail_with_one_line_and_no_output() {
    let out = scratch("bad");
    let dir = scratch("bad_inputs");
    std::fs::create_dir_all(&dir).unwrap();
    let file = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let unknown = file("unknown.txt", "drift.shupe_dph_per_cps: 10%\nshupe: 10%\n");
    let absurd = file("absurd.txt", "drift.shupe_dph_per_cps: 300%\n");
    let missing = dir.join("missing.txt").to_str().unwrap().to_string();
    let o = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["--units", "0"], "--units 0: must be within 1..=999"),
        (vec!["--units", "1000"], "--units 1000"),
        (
            vec!["--units", "2", "--unit-spread", &unknown],
            "unknown.txt: line 2: unknown parameter `shupe`",
        ),
        (
            vec!["--units", "2", "--unit-spread", &absurd],
            "absurd.txt: line 1: `drift.shupe_dph_per_cps` spread 300%",
        ),
        (
            vec!["--units", "2", "--unit-spread", &missing],
            "missing.txt: cannot read",
        ),
        (
            vec!["--unit-spread", "none"],
            "--unit-spread none: needs --units",
        ),
        (vec!["--type-seed", "3"], "--type-seed 3: needs --units"),
        (vec!["--units", "30"], "x 30 units"),
    ] {
        let mut all = vec![
            "campaign",
            "--out",
            o,
            "--ambient-c",
            "-40,-30,-20,-10,0,10,20,30,40,50,60",
        ];
        all.extend(&args);
        let r = fogsim(&all);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{args:?} accepted");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} left output behind");
    }
    std::fs::remove_dir_all(dir).unwrap();
}
