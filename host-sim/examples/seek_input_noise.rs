//! Which model input's noise scatters the first seeks, and from which 10 s windows.
//!
//! Trains `north-seek`'s own default model at an ambient (exactly as `north-seek` does,
//! `own_model::train_own_model`, seed 1), then simulates fresh runs twice with the same
//! seed: as the sensor reads (noise, quantisation) and with a perfect thermometer. The
//! sensor has its own random stream, so both twins share every other draw (gyro noise,
//! warm-up, dissipation): their inputs differ by the thermometer's noise alone. Each input
//! column in turn is taken from the noisy twin into the clean rows, and the model's
//! predicted seek difference (the Monte Carlo's dwells: position 0 rows ending in
//! (270k + 13, 270k + 113] s, position 180 in (270k + 169, 270k + 269] s, psi 108.4 deg) is
//! compared with the clean one: its scatter over the runs is the azimuth scatter that
//! input's noise gives seek k. Then, per row of seek 1, the rms over the runs of each
//! input's noise and of the prediction error it causes. Last, the whole seek error
//! (target - prediction) over the runs of twins without gyro noise, without thermometer
//! noise, with one dissipation for all runs, with a perfect soak: what is left when the
//! gyro and the thermometer are quiet is misfit, and the twin that removes it names the
//! run-to-run difference the model's inputs do not follow.
//!
//! `target/release/examples/seek_input_noise AMBIENT_C [RUNS] [SEED]` (defaults 40, 777).
//! Experiments (environment): `SEEK_INPUT_NOISE_SET` (an input set), `_DECAY` (append the
//! time since power-on, `PowerOnDecay` with this tau, s), `_WIDTHS`, `_LINEAR=1`, `_RUNS`
//! retrain on the own model's runs (or that many) with them; `_SAVE=PATH` writes the model (never over a file);
//! `_CSV=DIR` writes each twin's rows (inputs, target, prediction).

use anyhow::{anyhow, bail, Result};
use fog_core::model::format::{FeatureKind, FeatureSpec, RbfModel, MAX_ENCODED_LEN};
use fog_sim::io::runs::Run;
use fog_sim::pipeline::campaign::CampaignSpec;
use fog_sim::pipeline::campaign_steps::simulate_checked;
use fog_sim::pipeline::north_seek::own_model::{train_own_model, OwnModelPlan};
use fog_sim::sim::{GyroParams, DEFAULT_LATITUDE_DEG};
use fog_sim::train::seek_score::Criterion;
use fog_sim::train::{
    dataset_from_runs, predict_batch, train_model, Dataset, InputSet, TrainConfig,
};

const PSI_DEG: f64 = 108.4;

fn runs(params: &GyroParams, ambient_c: f64, n: usize, seed: u64) -> Result<Vec<Run>> {
    Ok(simulate_checked(
        params,
        &CampaignSpec {
            ambients_c: vec![ambient_c],
            runs_per_ambient: n,
            ..CampaignSpec::paper(seed)
        },
    )?
    .into_iter()
    .map(|c| c.run)
    .collect())
}

