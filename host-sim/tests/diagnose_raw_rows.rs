//! The raw rows before averaging (`diagnose::input::rawrows`), on 1 Hz files from the
//! independent generator (`common/independent.rs`: white rate noise of known level, a
//! 0.0625 degC thermometer, a warm-up trend, no steps in the drift): the Allan deviation
//! gives back the ARW, the thermometer's quantum is found, the warm-up is not called a
//! step; the twin campaign with one planted 0.1 deg/h jump has exactly that step.

use crate::common::independent;
use fog_sim::diagnose::input::rawrows::read_runs;
use fog_sim::io::runs::write_run;
use independent::{campaign, Hidden, NOISE_10S_DPH};

/// Writes seed 11's null campaign (8 of its runs) with an optional jump of `step_dph` at
/// t = 1500 s in run 3; returns the directory.
fn write_campaign(name: &str, step_dph: f64) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("fog_raw_rows_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (runs, _) = campaign(Hidden::Null, 11);
    for (i, mut run) in runs.into_iter().take(8).enumerate() {
        if i == 3 {
            let t = run.data[0].clone();
            for (r, t) in run.data[1].iter_mut().zip(t) {
                if t >= 1500.0 {
                    *r += step_dph;
                }
            }
        }
        write_run(dir.join(format!("run{i:02}.csv")), &run).unwrap();
    }
    dir
}

#[test]
fn allan_arw_quantum_and_steps_of_1_hz_rows() {
    let dir = write_campaign("null", 0.0);
    let (runs, raw) = read_runs(&[&dir]).unwrap();
    assert_eq!(runs.len(), 8);
    assert_eq!(runs[0].t_s().len(), 270, "1 Hz rows binned to 10 s windows");
    assert_eq!(raw.rows, 8 * 2700);
    assert_eq!(raw.sample_period_s, 1.0);
    // White noise of 1 s rows = NOISE_10S * sqrt(10) deg/h: N = that * sqrt(1 s / 1 h).
    let want = NOISE_10S_DPH * 10f64.sqrt() / 60.0;
    let arw = raw.arw_dpsh.expect("a -1/2 slope");
    println!(
        "ARW {arw:.4e} +/- {:.1e} deg/sqrt(h) (generated {want:.4e}) over tau {:?} s; B {:?} deg/h at {:?} s ({})",
        raw.arw_plus_minus_dpsh.unwrap(),
        raw.arw_fit_taus_s,
        raw.bias_instability_dph,
        raw.bias_instability_tau_s,
        raw.bias_instability_note
    );
    assert!((arw / want - 1.0).abs() < 0.05, "ARW {arw} vs {want}");
    assert_eq!(raw.arw_fit_taus_s.first(), Some(&1.0));
    let temp = raw
        .quantisation
        .iter()
        .find(|q| q.column == "temp_c")
        .unwrap();
    assert!(
        (temp.smallest_step - 0.0625).abs() < 1e-9 && temp.quantised,
        "{temp:?}"
    );
    let rate = raw
        .quantisation
        .iter()
        .find(|q| q.column == "rate_dph")
        .unwrap();
    assert!(!rate.quantised, "{rate:?}");
    assert_eq!(raw.steps.count, 0, "{:?}", raw.steps.listed);

    let twin = write_campaign("step", 0.1);
    let (_, raw) = read_runs(&[&twin]).unwrap();
    assert_eq!(raw.steps.count, 1, "{:?}", raw.steps.listed);
    let s = &raw.steps.listed[0];
    assert!(
        s.run.ends_with("run03.csv") && (s.t_s - 1500.0).abs() <= 3.0,
        "{s:?}"
    );
    assert!((s.size_dph - 0.1).abs() < 0.03, "{s:?}");
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_dir_all(&twin).ok();
}
