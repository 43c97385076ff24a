//! The field refinement (`fogsim train --field`, `field::refine_with_records`) on a gyro
//! that is not the project's simulator: `common/field_gyro.rs` (its own thermal law, a
//! tanh temperature knee, a lagged gradient term, electronics settling, its own table),
//! driven through the same seek loop (`northseek::run_seeks_on`) by the aging measurement
//! (`field_aging::run_aging_on`). Field and evaluation at 10, 20 and 30 degC.
//!
//! Cheap test (seconds): the knee law (a temperature law) after 50 field seeks: the
//! evaluation seeks' residual bias falls (paired verdict "helps"); the null twin: neither
//! its bias nor its azimuth is made worse beyond noise. With 5 field seeks (one power-on)
//! nothing is refined (no test power).
//!
//! `FOG_FIELD_AGING_FULL=1` (`FOG_FIELD_AGING_SEED=N`, default 1): the whole table (the three laws, 5 / 20 / 50 field seeks, 30
//! evaluation starts x 6 seeks), printed (`--nocapture`) for docs/record/field.md.

use crate::common::field_gyro;

use field_gyro::{IndependentAging, IndependentLaw};
use fog_sim::pipeline::field_aging::{aging_table, run_aging_on, AgingPlan, AgingReport, Verdict};

/// `FOG_FIELD_AGING_SEED` (default 1).
fn seed() -> u64 {
    std::env::var("FOG_FIELD_AGING_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
}

fn measure(
    laws: Vec<IndependentLaw>,
    counts: Vec<usize>,
    eval_starts: usize,
    seed: u64,
) -> AgingReport {
    let plan = AgingPlan {
        field_seek_counts: counts,
        eval_starts,
        ambients_c: vec![10.0, 20.0, 30.0],
        threads: 2,
        ..AgingPlan::standard(seed)
    };
    let subject = IndependentAging {
        laws,
        runs_per_ambient: 6,
    };
    run_aging_on(&plan, &subject, &|_| {}).unwrap()
}

#[test]
fn refinement_recovers_the_independent_gyros_knee_aging_and_leaves_the_null_twin() {
    let r = measure(
        vec![IndependentLaw::Knee, IndependentLaw::None],
        vec![5, 50],
        10,
        1,
    );
    eprintln!("{}", aging_table(&r));
    let row = |law: &str, n: usize| {
        r.rows
            .iter()
            .find(|x| x.law == law && x.field_seeks == n)
            .unwrap()
    };
    // One power-on: no test power, the model unchanged.
    for law in ["knee", "none"] {
        assert_eq!(row(law, 5).field_weight, None, "{:?}", row(law, 5));
        assert_eq!(row(law, 5).comparison.rms_ratio, 1.0);
    }
    let aged = row("knee", 50);
    assert_eq!(aged.bias.verdict, Verdict::Helps, "{:?}", aged.bias);
    assert!(
        aged.bias.rms_with_dph < 0.8 * aged.bias.rms_without_dph,
        "{:?}",
        aged.bias
    );
    // The aging cost bias: the aged gyro's residual without refinement exceeds the null's.
    let null = row("none", 50);
    assert!(aged.bias.rms_without_dph > null.bias.rms_without_dph);
    assert!(!null.hurts(), "{null:?}");
    assert!(null.comparison.rms_ratio < 1.01, "{:?}", null.comparison);
}

#[test]
fn full_aging_table_on_the_independent_gyro() {
    if std::env::var_os("FOG_FIELD_AGING_FULL").is_none() {
        eprintln!("FOG_FIELD_AGING_FULL not set: the full table is not measured");
        return;
    }
    let r = measure(IndependentLaw::ALL.to_vec(), vec![5, 20, 50], 30, seed());
    println!("{}", aging_table(&r));
    for row in &r.rows {
        println!(
            "{} {}: terms {:?} coef {:?} not fitted {:?}",
            row.law, row.field_seeks, row.correction_terms, row.correction_coef_dph, row.not_fitted
        );
    }
    let worse: Vec<String> = r
        .rows
        .iter()
        .filter(|x| x.hurts())
        .map(|x| format!("{} {}", x.law, x.field_seeks))
        .collect();
    assert!(worse.is_empty(), "refinement made rows worse: {worse:?}");
}
