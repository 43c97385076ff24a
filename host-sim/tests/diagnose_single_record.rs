//! Single long records validated on time blocks: with strongly autocorrelated drift noise
//! (AR(1) bias wander or a rate random walk) and nothing planted, the family-wise rule
//! must not name anything more often than its level allows, and a real planted effect in
//! one record must be named without naming wrong columns more often than the level
//! allows (its power is low here and measured, see docs/record/diagnose.md). Two generators with
//! different physical laws (`common/single_record.rs`); the unbuffered rule (before
//! issue 9 item 5) runs next to the buffered one for comparison.

use crate::common::single_record;
use fog_sim::diagnose::diagnose_with;
use fog_sim::diagnose::validation::buffer::BufferRule;
use single_record::{record, Law};

/// Seeds for the null count (`SINGLE_SEEDS=N` for more).
fn null_seeds() -> Vec<u64> {
    let n = std::env::var("SINGLE_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20u64);
    (1..=n).collect()
}

struct Outcome {
    named: Option<String>,
    no_test_power: bool,
    line: String,
}

fn run(law: Law, sigmas: f64, seed: u64, rule: BufferRule) -> Outcome {
    let (runs, _) = record(law, sigmas, seed);
    let d = diagnose_with(&runs, rule).expect("diagnose a single record");
    let r = &d.report;
    let named = r.named_cause.as_ref().map(|c| c.label());
    let top = r.candidates.first().map(|c| {
        format!(
            "{}:{}({:?}) {:+.2}% p{:.4}",
            c.column,
            c.transform.name(),
            c.tau_s,
            c.gain_pct,
            c.p_value
        )
    });
    let line = format!(
        "{law:?} x{sigmas} seed {seed} {rule:?}: {}, smallest p {:.4}, base {} {:.4}, named {named:?}, top {top:?}",
        r.campaign.validation, r.campaign.smallest_attainable_p, r.base.name, r.base.heldout_rms_dph
    );
    Outcome {
        named,
        no_test_power: r.cause_in_words.contains("no test power"),
        line,
    }
}

/// Per rule (unbuffered, buffered): records where something was named, where the
/// planted label was named, where something of another column was named, and where "no
/// test power" was said, over the seeds.
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    named: [usize; 2],
    right: [usize; 2],
    wrong_column: [usize; 2],
    no_power: [usize; 2],
    records: usize,
}

const RULES: [BufferRule; 2] = [BufferRule::None, BufferRule::FromResidual];

fn tally(law: Law, sigmas: f64) -> Tally {
    let mut t = Tally::default();
    for seed in null_seeds() {
        for (i, rule) in RULES.into_iter().enumerate() {
            let o = run(law, sigmas, seed, rule);
            println!("{} no_test_power {}", o.line, o.no_test_power);
            t.named[i] += usize::from(o.named.is_some());
            t.right[i] += usize::from(o.named.as_deref() == Some("supply_v:value"));
            t.wrong_column[i] += usize::from(
                o.named
                    .as_deref()
                    .is_some_and(|n| sigmas == 0.0 || !n.starts_with("supply_v:")),
            );
            t.no_power[i] += usize::from(o.no_test_power);
        }
        t.records += 1;
    }
    t
}

/// Both laws in parallel; prints and returns the pooled tally.
fn tallies(sigmas: f64) -> Tally {
    let out: Vec<(Law, Tally)> = std::thread::scope(|s| {
        let h: Vec<_> = [Law::CoolDown, Law::WarmUp]
            .into_iter()
            .map(|law| s.spawn(move || (law, tally(law, sigmas))))
            .collect();
        h.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut all = Tally::default();
    for (law, t) in &out {
        println!(
            "{law:?} x{sigmas}: of {} records, unbuffered / buffered: named something {} / {}, \
             the planted supply_v:value {} / {}, a wrong column {} / {}, no test power said {} / {}",
            t.records, t.named[0], t.named[1], t.right[0], t.right[1], t.wrong_column[0],
            t.wrong_column[1], t.no_power[0], t.no_power[1]
        );
        for i in 0..2 {
            all.named[i] += t.named[i];
            all.right[i] += t.right[i];
            all.wrong_column[i] += t.wrong_column[i];
            all.no_power[i] += t.no_power[i];
        }
        all.records += t.records;
    }
    all
}

/// Largest count of false names consistent with the family-wise level over `records`
/// independent records: the 99 % quantile of Binomial(records, ALPHA).
fn allowed_false_names(records: usize) -> usize {
    let alpha = fog_sim::diagnose::selection::scored::ALPHA;
    let mut cdf = 0.0;
    for k in 0..=records {
        let ln_choose: f64 = (1..=k)
            .map(|i| ((records - k + i) as f64 / i as f64).ln())
            .sum();
        cdf +=
            (ln_choose + k as f64 * alpha.ln() + (records - k) as f64 * (1.0 - alpha).ln()).exp();
        if cdf >= 0.99 {
            return k;
        }
    }
    records
}

/// The buffered rule's false names (`wrong[1]`) must stay within the level.
fn assert_within_level(t: &Tally, wrong: [usize; 2], what: &str) {
    let allowed = allowed_false_names(t.records);
    assert!(
        wrong[1] <= allowed,
        "buffered rule named {what} in {} of {} records (level allows {allowed})",
        wrong[1],
        t.records
    );
}

#[test]
fn null_single_records_with_autocorrelated_noise_name_nothing_beyond_the_level() {
    let t = tallies(0.0);
    assert_within_level(&t, t.named, "something (null)");
}

#[test]
fn a_planted_supply_effect_in_one_record_is_named_without_wrong_columns() {
    let t = tallies(2.0);
    assert_within_level(&t, t.wrong_column, "a wrong column");
    assert!(t.right[1] > 0, "the planted effect was never named");
}
