//! `fogsim heading-cal`: a heading harmonic attached to a model (format v3) from explicit
//! coefficients and from a real `diagnose` report (the independent generator's campaign
//! with a heading bias between runs), bad input refused whole, and no input overwritten.

use crate::app_support;

use crate::common::independent;

use app_support::{fogsim, scratch_dir, stderr};
use fog_core::model::format::RbfModel;
use fog_core::model::synthetic::warmup_model;
use fog_sim::diagnose::diagnose;
use independent::{campaign, Hidden, REPEATABILITY_DPH};

fn write_model(dir: &std::path::Path) -> RbfModel {
    let m = warmup_model(16, 2, 1.0, 7);
    let mut buf = [0u8; fog_core::model::format::MAX_ENCODED_LEN];
    let n = m.encode(&mut buf).unwrap();
    std::fs::write(dir.join("model.bin"), &buf[..n]).unwrap();
    m
}

fn read(path: std::path::PathBuf) -> RbfModel {
    RbfModel::decode(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn explicit_coefficients_are_attached_and_bad_ones_refused() {
    let dir = scratch_dir("heading-cal-explicit");
    let plain = write_model(&dir);
    let args = [
        "heading-cal",
        "--model",
        "model.bin",
        "--out",
        "cal.bin",
        "--a-dph",
        "-0.031",
        "--b-dph",
        "0.022",
        "--sigma-dph",
        "0.0015",
        "--n-headings",
        "8",
    ];
    let out = fogsim(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let cal = read(dir.join("cal.bin"));
    let h = cal.heading.expect("harmonic attached");
    assert_eq!((h.cos_dph, h.sin_dph), (-0.031, 0.022));
    assert_eq!((h.cos_sigma_dph, h.n_headings), (0.0015, 8));
    assert_eq!(
        RbfModel {
            heading: None,
            ..cal
        },
        plain,
        "the rest unchanged"
    );

    // Out of bounds (> 10 deg/h), an output that is the input, too few headings: refused,
    // nothing written, the input intact.
    let before = std::fs::read(dir.join("model.bin")).unwrap();
    for (bad, needle) in [
        (
            ["--a-dph", "12.0", "--out", "x.bin", "--n-headings", "8"],
            "heading",
        ),
        (
            ["--a-dph", "0.01", "--out", "model.bin", "--n-headings", "8"],
            "model.bin",
        ),
        (
            ["--a-dph", "0.01", "--out", "x.bin", "--n-headings", "3"],
            "heading",
        ),
    ] {
        let mut a = vec![
            "heading-cal",
            "--model",
            "model.bin",
            "--b-dph",
            "0",
            "--sigma-dph",
            "0.001",
        ];
        a.extend(bad);
        let out = fogsim(&dir, &a);
        let err = stderr(&out);
        assert!(
            !out.status.success() && err.contains(needle),
            "{a:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!dir.join("x.bin").exists(), "{a:?} wrote an output");
    }
    assert_eq!(std::fs::read(dir.join("model.bin")).unwrap(), before);
}

/// Writes `report` as diagnose's JSON to `json` and runs `heading-cal --from-diagnose`.
fn attach_report(
    dir: &std::path::Path,
    report: &fog_sim::diagnose::Report,
    json: &str,
    out: &str,
) -> std::process::Output {
    std::fs::write(dir.join(json), serde_json::to_vec_pretty(report).unwrap()).unwrap();
    fogsim(
        dir,
        &[
            "heading-cal",
            "--model",
            "model.bin",
            "--from-diagnose",
            json,
            "--out",
            out,
        ],
    )
}

#[test]
fn diagnoses_between_run_harmonic_is_attached_with_the_same_bias_at_every_azimuth() {
    let dir = scratch_dir("heading-cal-diagnose");
    write_model(&dir);
    // A heading bias of 3 repeatability sigmas (rms over headings): amplitude A = 3 x
    // 0.005 x sqrt 2 = 0.0212 deg/h; one heading per run, 20 runs.
    let (runs, expected) = campaign(Hidden::HeadingBetweenRuns(3.0), 3);
    let d = diagnose(&runs).expect("diagnose");
    let named = d.report.between_run.heading.clone().expect("heading named");
    assert_eq!(expected, Some("heading_deg:run_harmonic"));
    let out = attach_report(&dir, &d.report, "d.json", "cal.bin");
    assert!(out.status.success(), "{}", stderr(&out));
    let h = read(dir.join("cal.bin"))
        .heading
        .expect("harmonic attached");
    for k in 0..24 {
        let alpha = 15.0 * k as f64;
        let want = named.amplitude_dph * (alpha - named.phase_deg).to_radians().cos();
        assert!((h.bias_dph(alpha) - want).abs() < 1e-6, "alpha {alpha}");
    }
    let true_amp = 3.0 * REPEATABILITY_DPH * std::f64::consts::SQRT_2;
    assert!(
        (f64::from(h.amplitude_dph()) - true_amp).abs() < 4.0 * f64::from(h.cos_sigma_dph),
        "amplitude {} vs planted {true_amp} (sigma {})",
        h.amplitude_dph(),
        h.cos_sigma_dph
    );
    assert_eq!(usize::from(h.n_headings), runs.len());

    // A report without a heading harmonic (the null campaign) attaches nothing.
    let (null_runs, _) = campaign(Hidden::Null, 3);
    let null = diagnose(&null_runs).expect("diagnose null");
    assert!(null.report.between_run.heading.is_none());
    let out = attach_report(&dir, &null.report, "null.json", "n.bin");
    assert!(!out.status.success() && stderr(&out).contains("between_run.heading is null"));
    assert!(!dir.join("n.bin").exists());
}

/// `campaign --headings-deg` with a planted heading bias, then `heading-cal --from-runs`
/// with a model of the same gyro: a and b come back within 3 of their reported sigmas
/// (A cos(alpha): a = A, b = 0); the null twin (nothing planted) gives a harmonic
/// compatible with zero; bad runs are refused naming the file and the value.
#[test]
fn a_and_b_are_fitted_from_runs_at_several_headings() {
    let dir = scratch_dir("heading-cal-runs");
    app_support::campaign_and_model(&dir, 3);
    for (bias, tag) in [(0.05, "planted"), (0.0, "null")] {
        let o = fogsim(
            &dir,
            &[
                "campaign",
                "--out",
                tag,
                "--ambient",
                "20",
                "--runs",
                "1",
                "--headings-deg",
                "0,45,90,135,180,225,270,315",
                "--heading-bias-dph",
                &bias.to_string(),
                "--seed",
                "3",
            ],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let out = format!("cal_{tag}.bin");
        let o = fogsim(
            &dir,
            &[
                "heading-cal",
                "--model",
                "model.bin",
                "--out",
                &out,
                "--from-runs",
                tag,
            ],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let h = read(dir.join(&out)).heading.expect("a harmonic attached");
        eprintln!(
            "heading-cal --from-runs {tag}: a {:+.5} +- {:.5}, b {:+.5} +- {:.5} deg/h",
            h.cos_dph, h.cos_sigma_dph, h.sin_dph, h.sin_sigma_dph
        );
        assert_eq!(h.n_headings, 8);
        assert!(h.cos_sigma_dph > 0.0 && h.cos_sigma_dph < 0.02, "{h:?}");
        assert!(
            (f64::from(h.cos_dph) - bias).abs() < 3.0 * f64::from(h.cos_sigma_dph),
            "{tag}: {h:?}"
        );
        assert!(
            f64::from(h.sin_dph).abs() < 3.0 * f64::from(h.sin_sigma_dph),
            "{tag}: {h:?}"
        );
    }
}

/// Runs without a heading, or at an impossible latitude: refused naming file and value.
#[test]
fn bad_heading_runs_are_refused_naming_the_file_and_the_value() {
    let dir = scratch_dir("heading-cal-bad-runs");
    app_support::campaign_and_model(&dir, 3);
    let o = fogsim(
        &dir,
        &[
            "campaign",
            "--out",
            "planted",
            "--ambient",
            "20",
            "--runs",
            "1",
            "--minutes",
            "10",
            "--headings-deg",
            "0,90,180,270",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // A run without a heading, and one at an impossible latitude: file and value named.
    std::fs::create_dir_all(dir.join("bad")).unwrap();
    let text = std::fs::read_to_string(dir.join("planted/amb00_p020c_h000.0_run1.csv")).unwrap();
    std::fs::write(
        dir.join("bad/r.csv"),
        text.replace("latitude_deg: 39.9", "latitude_deg: 95"),
    )
    .unwrap();
    let from = |runs: &str| {
        let args = [
            "heading-cal",
            "--model",
            "model.bin",
            "--out",
            "x.bin",
            "--from-runs",
            runs,
        ];
        fogsim(&dir, &args)
    };
    let o = from("bad");
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("bad/r.csv: latitude_deg 95.0000 is out of range"),
        "{err}"
    );
    assert!(!dir.join("x.bin").exists());
    std::fs::create_dir_all(dir.join("bad2")).unwrap();
    std::fs::write(
        dir.join("bad2/r.csv"),
        text.replace("heading_deg", "table_deg"),
    )
    .unwrap();
    let o = from("bad2");
    assert!(
        stderr(&o).contains("bad2/r.csv: no heading_deg column"),
        "{}",
        stderr(&o)
    );
}
