//! Exports the trainer's Gaussian design matrix for `bench/sklearn_omp.py`, so
//! scikit-learn's OrthogonalMatchingPursuit runs on exactly the matrix our OLS sees.
//!
//! `cargo run --release -p fog-sim --example export_design -- CAMPAIGN_DIR OUT_DIR`
//! (CAMPAIGN_DIR from `fogsim campaign`). Paper protocol: per ambient, the first 3 runs
//! (name order) train, the rest are held out. Trains our model (OLS, width by grouped
//! validation), then writes at the chosen width:
//!   phi_train.f32  N_train x N_train, row i = sample i, column k = candidate centre k
//!   phi_test.f32   N_test x N_train
//!   y_train.f64, y_test.f64   target drift, deg/h
//!   meta.json      sizes, width, and our timings / held-out rms / centre count.

use fog_sim::io::runs::{read_runs, Run};
use fog_sim::train::{
    dataset_from_runs, default_specs, predict_batch, rms, train_model, TrainConfig,
};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [campaign, out] = args.as_slice() else {
        anyhow::bail!("usage: export_design CAMPAIGN_DIR OUT_DIR");
    };
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out)?;
    let runs = read_runs(&[PathBuf::from(campaign)])?;
    let mut per_ambient: BTreeMap<i64, usize> = BTreeMap::new();
    let (mut train, mut test): (Vec<Run>, Vec<Run>) = (Vec::new(), Vec::new());
    for run in runs {
        let key = (run.ambient_c().unwrap_or(0.0) * 10.0).round() as i64;
        let seen = per_ambient.entry(key).or_default();
        *seen += 1;
        if *seen <= 3 {
            train.push(run)
        } else {
            test.push(run)
        }
    }
    let specs = default_specs();
    let ds_train = dataset_from_runs(&train, &specs)?;
    let ds_test = dataset_from_runs(&test, &specs)?;
    let cfg = TrainConfig::default();
    let t0 = Instant::now();
    let outcome = train_model(&ds_train, &cfg)?;
    let pipeline_s = t0.elapsed().as_secs_f64();
    let model = &outcome.model;
    let pred = predict_batch(model, ds_test.rows())?;
    let resid: Vec<f64> = ds_test
        .targets_dph
        .iter()
        .zip(&pred)
        .map(|(y, p)| y - p)
        .collect();
    let heldout = rms(&resid);

    let width = outcome.report.width;
    let norm = |r: &[f64]| -> Vec<f64> {
        (0..r.len())
            .map(|j| (r[j] - f64::from(model.input_offset[j])) / f64::from(model.input_scale[j]))
            .collect()
    };
    let centres: Vec<Vec<f64>> = ds_train
        .rows()
        .map(|r| norm(r).iter().map(|&v| f64::from(v as f32)).collect())
        .collect();
    let write_phi = |name: &str, rows: Vec<Vec<f64>>| -> anyhow::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(out.join(name))?);
        for x in rows {
            for c in &centres {
                let d2: f64 = x.iter().zip(c).map(|(a, b)| (a - b) * (a - b)).sum();
                f.write_all(&((-d2 / (2.0 * width * width)).exp() as f32).to_le_bytes())?;
            }
        }
        Ok(f.flush()?)
    };
    write_phi("phi_train.f32", centres.clone())?;
    write_phi("phi_test.f32", ds_test.rows().map(norm).collect())?;
    for (name, y) in [
        ("y_train.f64", &ds_train.targets_dph),
        ("y_test.f64", &ds_test.targets_dph),
    ] {
        let bytes: Vec<u8> = y.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(out.join(name), bytes)?;
    }
    let meta = serde_json::json!({
        "n_train": ds_train.len(), "n_test": ds_test.len(), "width": width,
        "ours": {
            "method": "OLS (Chen-Cowan-Grant), every sample a candidate, bias forced",
            "final_fit_s": outcome.report.timings.final_fit_s,
            "pipeline_s": pipeline_s,
            "n_centers": model.centers.len(),
            "train_rms_dph": outcome.report.train_rms_dph,
            "heldout_rms_dph": heldout,
        }
    });
    std::fs::write(out.join("meta.json"), serde_json::to_vec_pretty(&meta)?)?;
    println!(
        "exported {} train x {} candidates, {} test rows at width {width}; ours: {} centres, fit {:.2} s, held-out rms {heldout:.4} dph",
        ds_train.len(), ds_train.len(), ds_test.len(), model.centers.len(), outcome.report.timings.final_fit_s
    );
    Ok(())
}
