//! `diagnose` on bad input: clear errors or stated exclusions, never a panic.

#[allow(dead_code)]
use crate::common::planted;
use fog_sim::diagnose::selection::power::PowerCheck;
use fog_sim::diagnose::{diagnose, DiagnoseError};
use fog_sim::io::runs::Run;
use fog_sim::pipeline::campaign::{simulate_campaign, CampaignSpec};
use fog_sim::sim::GyroParams;
use planted::{campaign, Effect, Shape};

fn small() -> Vec<Run> {
    campaign(
        Effect::Null,
        5,
        Shape {
            runs: 6,
            minutes: 20.0,
            sigmas: 1.0,
        },
    )
    .0
}

/// One 45 min record with nothing planted.
fn one_record() -> Vec<Run> {
    campaign(
        Effect::Null,
        9,
        Shape {
            runs: 1,
            minutes: 45.0,
            sigmas: 1.0,
        },
    )
    .0
}

fn set_column(run: &mut Run, name: &str, values: Vec<f64>) {
    match run.columns.iter().position(|c| c == name) {
        Some(i) => run.data[i] = values,
        None => {
            run.columns.push(name.to_owned());
            run.data.push(values);
        }
    }
}

#[test]
fn too_few_runs_is_a_clear_error() {
    let runs = campaign(
        Effect::Null,
        1,
        Shape {
            runs: 2,
            minutes: 2.0,
            sigmas: 1.0,
        },
    )
    .0;
    let e = diagnose(&runs).unwrap_err();
    assert!(
        matches!(e, DiagnoseError::TooFewRuns { runs: 2, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("too few"), "{e}");
    assert!(matches!(diagnose(&[]), Err(DiagnoseError::NoRuns)));
}

#[test]
fn nan_in_a_required_column_names_run_column_and_row() {
    let mut runs = small();
    let mut rate = runs[3].rate_dph().to_vec();
    rate[7] = f64::NAN;
    set_column(&mut runs[3], "rate_dph", rate);
    let e = diagnose(&runs).unwrap_err();
    assert_eq!(
        e,
        DiagnoseError::NotFinite {
            run: "run_03.csv".into(),
            column: "rate_dph".into(),
            row: 7
        }
    );
}

#[test]
fn mismatched_lengths_are_refused() {
    let mut runs = small();
    let n = runs[1].len();
    set_column(&mut runs[1], "supply_v", vec![1.0; n - 3]);
    let e = diagnose(&runs).unwrap_err();
    assert!(
        matches!(e, DiagnoseError::MismatchedLength { ref column, .. } if column == "supply_v"),
        "{e}"
    );
}

#[test]
fn nan_and_constant_extra_columns_are_excluded_with_a_reason() {
    let mut runs = small();
    for r in runs.iter_mut() {
        let n = r.len();
        set_column(r, "stuck_v", vec![5.0; n]);
        let mut bad: Vec<f64> = (0..n).map(|i| i as f64).collect();
        bad[2] = f64::NAN;
        set_column(r, "broken_c", bad);
    }
    let d = diagnose(&runs).expect("extra-column problems are exclusions, not errors");
    let ex = &d.report.campaign.excluded_columns;
    assert!(
        ex.iter()
            .any(|e| e.column == "stuck_v" && e.reason.contains("constant")),
        "{ex:?}"
    );
    assert!(
        ex.iter()
            .any(|e| e.column == "broken_c" && e.reason.contains("NaN")),
        "{ex:?}"
    );
    assert!(d
        .report
        .candidates
        .iter()
        .all(|c| c.column != "stuck_v" && c.column != "broken_c"));
}

#[test]
fn constant_temperature_is_refused() {
    let mut runs = small();
    for r in runs.iter_mut() {
        let n = r.len();
        set_column(r, "temp_c", vec![20.0; n]);
    }
    assert!(matches!(
        diagnose(&runs),
        Err(DiagnoseError::ConstantRequired { .. })
    ));
}

#[test]
fn a_single_record_is_validated_on_time_blocks_and_says_so() {
    let runs = one_record();
    let d = diagnose(&runs).expect("one long record is enough for time blocks");
    assert!(
        d.report.campaign.validation.contains("time blocks"),
        "{}",
        d.report.campaign.validation
    );
    assert!(d.report.named_cause.is_none());
}

/// The power check of a diagnosis that named nothing on a layout that can reach p < 0.01.
fn power_check_with_reachable_p(d: &fog_sim::diagnose::Diagnosis) -> &PowerCheck {
    assert!(d.report.campaign.smallest_attainable_p < 0.01);
    d.report
        .campaign
        .power_check
        .as_ref()
        .expect("checked when nothing is named")
}

#[test]
fn nothing_named_says_whether_the_record_could_have_shown_an_effect() {
    // 20 runs, nothing planted: nothing named, and a copy of a candidate planted at one
    // residual sigma is named, so "no significant cause" is a statement about the drift.
    let many = campaign(
        Effect::Null,
        9,
        Shape {
            runs: 20,
            minutes: 45.0,
            sigmas: 1.0,
        },
    )
    .0;
    let d = diagnose(&many).unwrap();
    let pc = power_check_with_reachable_p(&d);
    assert!(pc.named, "{pc:?}");
    assert!(
        d.report.cause_in_words.starts_with("no significant cause"),
        "{}",
        d.report.cause_in_words
    );
    // One 45 min record with drift wander: 8 time blocks reach p 0.0039, but the planted
    // one-sigma copy is not named, so the tool cannot decide and says so.
    let long = one_record();
    let d = diagnose(&long).unwrap();
    let pc = power_check_with_reachable_p(&d);
    assert!(!pc.named, "{pc:?}");
    assert!(
        d.report.cause_in_words.contains("no test power at 1 sigma"),
        "{}",
        d.report.cause_in_words
    );
    // 20 points: too few validation units for any p below the level.
    let mut short = long;
    for v in short[0].data.iter_mut() {
        v.truncate(20);
    }
    let d = diagnose(&short).unwrap();
    let p = d.report.campaign.smallest_attainable_p;
    assert!(p >= 0.01, "20 points, 6 blocks: smallest p {p}");
    assert!(d.report.campaign.power_check.is_none());
    assert!(
        d.report.cause_in_words.contains("no test power"),
        "{}",
        d.report.cause_in_words
    );
}

#[test]
fn a_record_whose_column_candidates_are_functions_of_the_base_plants_only_other_shapes() {
    // The project's simulator at one ambient, nothing but time, temperature and a fixed
    // heading: every candidate built from T and t (lags, rates, decays) is mostly predicted
    // by a base in T on a warm-up, so planting one could not test power. Since the generic
    // library (issue 18) the record's metadata (`# run`, `# seed`) also enter, as products
    // with T and dT/dt, which the base cannot predict, and since the hysteresis operator
    // (issue 38) T's stop operator, which on a warm-up from one ambient is min(T - T0, h):
    // a corner h above the start that no polynomial in T carries. Only those are planted.
    let spec = CampaignSpec {
        ambients_c: vec![20.0],
        runs_per_ambient: 20,
        minutes: 45.0,
        seed: 3,
        latitude_deg: 39.9,
        raw_rate_hz: 1.0,
        warm_restarts: None,
    };
    let runs: Vec<Run> = simulate_campaign(&GyroParams::paper_default(), &spec)
        .unwrap()
        .into_iter()
        .map(|c| c.run)
        .collect();
    let d = diagnose(&runs).unwrap();
    let pc = power_check_with_reachable_p(&d);
    assert!(!pc.shapes.is_empty(), "{pc:?}");
    assert!(
        pc.shapes
            .iter()
            .all(|s| s.planted.starts_with("# ") || s.planted.starts_with("temp_c:hysteresis")),
        "a T or t candidate was planted: {pc:?}"
    );
    assert!(
        d.report.cause_in_words.contains("power check")
            || d.report.cause_in_words.contains("no test power"),
        "{}",
        d.report.cause_in_words
    );
}
