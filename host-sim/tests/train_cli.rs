//! `fogsim train` end to end on small fog-runs files: a valid model file is written and
//! decodes with fog-core; bad input gives a one-line error, a non-zero exit and no file.

mod app_support;

use fog_core::model::RbfModel;
use std::path::Path;

/// Writes one fog-runs v1 file of a warm-up whose drift follows dT/dt.
fn write_run(path: &Path, ambient_c: f64, run: usize) {
    let mut s = format!("# fog-runs v1\n# ambient_c: {ambient_c}\nt_s,rate_dph,temp_c,earth_dph\n");
    for i in 1..=120u32 {
        let t = 10.0 * f64::from(i);
        let tau = 500.0 + 50.0 * run as f64;
        let temp = ambient_c + 5.0 * (1.0 - (-t / tau).exp());
        let rate = 5.0 / tau * (-t / tau).exp();
        let drift = 15.0 * rate + 0.003 * f64::from((i * 7 + run as u32) % 5);
        s += &format!("{t},{},{temp:.4},9.7\n", 9.7 + drift);
    }
    std::fs::write(path, s).unwrap();
}

/// Runs `fogsim` (every path argument here is absolute, so any working directory does).
fn fogsim(args: &[&str]) -> std::process::Output {
    app_support::fogsim(&std::env::temp_dir(), args)
}

#[test]
fn train_writes_a_valid_model_and_rejects_bad_input_without_output() {
    let dir = std::env::temp_dir().join(format!("fogsim_train_cli_{}", std::process::id()));
    let runs = dir.join("runs");
    std::fs::create_dir_all(&runs).unwrap();
    for (a, amb) in [0.0, 20.0].iter().enumerate() {
        for r in 0..3 {
            write_run(&runs.join(format!("a{a}_run{r}.csv")), *amb, r);
        }
    }
    let model = dir.join("model.bin");
    let json = dir.join("report.json");
    let out = fogsim(&[
        "train",
        runs.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--max-centers",
        "10",
        "--widths",
        "0.5,1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let m = RbfModel::decode(&std::fs::read(&model).unwrap()).unwrap();
    assert!(!m.centers.is_empty() && m.centers.len() <= 10);
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["n_runs"], 6);
    assert!(report["heldout_rms_dph"].as_f64().unwrap() < 0.01);

    // A malformed cell: error names the file and line, exit != 0, no model written.
    let bad_dir = dir.join("bad");
    std::fs::create_dir_all(&bad_dir).unwrap();
    for r in 0..3 {
        write_run(&bad_dir.join(format!("run{r}.csv")), 20.0, r);
    }
    let bad_file = bad_dir.join("run1.csv");
    let text = std::fs::read_to_string(&bad_file)
        .unwrap()
        .replacen("9.7\n", "oops\n", 1);
    std::fs::write(&bad_file, text).unwrap();
    let bad_model = dir.join("bad_model.bin");
    let out = fogsim(&[
        "train",
        bad_dir.to_str().unwrap(),
        "--out",
        bad_model.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("run1.csv") && err.trim().lines().count() == 1,
        "{err}"
    );
    assert!(!bad_model.exists());

    // Impossible option: named, no output.
    let out = fogsim(&[
        "train",
        runs.to_str().unwrap(),
        "--out",
        bad_model.to_str().unwrap(),
        "--rho",
        "2",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("rho"));
    assert!(!bad_model.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
