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
