//! Shared helpers of the `app_*` tests: run the `fogsim` binary, make a scratch directory,
//! and write a small simulated campaign plus a model trained on it.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use fog_sim::io::runs::write_run;
use fog_sim::pipeline::campaign_steps::{simulate_checked, train_default, CampaignSpec};
use fog_sim::sim::GyroParams;

/// Runs `fogsim` with `args` in `dir`.
pub fn fogsim(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fogsim"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("fogsim runs")
}

/// Runs `fogsim` with `args` (paths absolute) and asserts it succeeded, with its stderr.
pub fn fogsim_ok(args: &[&str]) {
    let out = fogsim(&std::env::temp_dir(), args);
    assert!(out.status.success(), "fogsim {args:?}: {}", stderr(&out));
}

/// stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh, empty directory for one test. It stays after the test (to look at when one
/// fails); the same test's directories of earlier test processes that have ended are
/// removed here, so at most one per test is left behind.
pub fn scratch_dir(name: &str) -> PathBuf {
    let prefix = format!("fogsim-app-{name}-");
    let tmp = std::env::temp_dir();
    remove_stale_scratch(&tmp, &prefix);
    let d = tmp.join(format!("{prefix}{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Removes `tmp/<prefix><pid>` directories whose process has ended (Linux: no
/// `/proc/<pid>`; elsewhere nothing is removed).
fn remove_stale_scratch(tmp: &Path, prefix: &str) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(tmp) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(|n| n.strip_prefix(prefix)) else {
            continue;
        };
        let ended = !pid.is_empty()
            && pid.bytes().all(|b| b.is_ascii_digit())
            && !Path::new("/proc").join(pid).exists();
        if ended {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Writes `runs` simulated 45-min cold starts at 20 degC into `dir/runs/` and a model
/// trained on the first three into `dir/model.bin`; returns the held-out run paths.
pub fn campaign_and_model(dir: &Path, runs: usize) -> Vec<PathBuf> {
    let params = GyroParams::paper_default();
    let plan = CampaignSpec {
        ambients_c: vec![20.0],
        runs_per_ambient: runs,
        ..CampaignSpec::paper(11)
    };
    let campaign = simulate_checked(&params, &plan).unwrap();
    let train: Vec<_> = campaign
        .iter()
        .filter(|c| c.index <= 3)
        .map(|c| &c.run)
        .collect();
    let model = train_default(&train, &fog_sim::train::default_specs(), "test")
        .unwrap()
        .model;
    let mut buf = [0u8; fog_core::model::format::MAX_ENCODED_LEN];
    let n = model.encode(&mut buf).unwrap();
    std::fs::write(dir.join("model.bin"), &buf[..n]).unwrap();
    std::fs::create_dir_all(dir.join("runs")).unwrap();
    campaign
        .iter()
        .filter(|c| c.index > 3)
        .map(|c| {
            let p = dir.join("runs").join(format!("run{}.csv", c.index));
            write_run(&p, &c.run).unwrap();
            p
        })
        .collect()
}

/// `n` field records of gyro `gyro_id`, one every `temp_step_c` from 15 degC, whose
/// residual bias is 0.002 deg/h per degC from 20 degC (what `train --field` can fit);
/// record `i` (0-based) measured under the model `model_crc32(i)`.
pub fn linear_field_records(
    gyro_id: &str,
    n: u32,
    temp_step_c: f32,
    model_crc32: impl Fn(u32) -> Option<u32>,
) -> Vec<fog_sim::io::field_records::StoredRecord> {
    use fog_core::seeking::field_record::FieldRecord;
    (0..n)
        .map(|i| {
            let temp_c = 15.0 + temp_step_c * i as f32;
            fog_sim::io::field_records::StoredRecord::new(
                gyro_id,
                &FieldRecord {
                    sequence: i + 1,
                    temp_c,
                    temp_rate_cps: 0.001 * (i % 3) as f32,
                    t_since_power_on_s: 600.0,
                    residual_bias_dph: 0.002 * (temp_c - 20.0),
                    model_crc32: model_crc32(i),
                    ..FieldRecord::ZERO
                },
            )
        })
        .collect()
}
