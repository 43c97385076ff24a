//! `fogsim campaign` end to end: the paper's file layout, determinism across
//! invocations, and one-line errors with no output for impossible options.

use crate::app_support;

use fog_sim::io::runs::read_runs;
use std::path::PathBuf;

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fog_sim_campaign_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs `fogsim` (every path argument here is absolute, so any working directory does).
fn fogsim(args: &[&str]) -> std::process::Output {
    app_support::fogsim(&std::env::temp_dir(), args)
}

#[test]
fn writes_one_file_per_power_on_in_order() {
    let out = scratch("ok");
    let o = out.to_str().unwrap();
    let args = [
        "campaign",
        "--out",
        o,
        "--ambient",
        "-10,20",
        "--runs",
        "2",
        "--minutes",
        "3",
        "--seed",
        "5",
    ];
    let r = fogsim(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let runs = read_runs(&[&out]).unwrap();
    let names: Vec<String> = runs.iter().map(|r| r.name()).collect();
    assert_eq!(
        names,
        [
            "amb00_m010c_run1.csv",
            "amb00_m010c_run2.csv",
            "amb01_p020c_run1.csv",
            "amb01_p020c_run2.csv"
        ]
    );
    for (r, amb) in runs.iter().zip([-10.0, -10.0, 20.0, 20.0]) {
        assert_eq!(r.len(), 18);
        assert_eq!(r.ambient_c(), Some(amb));
        assert_eq!(r.meta_value("input_axis"), Some("vertical"));
        let earth = r.column("earth_dph").unwrap();
        assert!((earth[0] - 15.041067 * 39.9f64.to_radians().sin()).abs() < 1e-9);
    }
    // Re-running into the same directory is fine; a campaign that would leave stale runs is not.
    assert!(fogsim(&args).status.success());
    let fewer = [
        "campaign",
        "--out",
        o,
        "--ambient",
        "-10",
        "--runs",
        "1",
        "--minutes",
        "3",
    ];
    let r = fogsim(&fewer);
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("not part of this campaign"));
    assert_eq!(
        read_runs(&[&out]).unwrap().len(),
        4,
        "nothing written or removed"
    );
    let first = std::fs::read(out.join(&names[0])).unwrap();
    let again = scratch("again");
    let mut args2 = args;
    args2[2] = again.to_str().unwrap();
    assert!(fogsim(&args2).status.success());
    assert_eq!(
        first,
        std::fs::read(again.join(&names[0])).unwrap(),
        "same seed, same bytes"
    );
    std::fs::remove_dir_all(out).unwrap();
    std::fs::remove_dir_all(again).unwrap();
}

#[test]
fn impossible_options_fail_with_one_line_and_no_output() {
    let out = scratch("bad");
    let o = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["--runs", "0"], "--runs"),
        (vec!["--minutes", "-5"], "--duration-min"),
        (vec!["--latitude", "100"], "--latitude"),
        (vec!["--ambient", "-40,200"], "--ambient"),
        (vec!["--ambient", "-40,abc"], "--ambient"),
        (vec!["--raw-rate-hz", "33.33"], "--raw-rate-hz"),
    ] {
        let mut all = vec!["campaign", "--out", o];
        all.extend(&args);
        let r = fogsim(&all);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{args:?} accepted");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} left output behind");
    }
}
