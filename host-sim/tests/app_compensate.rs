//! `fogsim compensate` end to end: the JSON has the issue's shape, compensation of held-out
//! simulated cold starts lowers the drift std, the largest deviation and the time to spec,
//! and the plots are written.

use crate::app_support;

use app_support::{campaign_and_model, fogsim, scratch_dir, stderr};
use serde_json::Value;

fn stats(v: &Value) -> (f64, f64, Option<f64>) {
    (
        v["std_dph"].as_f64().unwrap(),
        v["max_dev_dph"].as_f64().unwrap(),
        v["time_to_spec_s"].as_f64(),
    )
}

#[test]
fn compensation_improves_held_out_runs_and_json_has_the_issue_shape() {
    let dir = scratch_dir("compensate");
    let runs = campaign_and_model(&dir, 5);
    let out = fogsim(
        &dir,
        &[
            "compensate",
            "runs",
            "--model",
            "model.bin",
            "--json",
            "report.json",
            "--plots",
            "plots",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("overall (pooled)"), "{text}");

    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let rows = json["runs"].as_array().unwrap();
    assert_eq!(rows.len(), runs.len());
    for r in rows {
        assert!(r["file"].as_str().unwrap().ends_with(".csv"));
        assert_eq!(r["ambient_c"].as_f64(), Some(20.0));
        let (sb, mb, tb) = stats(&r["before"]);
        let (sa, ma, ta) = stats(&r["after"]);
        assert!(sa < 0.6 * sb, "std {sb} -> {sa}");
        assert!(ma < mb, "max dev {mb} -> {ma}");
        let (tb, ta) = (
            tb.expect("uncompensated run reaches spec"),
            ta.expect("compensated run reaches spec"),
        );
        assert!(tb > 300.0 && ta < tb, "time to spec {tb} -> {ta}");
    }
    for part in ["before", "after"] {
        let o = &json["overall"][part];
        for key in ["std_dph", "max_dev_dph", "time_to_spec_s"] {
            assert!(o.get(key).is_some(), "overall.{part}.{key} missing");
        }
    }
    assert!(
        json["overall"]["after"]["std_dph"].as_f64()
            < json["overall"]["before"]["std_dph"].as_f64()
    );
    for f in ["startup_before.svg", "startup_after.svg"] {
        let svg = std::fs::read_to_string(dir.join("plots").join(f)).unwrap();
        assert!(svg.contains("<svg") && svg.contains("</svg>"), "{f}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `out_of_range_windows` of `fogsim compensate DIR --model MODEL` (one run).
fn out_of_range_windows(dir: &std::path::Path, runs: &str, model: &str) -> u64 {
    let json = format!("{runs}.json");
    let out = fogsim(
        dir,
        &["compensate", runs, "--model", model, "--json", &json],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(&json)).unwrap()).unwrap();
    v["runs"][0]["out_of_range_windows"].as_u64().unwrap()
}

/// A type model reading the power-on clocks (the law shape of a 3-unit fleet of 30 min
/// cold starts) on a unit left on for an hour: no window leaves the declared range, the
/// clocks' settled value being inside it (it flagged 86 of 360 windows, every one from
/// 46 min on, and every seek then). The twin, a cold start at an ambient the fleet never
/// saw (50 degC), is still flagged throughout.
#[test]
fn a_clock_model_from_half_hour_runs_keeps_a_unit_on_for_an_hour_in_range() {
    let dir = scratch_dir("compensate-clock-range");
    for args in [
        "campaign --out fleet --units 3 --ambient 10,20,30 --runs 1 --minutes 30 --raw-rate-hz 1 --seed 3",
        "train fleet --type-out type.json --out type.fogm",
        "campaign --out long --ambient 20 --runs 1 --minutes 60 --raw-rate-hz 1 --seed 5",
        "campaign --out hot --ambient 50 --runs 1 --minutes 30 --raw-rate-hz 1 --seed 5",
    ] {
        let args: Vec<&str> = args.split(' ').collect();
        let out = fogsim(&dir, &args);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    }
    let ty = std::fs::read_to_string(dir.join("type.json")).unwrap();
    assert!(
        ty.contains("warm-up clock amplitude (400 s)"),
        "the type reads the power-on clocks"
    );
    assert_eq!(out_of_range_windows(&dir, "long", "type.fogm"), 0);
    assert_eq!(out_of_range_windows(&dir, "hot", "type.fogm"), 180);
}
