//! `fogsim train --inputs`: `auto` scores (T, dT/dt) and (T, dT/dt, d2T/dt2) by grouped
//! validation on the same points and keeps the better; the model carries its inputs.
//! Three laws: drift in d2T/dt2 (accel must win clearly), the Shupe law in dT/dt (accel
//! brings nothing material) and drift unrelated to temperature (the null: neither helps).
//! Also: outputs locked against a second `train`, and too few runs refused before reading.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};
use fog_core::model::format::{FeatureKind, RbfModel};
use std::path::Path;

#[derive(Clone, Copy)]
enum Law {
    Accel,
    Shupe,
    Null,
}

/// A warm-up with two thermal time constants (coil and housing), so d2T/dt2 is not a
/// function of T and dT/dt; drift by `law`, plus hashed noise.
fn write_run(path: &Path, ambient_c: f64, run: usize, law: Law) {
    let mut s = format!("# fog-runs v1\n# ambient_c: {ambient_c}\nt_s,rate_dph,temp_c\n");
    let mut h = 0x9E37_79B9_7F4A_7C15u64 ^ (run as u64 + 7).wrapping_mul(0xD1B5_4A32_D192_ED03);
    let (tau1, tau2) = (250.0 + 60.0 * run as f64, 1500.0 - 100.0 * run as f64);
    for i in 1..=180u32 {
        let t = 10.0 * f64::from(i);
        let (e1, e2) = ((-t / tau1).exp(), (-t / tau2).exp());
        let temp = ambient_c + 5.0 * (1.0 - e1) + 3.0 * (1.0 - e2);
        let rate = 5.0 / tau1 * e1 + 3.0 / tau2 * e2;
        let accel = -5.0 / (tau1 * tau1) * e1 - 3.0 / (tau2 * tau2) * e2;
        h ^= h << 13;
        h ^= h >> 7;
        h ^= h << 17;
        let noise = 0.004 * ((h >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
        let drift = match law {
            Law::Accel => -2000.0 * accel + noise,
            Law::Shupe => 15.0 * rate + noise,
            Law::Null => 10.0 * noise,
        };
        s += &format!("{t},{},{temp:.6}\n", 9.7 + drift);
    }
    std::fs::write(path, s).unwrap();
}

fn campaign(dir: &Path, law: Law) {
    std::fs::create_dir_all(dir).unwrap();
    for (a, amb) in [-10.0, 20.0, 50.0].iter().enumerate() {
        for r in 0..3 {
            write_run(&dir.join(format!("a{a}_run{r}.csv")), *amb, r, law);
        }
    }
}

/// Trains with `--inputs auto --force`; returns (chosen, score of t,rate, score of
/// t,rate,accel, model).
fn auto(dir: &Path, name: &str) -> (String, f64, f64, Option<RbfModel>) {
    let runs = dir.join(name);
    let model = dir.join(format!("{name}.bin"));
    let json = dir.join(format!("{name}.json"));
    let o = fogsim(
        dir,
        &[
            "train",
            runs.to_str().unwrap(),
            "--out",
            model.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
            "--widths",
            "0.6,1",
            "--force",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("inputs: t,rate") && out.contains("<- chosen"),
        "{out}"
    );
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let sel = &r["input_selection"];
    let score = |i: usize| sel["scores"][i]["score"].as_f64().unwrap();
    assert_eq!(
        sel["scores"][0]["rows"], sel["scores"][1]["rows"],
        "same points"
    );
    let m = RbfModel::decode(&std::fs::read(&model).unwrap()).ok();
    (
        sel["chosen"].as_str().unwrap().to_owned(),
        score(0),
        score(1),
        m,
    )
}

#[test]
fn auto_chooses_the_inputs_the_data_needs() {
    let dir = scratch_dir("train-inputs");
    campaign(&dir.join("accel"), Law::Accel);
    campaign(&dir.join("shupe"), Law::Shupe);
    campaign(&dir.join("null"), Law::Null);

    let (chosen, two, three, model) = auto(&dir, "accel");
    assert_eq!(chosen, "t,rate,accel", "{two} vs {three}");
    assert!(three < 0.7 * two, "d2T/dt2 law: {three} vs {two}");
    let model = model.unwrap();
    assert_eq!(model.n_inputs(), 3);
    assert_eq!(model.inputs[2].kind, FeatureKind::TempAccelCps2);

    let (_, two, three, _) = auto(&dir, "shupe");
    assert!(
        three > 0.9 * two,
        "Shupe law: accel brings nothing material: {three} vs {two}"
    );
    let (_, two, three, _) = auto(&dir, "null");
    assert!(
        (three - two).abs() < 0.1 * two,
        "null law: {three} vs {two}"
    );

    // A fixed set is trained as given, without a choice.
    let model = dir.join("fixed.bin");
    let o = fogsim(
        &dir,
        &[
            "train",
            "shupe",
            "--out",
            model.to_str().unwrap(),
            "--inputs",
            "t,rate",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        RbfModel::decode(&std::fs::read(&model).unwrap())
            .unwrap()
            .n_inputs(),
        2
    );
}

/// A second `train` naming an output another one holds is refused and writes nothing;
/// two racing trains leave a model and a report of the same run.
#[test]
fn a_second_train_on_the_same_outputs_is_refused() {
    let dir = scratch_dir("train-lock");
    campaign(&dir.join("runs"), Law::Shupe);
    let out = dir.join("model.bin");
    let lock = std::fs::File::create(dir.join(".model.bin.lock")).unwrap();
    lock.lock().unwrap();
    let o = fogsim(
        &dir,
        &["train", "runs", "--out", "model.bin", "--json", "r.json"],
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("another command is writing it"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists() && !dir.join("r.json").exists());
    drop(lock);

    let spawn = |id: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_fogsim"))
            .current_dir(&dir)
            .args([
                "train",
                "runs",
                "--out",
                "model.bin",
                "--json",
                "r.json",
                "--inputs",
                "t,rate",
                "--gyro-id",
                id,
            ])
            .output()
    };
    let (a, b) = std::thread::scope(|s| {
        let a = s.spawn(|| spawn("first"));
        let b = s.spawn(|| spawn("second"));
        (a.join().unwrap().unwrap(), b.join().unwrap().unwrap())
    });
    assert!(a.status.success() || b.status.success());
    for o in [&a, &b] {
        if !o.status.success() {
            assert!(
                stderr(o).contains("another command is writing it"),
                "{}",
                stderr(o)
            );
        }
    }
    let model = RbfModel::decode(&std::fs::read(&out).unwrap()).unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    assert_eq!(
        model.meta.gyro_id.as_str(),
        report["gyro_id"].as_str().unwrap()
    );
}

#[test]
fn too_few_runs_are_refused_before_any_row_is_read() {
    let dir = scratch_dir("train-few");
    std::fs::create_dir_all(dir.join("runs")).unwrap();
    write_run(&dir.join("runs/a.csv"), 20.0, 0, Law::Shupe);
    // The second file is not even fog-runs: the count is refused before it is read.
    std::fs::write(dir.join("runs/b.csv"), "not a run\n").unwrap();
    let o = fogsim(&dir, &["train", "runs", "--out", "m.bin"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("2 run file(s)"), "{}", stderr(&o));
}
