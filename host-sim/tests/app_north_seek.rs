//! `fogsim north-seek` on a short Monte Carlo: the JSON has the fields, the seeks
//! fit the paper's 4 min 56 s, and after a cold start the compensated first seek is
//! clearly better than the uncompensated one. Also: the Monte Carlo is deterministic and
//! does not depend on the thread count; a bad `--unit-spread` file of the unit recipe is
//! refused with one line.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};
use serde_json::Value;

fn f(v: &Value, path: &[&str]) -> f64 {
    path.iter()
        .fold(v, |v, k| &v[*k])
        .as_f64()
        .unwrap_or_else(|| panic!("{path:?} missing"))
}

/// `north-seek --starts 6 --seeks 3 --json JSON EXTRA...` in `dir`, which must succeed;
/// its JSON report.
fn short_seek(dir: &std::path::Path, json: &str, extra: &[&str]) -> Value {
    let args = [
        &[
            "north-seek",
            "--starts",
            "6",
            "--seeks",
            "3",
            "--json",
            json,
        ][..],
        extra,
    ]
    .concat();
    let out = fogsim(dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_str(&std::fs::read_to_string(dir.join(json)).unwrap()).unwrap()
}

#[test]
fn compensated_cold_start_seeks_beat_uncompensated_ones() {
    let dir = scratch_dir("northseek");
    // 24 chamber runs, not the default 96: this test is about the command, not about how
    // good the default model is (docs/record/northfinder.md measures that).
    let json = short_seek(
        &dir,
        "ns.json",
        &["--threads", "2", "--training-runs", "24"],
    );
    assert_eq!(json["starts"].as_u64(), Some(6));
    assert_eq!(json["seeks_per_start"].as_u64(), Some(3));
    let floor = f(&json, &["noise_floor_deg"]);
    assert!(floor > 0.005 && floor < 0.05, "floor {floor}");
    assert!(f(&json, &["seek_duration_s"]) <= 296.0);
    assert!(f(&json, &["max_seek_duration_s"]) <= 296.0);
    for arm in ["uncompensated", "compensated"] {
        assert!(f(&json, &[arm, "std_deg"]) > 0.0);
        assert!(f(&json, &[arm, "max_dev_deg"]) > 0.0);
        assert_eq!(
            json[arm]["per_seek_rms_error_deg"]
                .as_array()
                .unwrap()
                .len(),
            3
        );
        assert_eq!(json[arm]["per_seek_std_deg"].as_array().unwrap().len(), 3);
        assert_eq!(json[arm]["azimuths_deg"].as_array().unwrap().len(), 6);
    }
    let first = |arm: &str| json[arm]["per_seek_rms_error_deg"][0].as_f64().unwrap();
    assert!(
        first("compensated") < 0.6 * first("uncompensated"),
        "first seek: compensated {} vs uncompensated {}",
        first("compensated"),
        first("uncompensated")
    );
    assert!(
        f(&json, &["compensated", "rms_error_deg"]) < f(&json, &["uncompensated", "rms_error_deg"])
    );

    // Same seed, one thread: identical report.
    short_seek(
        &dir,
        "ns1.json",
        &[
            "--threads",
            "1",
            "--training-runs",
            "24",
            "--save-model",
            "own.bin",
        ],
    );
    let a = std::fs::read_to_string(dir.join("ns.json")).unwrap();
    let b = std::fs::read_to_string(dir.join("ns1.json")).unwrap();
    assert_eq!(a, b, "the Monte Carlo depends on the thread count");
    // The saved default model is the one the Monte Carlo ran: given back with `--model`,
    // the same seed gives the same compensated azimuths.
    let again = short_seek(&dir, "ns2.json", &["--model", "own.bin"]);
    assert_eq!(
        again["compensated"]["azimuths_deg"], json["compensated"]["azimuths_deg"],
        "--save-model wrote another model than the one the Monte Carlo ran"
    );
    assert_eq!(f(&json, &["restart_above_ambient_c"]), 0.0);

    // A warm restart 6 degC above the ambient (about the powered-on rise): the same gyro
    // has little warm-up left, so the uncompensated second seek, which after a cold start
    // carries -0.06 deg of warm-up drift, is near its noise. Out-of-range restarts are
    // refused by name.
    let warm = short_seek(
        &dir,
        "ns3.json",
        &["--model", "own.bin", "--restart-above-c", "6"],
    );
    assert_eq!(f(&warm, &["restart_above_ambient_c"]), 6.0);
    let seek2_mean = |v: &Value| {
        v["uncompensated"]["per_seek_mean_error_deg"][1]
            .as_f64()
            .unwrap()
    };
    assert!(
        seek2_mean(&warm).abs() < 0.5 * seek2_mean(&json).abs(),
        "uncompensated seek 2 mean: restart {} vs cold start {}",
        seek2_mean(&warm),
        seek2_mean(&json)
    );
    // The model carries its training cold starts' envelope: every restart is found not to
    // be one of them, and its seeks within the warm-up are refused instead of biased;
    // no cold start was flagged.
    let detected = |v: &Value, arm: &str| f(v, &[arm, "reliability", "warm_restarts_detected"]);
    assert_eq!(detected(&warm, "compensated"), 6.0);
    assert_eq!(detected(&warm, "uncompensated"), 0.0);
    assert!(f(&warm, &["compensated", "reliability", "refused"]) > 0.0);
    assert_eq!(detected(&json, "compensated"), 0.0);
    assert_eq!(f(&json, &["compensated", "reliability", "refused"]), 0.0);
    for bad in ["31", "-1", "nan"] {
        let out = fogsim(
            &dir,
            &["north-seek", "--model", "own.bin", "--restart-above-c", bad],
        );
        assert!(!out.status.success(), "--restart-above-c {bad} was taken");
        assert!(
            stderr(&out).contains("--restart-above-c"),
            "{bad}: {}",
            stderr(&out)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tilt_and_heading_arms_are_in_the_json_and_out_of_range_tilt_is_refused() {
    let dir = scratch_dir("northseek-tilt");
    let args = [
        "north-seek",
        "--starts",
        "3",
        "--seeks",
        "2",
        "--tilt-deg",
        "5",
        "--heading-bias-dph",
        "0.05",
        "--json",
        "tilt.json",
        "--threads",
        "2",
        "--training-runs",
        "24",
    ];
    let out = fogsim(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("tilt.json")).unwrap()).unwrap();
    let comp = f(&json, &["compensated", "std_deg"]);
    let floor = f(&json, &["noise_floor_deg"]);
    let tilt_unc = f(&json, &["tilt_uncompensated", "std_deg"]);
    assert!(comp < 3.0 * floor, "compensated {comp} vs floor {floor}");
    assert!(tilt_unc > 10.0 * comp, "tilt not fed {tilt_unc} vs {comp}");
    // The heading bias biases the two-position seek unless calibrated.
    let cal = f(&json, &["compensated", "mean_error_deg"]).abs();
    let uncal = f(&json, &["heading_uncalibrated", "mean_error_deg"]).abs();
    assert!(
        uncal > cal + 0.03,
        "uncalibrated {uncal} vs calibrated {cal}"
    );
    assert!((f(&json, &["heading_calibration", "amplitude_dph"]) - 0.05).abs() < 0.01);

    let out = fogsim(&dir, &["north-seek", "--starts", "1", "--tilt-deg", "31"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--tilt-deg 31"), "{}", stderr(&out));
}

#[test]
fn a_bad_unit_spread_file_is_refused_with_one_line_and_nothing_written() {
    let dir = scratch_dir("north-seek-spread");
    std::fs::write(
        dir.join("spread.txt"),
        "drift.shupe_dph_per_cps: ten percent\n",
    )
    .unwrap();
    let out = fogsim(
        &dir,
        &[
            "north-seek",
            "--type-units",
            "3",
            "--unit-spread",
            "spread.txt",
            "--starts",
            "1",
            "--json",
            "out.json",
        ],
    );
    let err = stderr(&out);
    assert!(!out.status.success());
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("--unit-spread spread.txt"), "{err}");
    assert!(!dir.join("out.json").exists());
    std::fs::remove_dir_all(dir).unwrap();
}
