//! `fogsim import` of the PAN thermal-vacuum MEMS log: burst means, LSM6DSM temperature
//! conversion, rad/s -> deg/h, outlier removal, and rejection of malformed files; the
//! warm-up clock choice on the recording (one cooling run: no test power, the slope).

use fog_sim::io::import::{import_pan, lsm6dsm_temp_c, PAN_HEADER};
use std::path::PathBuf;

const RADS_TO_DPH: f64 = 180.0 / std::f64::consts::PI * 3600.0;

fn write_tmp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fog-import-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Two bursts of 10 samples 300 s apart, one spike in the first burst's x axis.
fn synthetic() -> String {
    let mut s = format!("{PAN_HEADER}\n");
    for burst in 0..2 {
        for k in 0..10 {
            let t_ms = 15_000 + burst * 300_000 + k * 20;
            let gx = if burst == 0 && k == 4 {
                -0.09
            } else {
                -0.065 + 0.0001 * (k % 3) as f64
            };
            let raw = 65236 - burst * 100;
            s += &format!("{t_ms},-1.4E-05,2.7E-05,2.8E-05,{gx},0.057,0.029,{raw}\n");
        }
    }
    s
}

#[test]
fn bursts_become_rows_in_fog_runs_units() {
    let p = write_tmp("TVC_synth.csv", &synthetic());
    let imp = import_pan(&p, &[0, 1]).unwrap();
    assert_eq!((imp.samples, imp.bursts, imp.outliers_dropped), (20, 2, 1));
    let x = &imp.runs[0];
    assert_eq!(x.len(), 2);
    let expect_x = (-0.065
        + 0.0001 * (0.0 + 1.0 + 2.0 + 0.0 + 1.0 + 2.0 + 0.0 + 1.0 + 2.0 - 1.0) / 9.0)
        * RADS_TO_DPH;
    assert!(
        (x.rate_dph()[0] - expect_x).abs() < 1e-6,
        "{} vs {expect_x}",
        x.rate_dph()[0]
    );
    assert!((x.temp_c()[1] - lsm6dsm_temp_c(65136.0)).abs() < 1e-12);
    assert!((imp.runs[1].rate_dph()[1] - 0.057 * RADS_TO_DPH).abs() < 1e-6);
    assert!((x.column("mag_x_ut").unwrap()[0] + 14.0).abs() < 1e-9);
    assert!(x.meta_value("license").unwrap().contains("MIT"));
}

#[test]
fn malformed_files_are_rejected_with_the_line() {
    let p = write_tmp(
        "bad.csv",
        &format!("{PAN_HEADER}\n1,0,0,0,0,0,0,1\n2,0,0,0,oops,0,0,1\n"),
    );
    let e = import_pan(&p, &[0]).unwrap_err();
    assert_eq!(e.line, Some(3), "{e}");
    let p = write_tmp("hdr.csv", "time,gyro\n1,2\n");
    assert!(import_pan(&p, &[0]).is_err());
    assert!(import_pan(&PathBuf::from("/nonexistent/TVC.csv"), &[0]).is_err());
}

/// The measured recording, when this machine has it (else None, said on stderr).
fn recording() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data/measured/pan-tvac-mems/TVCtest3_7_20.csv");
    if !p.exists() {
        eprintln!("skipped: {} not present on this machine", p.display());
        return None;
    }
    Some(p)
}

#[test]
fn the_real_recording_when_present_gives_25_bursts_and_3_outliers() {
    let Some(p) = recording() else { return };
    let imp = import_pan(&p, &[0, 1, 2]).unwrap();
    assert_eq!(
        (imp.samples, imp.bursts, imp.outliers_dropped),
        (6250, 25, 3)
    );
    let t = imp.runs[0].temp_c();
    assert!(
        (t[0] - 23.8).abs() < 0.1 && (t[24] - 15.7).abs() < 0.1,
        "{} .. {}",
        t[0],
        t[24]
    );
}

/// The warm-up clock choice (`train`'s default, with or without `--type-out`) on the measured recording: one
/// run of a unit cooling in a chamber, no power-on warm-up: fewer than 3 runs to test the
/// choice, so it says it has no test power and keeps the slope.
#[test]
fn the_real_recording_keeps_the_slope_for_want_of_runs() {
    let Some(p) = recording() else { return };
    let imp = import_pan(&p, &[0]).unwrap();
    let choice = fog_sim::train::warmup_clock::choose_warmup_clock(&imp.runs);
    println!("{}", choice.describe());
    assert!(
        !choice.is_diffusion() && choice.t.is_none(),
        "{}",
        choice.describe()
    );
    assert!(choice.describe().contains("no test power"));
}
