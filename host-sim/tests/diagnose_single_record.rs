//! Single long records validated on time blocks: with strongly autocorrelated drift noise
//! (AR(1) bias wander or a rate random walk) and nothing planted, the family-wise rule
//! must not name anything more often than its level allows, and a real planted effect in
//! one record must be named without naming wrong columns more often than the level
//! allows (its power is low here and measured, see docs/record/diagnose.md). Two generators with
//! different physical laws (`common/single_record.rs`).
//!
//! The fast guards run 3 records per law with the buffered rule: the null names nothing
//! beyond the level, and a 4-sigma effect is named on its column in at least one record
//! (measured: 2 of 6, as a spline of `supply_v`). The qualification (slow suite, `cargo
//! test -- --include-ignored`) runs 20 records per law at 2 sigma with the buffered rule;
//! `SINGLE_BOTH_RULES=1` runs the unbuffered rule (before issue 9 item 5) next to it, for
//! the comparison in docs/record/diagnose.md (it asserts nothing on the old rule).

use crate::common::single_record;
use fog_sim::diagnose::diagnose_with;
use fog_sim::diagnose::validation::buffer::BufferRule;
use single_record::{record, Law};

/// Seeds of the qualification (slow suite): 20 per law, `SINGLE_SEEDS=N` for more.
fn qualification_seeds() -> Vec<u64> {
    let n = std::env::var("SINGLE_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20u64);
    (1..=n).collect()
}

/// Seeds of the fast guards: enough records that a rule naming something in a third of
/// null records, or a planted 4-sigma effect never named, fails.
const FAST_SEEDS: [u64; 3] = [1, 2, 3];

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
    let top = r
        .candidates
        .first()
        .map(crate::common::seeds::candidate_line);
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
    right_column: [usize; 2],
    wrong_column: [usize; 2],
    no_power: [usize; 2],
    records: usize,
}

/// Both rules (the unbuffered one for comparison, docs/record/diagnose.md), or the
/// buffered one alone (index 1 of the tally, as in the qualification).
const BOTH_RULES: [BufferRule; 2] = [BufferRule::None, BufferRule::FromResidual];
const BUFFERED_ONLY: [BufferRule; 1] = [BufferRule::FromResidual];

/// The qualification's rules: the buffered one, or both with `SINGLE_BOTH_RULES=1`.
fn qualification_rules() -> &'static [BufferRule] {
    if std::env::var("SINGLE_BOTH_RULES").is_ok_and(|v| v == "1") {
        &BOTH_RULES
    } else {
        &BUFFERED_ONLY
    }
}

fn tally(law: Law, sigmas: f64, seeds: &[u64], rules: &[BufferRule]) -> Tally {
    let mut t = Tally::default();
    for &seed in seeds {
        for (k, &rule) in rules.iter().enumerate() {
            let i = k + 2 - rules.len();
            let o = run(law, sigmas, seed, rule);
            println!("{} no_test_power {}", o.line, o.no_test_power);
            t.named[i] += usize::from(o.named.is_some());
            t.right[i] += usize::from(o.named.as_deref() == Some("supply_v:value"));
            t.right_column[i] += usize::from(
                o.named
                    .as_deref()
                    .is_some_and(|n| sigmas > 0.0 && n.starts_with("supply_v:")),
            );
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
fn tallies(sigmas: f64, seeds: &[u64], rules: &[BufferRule]) -> Tally {
    let out: Vec<(Law, Tally)> = std::thread::scope(|s| {
        let h: Vec<_> = [Law::CoolDown, Law::WarmUp]
            .into_iter()
            .map(|law| s.spawn(move || (law, tally(law, sigmas, seeds, rules))))
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
            all.right_column[i] += t.right_column[i];
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
    crate::common::level::binomial_upper(records, fog_sim::diagnose::selection::scored::ALPHA, 0.99)
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
fn null_single_records_name_nothing_beyond_the_level() {
    let t = tallies(0.0, &FAST_SEEDS, &BUFFERED_ONLY);
    assert_within_level(&t, t.named, "something (null)");
}

#[test]
fn a_planted_four_sigma_supply_effect_is_named_without_wrong_columns() {
    let t = tallies(4.0, &FAST_SEEDS, &BUFFERED_ONLY);
    assert_within_level(&t, t.wrong_column, "a wrong column");
    assert!(
        t.right_column[1] > 0,
        "the planted effect's column was never named"
    );
}

#[test]
#[ignore = "slow suite: 40 null records (cargo test -- --include-ignored)"]
fn qualification_null_single_records_with_autocorrelated_noise_name_nothing_beyond_the_level() {
    let t = tallies(0.0, &qualification_seeds(), qualification_rules());
    assert_within_level(&t, t.named, "something (null)");
}

#[test]
#[ignore = "slow suite: 40 records with a 2-sigma effect (cargo test -- --include-ignored)"]
fn qualification_a_planted_supply_effect_in_one_record_is_named_without_wrong_columns() {
    let t = tallies(2.0, &qualification_seeds(), qualification_rules());
    assert_within_level(&t, t.wrong_column, "a wrong column");
    assert!(t.right[1] > 0, "the planted effect was never named");
}
