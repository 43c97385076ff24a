//! `fogsim diagnose` end to end from fog-runs files: the JSON carries at least the issue's
//! schema, plots are written, and the cross-check with the OLS trainer is included.

#[allow(dead_code)]
use crate::common::planted;
use fog_sim::cmd::diagnose::{run, Args};
use planted::{campaign, Effect, Shape};

#[test]
fn json_has_the_issue_schema_and_plots_are_written() {
    let dir = std::env::temp_dir().join(format!("fog-diag-cli-{}", std::process::id()));
    let runs_dir = dir.join("runs");
    std::fs::create_dir_all(&runs_dir).unwrap();
    let (runs, _) = campaign(
        Effect::ColumnValue,
        3,
        Shape {
            runs: 8,
            minutes: 30.0,
            sigmas: 1.0,
        },
    );
    for r in &runs {
        fog_sim::io::runs::write_run(runs_dir.join(r.name()), r).unwrap();
    }
    let json = dir.join("d.json");
    let plots = dir.join("plots");
    run(Args {
        runs: vec![runs_dir.clone()],
        outputs: fog_sim::cmd::ReportOutputs {
            json: Some(json.clone()),
            plots: Some(plots.clone()),
        },
    })
    .unwrap();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let base = &v["base"];
    let chosen = base["heldout_rms_dph"].as_f64().unwrap();
    assert!(chosen > 0.0);
    assert!(base["name"].is_string() && base["uses_rate"].is_boolean());
    let tried = base["tried"].as_array().unwrap();
    assert_eq!(tried.len(), 8, "constant, poly 1-3 with/without dT/dt, RBF");
    let same = tried.iter().find(|b| b["name"] == base["name"]).unwrap();
    assert_eq!(same["heldout_rms_dph"].as_f64().unwrap(), chosen);
    base_rule_holds(base, tried);
    let c0 = &v["candidates"][0];
    for key in [
        "column",
        "transform",
        "tau_s",
        "heldout_rms_dph",
        "gain_pct",
        "p_value",
        "significant",
    ] {
        assert!(c0.get(key).is_some(), "candidate lacks {key}: {c0}");
    }
    assert!(v.get("named_cause").is_some());
    for key in ["inputs", "heldout_rms_dph", "gain_pct"] {
        assert!(v["extended"].get(key).is_some(), "extended lacks {key}");
    }
    for key in ["before_rms_dph", "after_rms_dph"] {
        assert!(
            v["simulation"][key].as_f64().is_some(),
            "simulation lacks {key}"
        );
    }
    let u = &v["uncertainty"];
    let sim = u["simulator"].as_array().expect("uncertainty.simulator");
    for e in sim {
        for key in ["name", "unit", "value", "plus_minus", "ci95"] {
            assert!(e.get(key).is_some(), "estimate lacks {key}: {e}");
        }
    }
    let ratios: Vec<&str> = u["ratios"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| q["name"].as_str().unwrap())
        .collect();
    assert_eq!(ratios.len(), 4, "{ratios:?}");
    assert!(u["base"].is_array() && u["extension"].is_array());
    let raw = &v["raw_rows"];
    assert!(raw["rows"].as_u64().unwrap() > 0, "raw_rows: {raw}");
    assert!(!raw["allan"].as_array().unwrap().is_empty());
    for key in ["arw_dpsh", "bias_instability_dph", "quantisation", "steps"] {
        assert!(raw.get(key).is_some(), "raw_rows lacks {key}");
    }
    assert!(
        v["ols_trainer_check"]["baseline"]["heldout_std_dph"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    assert!(plots.join("residual_vs_time.svg").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// The parsimony rule's bookkeeping (issue 18 item 6): the lowest is the reference; the
/// chosen base is the lowest or the first simpler base weighed within one standard error.
fn base_rule_holds(base: &serde_json::Value, tried: &[serde_json::Value]) {
    let rule = &base["rule"];
    let rms_of = |name: &serde_json::Value| {
        let b = tried.iter().find(|b| b["name"] == *name).unwrap();
        b["heldout_rms_dph"].as_f64().unwrap()
    };
    let lowest = rms_of(&rule["lowest"]);
    assert!(tried
        .iter()
        .all(|b| b["heldout_rms_dph"].as_f64().unwrap() >= lowest));
    let weighed = rule["weighed"].as_array().unwrap();
    let within: Vec<&serde_json::Value> = weighed
        .iter()
        .filter(|w| w["within_one_se"] == true)
        .collect();
    if base["name"] == rule["lowest"] {
        assert!(within.is_empty(), "{rule}");
    } else {
        assert_eq!(within.len(), 1, "{rule}");
        assert_eq!(within[0]["base"], base["name"]);
        assert_eq!(weighed.last(), Some(within[0]));
    }
    assert!(rule["reason"].as_str().is_some_and(|r| !r.is_empty()));
}