/// Azimuth error, deg, of a drift difference e0 - e180 (deg/h) at the site.
fn azimuth_deg(e0: f64, e180: f64) -> f64 {
    let omh = fog_core::consts::earth_rate_horizontal_dph(DEFAULT_LATITUDE_DEG);
    -(e0 - e180) / (2.0 * omh * PSI_DEG.to_radians().sin()) * 180.0 / std::f64::consts::PI
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn std(v: &[f64]) -> f64 {
    let m = mean(v);
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
}

/// Seek k's azimuth error (deg) per run of a per-row drift series `e` (deg/h): the
/// Monte Carlo's dwells over the dataset's 10 s rows.
fn seek_azimuth_per_run(ds: &Dataset, e: &[f64], seek: usize) -> Vec<f64> {
    let s = 270.0 * seek as f64;
    let dwell = |g: usize, lo: f64, hi: f64| {
        let v: Vec<f64> = (0..ds.len())
            .filter(|&i| ds.groups[i] as usize == g && ds.t_s[i] > lo && ds.t_s[i] <= hi)
            .map(|i| e[i])
            .collect();
        mean(&v)
    };
    (0..ds.n_groups())
        .map(|g| {
            azimuth_deg(
                dwell(g, s + 13.0, s + 113.0),
                dwell(g, s + 169.0, s + 269.0),
            )
        })
        .collect()
}

fn env(key: &str) -> Option<String> {
    std::env::var(format!("SEEK_INPUT_NOISE_{key}")).ok()
}

/// The own model, or the experiment's retrained one (module notes), with its inputs.
fn model_under_test(
    paper: &GyroParams,
    ambient_c: f64,
) -> Result<(RbfModel, Vec<FeatureSpec>, usize)> {
    let own = train_own_model(
        paper,
        &OwnModelPlan {
            ambient_c,
            latitude_deg: DEFAULT_LATITUDE_DEG,
            dwell_s: 110.0,
            seed: 1,
            criterion: Criterion::seek_default(),
            inputs: fog_sim::train::InputChoice::Auto,
            seek_timing: None,
            rate_clock: Default::default(),
        },
        fog_sim::pipeline::north_seek::own_model::CAMPAIGN_RUNS,
        None,
    )?;
    let mut specs = own.selection.chosen.specs();
    if ["SET", "WIDTHS", "LINEAR", "DECAY", "RUNS"]
        .iter()
        .all(|k| env(k).is_none())
    {
        return Ok((own.trained.model, specs, own.runs));
    }
    if let Some(set) = env("SET") {
        specs = InputSet::parse(&set)
            .ok_or_else(|| anyhow!("bad set {set}"))?
            .specs();
    }
    if let Some(tau) = env("DECAY") {
        specs.push(FeatureSpec {
            kind: FeatureKind::PowerOnDecay,
            tau_s: tau.parse()?,
        });
    }
    let mut cfg = TrainConfig {
        criterion: Criterion::seek_default(),
        linear_on_rbf_inputs: env("LINEAR").as_deref() == Some("1"),
        ..Default::default()
    };
    if let Some(w) = env("WIDTHS") {
        cfg.width_candidates = w.split(',').map(|x| x.parse()).collect::<Result<_, _>>()?;
    }
    let n_train = env("RUNS")
        .map(|r| r.parse())
        .transpose()?
        .unwrap_or(own.runs);
    let ds = dataset_from_runs(&runs(paper, ambient_c, n_train, 1)?, &specs)?;
    let out = train_model(&ds, &cfg)?;
    println!(
        "retrained: held-out seek {:.5} deg",
        out.report.cross_validation.best.heldout_seek_deg
    );
    Ok((out.model, specs, n_train))
}

/// Writes the model for `north-seek --model` (never over an existing file).
fn save(model: &RbfModel, path: &str) -> Result<()> {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let len = model
        .encode(&mut buf)
        .map_err(|e| anyhow!("encoding the model: {e}"))?;
    if std::path::Path::new(path).exists() {
        bail!("{path} exists: not overwritten");
    }
    std::fs::write(path, &buf[..len])?;
    Ok(())
}

/// Each input's thermometer noise alone through the model (seeks 1-3), then per row of
/// seek 1 the rms input noise and prediction error.
fn input_noise(noisy: &Dataset, clean: &Dataset, model: &RbfModel) -> Result<()> {
    let k = noisy.n_inputs();
    let xn: Vec<&[f64]> = noisy.rows().collect();
    let xc: Vec<&[f64]> = clean.rows().collect();
    let pred_clean = predict_batch(model, xc.iter().copied())?;
    // Variant v < k: clean rows with input v noisy; v == k: all noisy.
    let mut preds = Vec::new();
    for v in 0..=k {
        let rows: Vec<Vec<f64>> = (0..xn.len())
            .map(|i| {
                (0..k)
                    .map(|j| if v == k || j == v { xn[i][j] } else { xc[i][j] })
                    .collect()
            })
            .collect();
        preds.push(predict_batch(model, rows.iter().map(|r| r.as_slice()))?);
    }
    println!("azimuth scatter over the runs from each input's thermometer noise, deg:");
    let names = noisy.input_names.iter().map(String::as_str);
    for (v, name) in names.chain(["all inputs"]).enumerate() {
        let diff: Vec<f64> = preds[v]
            .iter()
            .zip(&pred_clean)
            .map(|(a, b)| a - b)
            .collect();
        let mut line = format!("  {name:<24}");
        for seek in 0..3 {
            let az = seek_azimuth_per_run(noisy, &diff, seek);
            line += &format!(
                "  seek {}: {:.4} (mean {:+.4})",
                seek + 1,
                std(&az),
                mean(&az)
            );
        }
        println!("{line}");
    }
    println!("seek 1, per row: t_s, then per input: rms noise / rms prediction error (deg/h)");
    let mut ts: Vec<f64> = noisy.t_s.iter().copied().filter(|&t| t <= 270.0).collect();
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    for t in ts {
        let idx: Vec<usize> = (0..noisy.len()).filter(|&i| noisy.t_s[i] == t).collect();
        let rms = |f: &dyn Fn(usize) -> f64| {
            (idx.iter().map(|&i| f(i).powi(2)).sum::<f64>() / idx.len() as f64).sqrt()
        };
        let mut line = format!("  {t:>5.0}");
        for v in 0..=k {
            let noise = if v < k {
                format!("{:.2e}", rms(&|i| xn[i][v] - xc[i][v]))
            } else {
                "-".into()
            };
            line += &format!("  {noise} / {:.4}", rms(&|i| preds[v][i] - pred_clean[i]));
        }
        println!("{line}");
    }
    Ok(())
}

/// The whole seek error (target - prediction) of each twin, seeks 1-3.
fn twins(
    twins: &[(&str, GyroParams)],
    model: &RbfModel,
    specs: &[FeatureSpec],
    ambient_c: f64,
    n: usize,
    seed: u64,
) -> Result<()> {
    println!("seek error over the runs (target - prediction), std / mean, deg:");
    for (name, p) in twins {
        let ds = dataset_from_runs(&runs(p, ambient_c, n, seed)?, specs)?;
        let pred = predict_batch(model, ds.rows())?;
        let err: Vec<f64> = ds
            .targets_dph
            .iter()
            .zip(&pred)
            .map(|(y, p)| y - p)
            .collect();
        if let Some(dir) = env("CSV") {
            write_rows(
                &ds,
                &pred,
                &format!("{dir}/{}.csv", name.trim().replace([' ', ','], "_")),
            )?;
        }
        let mut line = format!("  {name:<34}");
        for seek in 0..3 {
            let az = seek_azimuth_per_run(&ds, &err, seek);
            line += &format!("  seek {}: {:.4} / {:+.4}", seek + 1, std(&az), mean(&az));
        }
        println!("{line}");
    }
    Ok(())
}

fn write_rows(ds: &Dataset, pred: &[f64], file: &str) -> Result<()> {
    if std::path::Path::new(file).exists() {
        bail!("{file} exists: not overwritten");
    }
    let mut out = format!(
        "run,t_s,{},target_dph,predicted_dph\n",
        ds.input_names.join(",")
    );
    for (i, row) in ds.rows().enumerate() {
        let x: Vec<String> = row.iter().map(|v| format!("{v:.8e}")).collect();
        out += &format!(
            "{},{},{},{:.6},{:.6}\n",
            ds.groups[i],
            ds.t_s[i],
            x.join(","),
            ds.targets_dph[i],
            pred[i]
        );
    }
    std::fs::write(file, out)?;
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let ambient_c: f64 = args
        .first()
        .ok_or_else(|| anyhow!("usage: seek_input_noise AMBIENT_C [RUNS] [SEED]"))?
        .parse()?;
    let n: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(40);
    let seed: u64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(777);
    let paper = GyroParams::paper_default();
    let (model, specs, n_train) = model_under_test(&paper, ambient_c)?;
    if let Some(path) = env("SAVE") {
        save(&model, &path)?;
    }
    println!(
        "model at {ambient_c} degC: {} on {n_train} runs, {} centres; {n} fresh runs (seed {seed})",
        specs
            .iter()
            .map(|s| format!("{:?}", s.kind))
            .collect::<Vec<_>>()
            .join(","),
        model.centers.len()
    );
    let mut clean = paper.clone();
    clean.sensor.noise_c = 0.0;
    clean.sensor.resolution_c = 0.0;
    let noisy_ds = dataset_from_runs(&runs(&paper, ambient_c, n, seed)?, &specs)?;
    let clean_ds = dataset_from_runs(&runs(&clean, ambient_c, n, seed)?, &specs)?;
    if noisy_ds.t_s != clean_ds.t_s || noisy_ds.groups != clean_ds.groups {
        bail!("the twins' rows differ (readiness depends on the readings)");
    }
    input_noise(&noisy_ds, &clean_ds, &model)?;
    // Twins: as measured; without gyro noise (what the model adds: thermometer noise and
    // misfit); also with a perfect thermometer (misfit: how each run's drift departs from
    // what its clean inputs predict); then without each run-to-run variation in turn.
    let mut quiet = paper.clone();
    quiet.noise.arw_dpsh = 0.0;
    quiet.noise.bias_instability_dph = 0.0;
    quiet.noise.rrw_dph_per_sqrt_h = 0.0;
    quiet.noise.quantization_arcsec = 0.0;
    let mut quiet_clean = quiet.clone();
    quiet_clean.sensor = clean.sensor.clone();
    let mut same_power = quiet_clean.clone();
    same_power.variation.power_sigma_frac = 0.0;
    let mut same_start = quiet_clean.clone();
    same_start.variation.start_temp_sigma_c = 0.0;
    twins(
        &[
            ("as measured", paper),
            ("no gyro noise", quiet),
            ("no gyro noise, clean thermometer", quiet_clean),
            ("  and the same dissipation", same_power),
            ("  and a perfect soak", same_start),
        ],
        &model,
        &specs,
        ambient_c,
        n,
        seed,
    )
}
