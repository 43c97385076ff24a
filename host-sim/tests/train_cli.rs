//! `fogsim train` end to end on small fog-runs files: a valid model file is written and
//! decodes with fog-core; bad input gives a one-line error, a non-zero exit and no file.

use crate::app_support;

use fog_core::model::format::{FeatureKind, RbfModel};
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

/// `fogsim train RUNS --out MODEL EXTRA...`.
fn train(runs: &Path, model: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "train",
        runs.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    fogsim(&args)
}

/// `fogsim train RUNS --out MODEL --widths 0.5,1 EXTRA...` must succeed; the model it wrote.
fn train_ok(runs: &Path, model: &Path, extra: &[&str]) -> RbfModel {
    train_ok_printed(runs, model, extra).0
}

/// `train_ok`, with the report it printed.
fn train_ok_printed(runs: &Path, model: &Path, extra: &[&str]) -> (RbfModel, String) {
    let out = train(runs, model, &[&["--widths", "0.5,1"], extra].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        RbfModel::decode(&std::fs::read(model).unwrap()).unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// The report's `linear terms:` line.
fn linear_terms_line(report: &str) -> &str {
    report
        .lines()
        .find(|l| l.starts_with("linear terms:"))
        .unwrap_or_else(|| panic!("no `linear terms:` line in\n{report}"))
}

/// `fogsim train RUNS --out MODEL EXTRA...` must fail and write no model; its stderr.
fn train_refused(runs: &Path, model: &Path, extra: &[&str]) -> String {
    let out = train(runs, model, extra);
    assert!(!out.status.success());
    assert!(!model.exists());
    String::from_utf8_lossy(&out.stderr).into_owned()
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
    let (m, printed) = train_ok_printed(
        &runs,
        &model,
        &["--json", json.to_str().unwrap(), "--max-centers", "10"],
    );
    assert_eq!(linear_terms_line(&printed), "linear terms: none (pure RBF)");
    assert!(!m.centers.is_empty() && m.centers.len() <= 10);
    // an exponential warm-up keeps dT/dt as the slope (`--warmup-clock auto`; its twin, a
    // diffusion warm-up read in its clock: train_type::the_cli_reads_dt_dt_in_the_clock...)
    assert!(
        printed
            .lines()
            .any(|l| l.starts_with("dT/dt read as the slope against time")),
        "{printed}"
    );
    assert!(m.inputs.iter().any(|s| s.kind == FeatureKind::TempRateCps));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["n_runs"], 6);
    assert!(report["heldout_rms_dph"].as_f64().unwrap() < 0.01);

    // --linear-inputs: linear terms in T and dT/dt under the Gaussians, in the model.
    let (lin, printed) = train_ok_printed(
        &runs,
        &dir.join("model_lin.bin"),
        &["--linear-inputs", "--inputs", "t,rate"],
    );
    // T's own linear term is the polynomial's (degree >= 1), so the line names dT/dt's.
    assert_eq!(linear_terms_line(&printed), "linear terms: temp_c:rate");
    assert_eq!(lin.linear.len(), 2, "one linear weight per RBF input");
    assert!(lin.linear.iter().any(|w| *w != 0.0));
    assert!(
        lin.linear_by_t.is_empty(),
        "no T-coupled terms unless asked"
    );
    // --inputs t,rise: T and the rise since power-on, no dT/dt, as given.
    let (rate_free, _) =
        train_ok_printed(&runs, &dir.join("model_rise.bin"), &["--inputs", "t,rise"]);
    let kinds: Vec<FeatureKind> = rate_free.inputs.iter().map(|s| s.kind).collect();
    assert_eq!(kinds, [FeatureKind::TempC, FeatureKind::TempRiseC]);
    // The rise takes the power-on for a cold start: the model carries its runs' envelope
    // (format v5); T and dT/dt alone take nothing of the kind and carry none.
    assert!(
        rate_free.cold_start.is_some(),
        "t,rise model without envelope"
    );
    assert!(lin.cold_start.is_none(), "t,rate model with an envelope");
    // --linear-by-t: beside each of them a coefficient of T x input (the dT/dt one here;
    // T x T is the polynomial's), written in the current format version (4 added them).
    let coupled_path = dir.join("model_lin_t.bin");
    let (coupled, printed) = train_ok_printed(
        &runs,
        &coupled_path,
        &["--linear-inputs", "--linear-by-t", "--inputs", "t,rate"],
    );
    assert!(
        linear_terms_line(&printed).ends_with("coefficients changing with T (t x input terms)"),
        "{printed}"
    );
    assert_eq!(coupled.linear_by_t.len(), 2);
    assert!(coupled.linear_by_t[1] != 0.0);
    let bytes = std::fs::read(&coupled_path).unwrap();
    assert_eq!(
        bytes[5] as u16,
        fog_core::model::format::MODEL_VERSION_BASE,
        "format version byte: {:?}",
        &bytes[..8]
    );
    // Without linear terms there is nothing to couple: refused by name, nothing written.
    let bad_model = dir.join("bad_model.bin");
    let err = train_refused(&runs, &bad_model, &["--linear-by-t"]);
    assert!(err.contains("linear-by-t"), "{err}");

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
    let err = train_refused(&bad_dir, &bad_model, &[]);
    assert!(
        err.contains("run1.csv") && err.trim().lines().count() == 1,
        "{err}"
    );

    // Impossible option: named, no output.
    let err = train_refused(&runs, &bad_model, &["--rho", "2"]);
    assert!(err.contains("rho"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Writes one fog-runs v1 warm-up whose drift is `shupe_dph_s_per_c` x dT/dt plus, with
/// `noise_only`, a drift that has nothing to do with temperature (a hashed sequence).
fn write_law_run(path: &Path, ambient_c: f64, run: usize, shupe: f64, noise_only: bool) {
    let mut s = format!("# fog-runs v1\n# ambient_c: {ambient_c}\nt_s,rate_dph,temp_c,earth_dph\n");
    let mut h = 0x9E37_79B9_7F4A_7C15u64 ^ (run as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03);
    for i in 1..=120u32 {
        let t = 10.0 * f64::from(i);
        let tau = 500.0 + 50.0 * run as f64;
        let temp = ambient_c + 5.0 * (1.0 - (-t / tau).exp());
        let rate_c_s = 5.0 / tau * (-t / tau).exp();
        h ^= h << 13;
        h ^= h >> 7;
        h ^= h << 17;
        let noise = 0.01 * ((h >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
        let drift = if noise_only {
            noise
        } else {
            shupe * rate_c_s + 0.1 * noise
        };
        s += &format!("{t},{},{temp:.4},9.7\n", 9.7 + drift);
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn train_refuses_a_model_that_does_not_help_and_compensate_warns_when_one_hurts() {
    let dir = std::env::temp_dir().join(format!("fogsim_train_guard_{}", std::process::id()));
    let noise = dir.join("noise");
    let shupe = dir.join("shupe");
    let reversed = dir.join("reversed");
    for d in [&noise, &shupe, &reversed] {
        std::fs::create_dir_all(d).unwrap();
    }
    for (a, amb) in [0.0, 20.0].iter().enumerate() {
        for r in 0..3 {
            let name = format!("a{a}_run{r}.csv");
            write_law_run(&noise.join(&name), *amb, r, 0.0, true);
            write_law_run(&shupe.join(&name), *amb, r, 15.0, false);
            // The twin law: the same warm-up with the opposite Shupe sign.
            write_law_run(&reversed.join(&name), *amb, r, -15.0, false);
        }
    }
    // Drift unrelated to temperature: the guard refuses, says why, writes the JSON only.
    let model = dir.join("noise_model.bin");
    let json = dir.join("noise_report.json");
    let args = |extra: &[&str]| {
        let mut v = vec![
            "train",
            noise.to_str().unwrap(),
            "--out",
            model.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
        ];
        v.extend_from_slice(extra);
        v.into_iter().map(str::to_string).collect::<Vec<_>>()
    };
    let refused = fogsim(&args(&[]).iter().map(String::as_str).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success(), "{err}");
    assert!(
        err.contains("not clearly better") && err.contains("--force"),
        "{err}"
    );
    assert!(!model.exists(), "a refused model must not be written");
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["verdict"], "not_better");
    // --force writes it anyway, still warning.
    let forced = fogsim(
        &args(&["--force"])
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(forced.status.success());
    assert!(String::from_utf8_lossy(&forced.stderr).contains("--force"));
    assert!(RbfModel::decode(&std::fs::read(&model).unwrap()).is_ok());

    // A model of the +Shupe gyro helps its own gyro and hurts the reversed one: compensate
    // warns for each record it makes worse, and only for those.
    let shupe_model = dir.join("shupe_model.bin");
    let trained = fogsim(&[
        "train",
        shupe.to_str().unwrap(),
        "--out",
        shupe_model.to_str().unwrap(),
    ]);
    assert!(
        trained.status.success(),
        "{}",
        String::from_utf8_lossy(&trained.stderr)
    );
    let own = fogsim(&[
        "compensate",
        shupe.to_str().unwrap(),
        "--model",
        shupe_model.to_str().unwrap(),
    ]);
    assert!(own.status.success());
    assert!(!String::from_utf8_lossy(&own.stderr).contains("makes this record worse"));
    let other = fogsim(&[
        "compensate",
        reversed.to_str().unwrap(),
        "--model",
        shupe_model.to_str().unwrap(),
    ]);
    assert!(other.status.success());
    let warned = String::from_utf8_lossy(&other.stderr)
        .lines()
        .filter(|l| l.contains("makes this record worse"))
        .count();
    assert_eq!(warned, 6, "{}", String::from_utf8_lossy(&other.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `model_path` with a heading calibration attached (`fogsim heading-cal`), and a calibrated
/// variant of a different model (another bias), both recorded in a new registry at
/// `registry` as `upload` records them; returns their CRC-32s (calibrated, other).
fn register_calibrated_variants(model_path: &Path, registry: &Path) -> (u32, u32) {
    use fog_sim::registry::{ModelRecord, Registry};
    let cal_path = model_path.with_file_name("model_cal.bin");
    let cal = fogsim(&[
        "heading-cal",
        "--model",
        model_path.to_str().unwrap(),
        "--out",
        cal_path.to_str().unwrap(),
        "--a-dph",
        "0.004",
        "--b-dph",
        "-0.002",
        "--sigma-dph",
        "0.001",
        "--n-headings",
        "8",
    ]);
    assert!(
        cal.status.success(),
        "{}",
        String::from_utf8_lossy(&cal.stderr)
    );
    let cal_bytes = std::fs::read(&cal_path).unwrap();
    let cal_model = RbfModel::decode(&cal_bytes).unwrap();
    assert!(cal_model.heading.is_some());
    let other = RbfModel {
        bias_dph: cal_model.bias_dph + 0.01,
        ..cal_model.clone()
    };
    let mut buf = [0u8; fog_core::model::format::MAX_ENCODED_LEN];
    let n = other.encode(&mut buf).unwrap();
    let mut reg = Registry::open(registry).unwrap();
    let cal_record = ModelRecord::of(&cal_model, &cal_bytes);
    let other_record = ModelRecord::of(&other, &buf[..n]);
    let trained_crc = fog_core::model::crc::crc32(&std::fs::read(model_path).unwrap());
    assert_eq!(cal_record.base_crc32, Some(trained_crc));
    assert_ne!(other_record.base_crc32, Some(trained_crc));
    reg.record_model(&cal_record).unwrap();
    reg.record_model(&other_record).unwrap();
    (cal_record.model_crc32, other_record.model_crc32)
}

/// Nine field records of gyro FIELD-1 (residual linear in T): six measured under `first`,
/// three under `second`.
fn field_records(first: u32, second: u32) -> Vec<fog_sim::io::field_records::StoredRecord> {
    app_support::linear_field_records("FIELD-1", 9, 2.0, |i| {
        Some(if i < 6 { first } else { second })
    })
}

/// `fogsim train`, its model with a heading calibration attached (`heading-cal`), the
/// variant recorded in the calibration registry as `upload` records it, field records
/// measured under the variant: `train --field --registry` retrains the same model and uses
/// those records; records under a calibrated variant of another model stay "measured under
/// another model". Without the registry (twin) no record matches and train refuses by name.
#[test]
fn train_field_counts_records_under_a_heading_calibrated_variant_the_registry_knows() {
    let dir = std::env::temp_dir().join(format!("fogsim_train_field_{}", std::process::id()));
    let runs = dir.join("runs");
    std::fs::create_dir_all(&runs).unwrap();
    for (a, amb) in [0.0, 20.0].iter().enumerate() {
        for r in 0..3 {
            write_run(&runs.join(format!("a{a}_run{r}.csv")), *amb, r);
        }
    }
    let model_path = dir.join("model.bin");
    let model = train_ok(&runs, &model_path, &["--gyro-id", "FIELD-1"]);
    let registry = dir.join("registry.sqlite");
    let (cal_crc, other_crc) = register_calibrated_variants(&model_path, &registry);
    let field = dir.join("field");
    fog_sim::io::field_records::merge_into_dir(&field, &field_records(cal_crc, other_crc)).unwrap();
    let train_field = |out: &Path, registry: Option<&Path>| {
        let mut args = vec![
            "train".to_string(),
            runs.display().to_string(),
            "--out".into(),
            out.display().to_string(),
            "--widths".into(),
            "0.5,1".into(),
            "--gyro-id".into(),
            "FIELD-1".into(),
            "--field".into(),
            field.display().to_string(),
        ];
        if let Some(r) = registry {
            args.extend(["--registry".into(), r.display().to_string()]);
        }
        // No default registry: only the one given counts.
        std::process::Command::new(env!("CARGO_BIN_EXE_fogsim"))
            .env("XDG_DATA_HOME", dir.join("no-default"))
            .args(&args)
            .output()
            .unwrap()
    };
    let refined_path = dir.join("refined.bin");
    let out = train_field(&refined_path, Some(&registry));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let expected = format!(
        "field refinement: 6 field seeks used (6 of them under heading-calibrated variants \
         [{cal_crc:08x}] (registry); 3 measured under another model, not used)"
    );
    assert!(stdout.contains(&expected), "{stdout}");
    assert!(stdout.contains("attach it again"), "{stdout}");
    // Each record has its own power-on clock (600 s): 6 power-ons to hold out in turn.
    assert!(stdout.contains("(6 power-ons;"), "{stdout}");
    assert!(
        stdout.contains("field range: T: field 15.0000 .. 25.0000"),
        "{stdout}"
    );
    let refined = RbfModel::decode(&std::fs::read(&refined_path).unwrap()).unwrap();
    assert_ne!(refined, model, "the field records moved the model");
    assert!(refined.heading.is_none());
    // Twin: the same records without the registry: none is this model's, refused by name.
    let twin_path = dir.join("twin.bin");
    let out = train_field(&twin_path, None);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("none of its 9 records was measured under this chamber model"),
        "{stderr}"
    );
    assert!(!twin_path.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn train_seek_refit_reports_its_weight_and_refuses_runs_without_a_whole_seek() {
    let dir = std::env::temp_dir().join(format!("fogsim_train_refit_{}", std::process::id()));
    let long = dir.join("long");
    let short = dir.join("short");
    std::fs::create_dir_all(&long).unwrap();
    std::fs::create_dir_all(&short).unwrap();
    for (a, amb) in [0.0, 20.0].iter().enumerate() {
        for r in 0..3 {
            write_run(&long.join(format!("a{a}_run{r}.csv")), *amb, r);
            // The same warm-up cut at 200 s: no seek's two positions (to 250 s) are in it.
            let text = std::fs::read_to_string(long.join(format!("a{a}_run{r}.csv"))).unwrap();
            let cut: Vec<&str> = text.lines().take(3 + 20).collect();
            std::fs::write(
                short.join(format!("a{a}_run{r}.csv")),
                cut.join("\n") + "\n",
            )
            .unwrap();
        }
    }
    let model = dir.join("m.bin");
    let json = dir.join("m.json");
    let (_, printed) = train_ok_printed(
        &long,
        &model,
        &["--seek-refit", "--json", json.to_str().unwrap()],
    );
    let line = printed
        .lines()
        .find(|l| l.starts_with("seek refit: pair weight"))
        .unwrap_or_else(|| panic!("no seek refit line in\n{printed}"));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let refit = &report["seek_refit"];
    // 6 runs of 1,200 s: 4 seeks each (the device's 270 s seek).
    assert_eq!(refit["pair_rows"], 24, "{refit}");
    assert_eq!(
        refit["bias_rms_deg"].as_array().unwrap().len(),
        9,
        "{refit}"
    );
    let w = refit["weight"].as_f64().unwrap();
    assert!(line.contains(&format!("pair weight {w} ")), "{line}");
    let short_model = dir.join("short.bin");
    let err = train_refused(&short, &short_model, &["--widths", "0.5,1", "--seek-refit"]);
    assert!(
        err.contains("--seek-refit") && err.contains("no run has rows over both positions"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
