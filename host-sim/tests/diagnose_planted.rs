//! `diagnose` must find a hidden effect planted in randomised "measured" campaigns,
//! name the right column and transform with positive held-out gain, and name nothing
//! when nothing is planted, over several seeds (cases run in parallel threads).

use crate::common::planted;
use fog_sim::diagnose::diagnose;
use planted::{campaign, Effect, Shape};

use crate::common::seeds;

fn check(effect: Effect) {
    let results: Vec<String> = seeds::per_seed_parallel(|seed| {
        let (runs, expected) = campaign(effect, seed, Shape::default());
        let d = diagnose(&runs).expect("diagnose runs");
        let r = &d.report;
        let named = r
            .named_cause
            .as_ref()
            .map(|c| (c.column.clone(), c.transform.name()));
        let ok = match (&expected, &named) {
            (None, None) => true,
            (Some((c, t)), Some((nc, nt))) => c == nc && t == nt && r.extended.gain_pct > 0.0,
            _ => false,
        };
        let top: Vec<String> = r
            .candidates
            .iter()
            .take(4)
            .map(seeds::candidate_line)
            .collect();
        let between = r.between_run.rows.first().map(|x| {
            format!(
                "{} {:+.1}% fw p {:.4} perm p {:.4}",
                x.label, x.gain_pct, x.p_value, x.permutation_p
            )
        });
        let line = format!(
                        "{effect:?} seed {seed}: expected {expected:?}, named {named:?} (between runs {:?}), gain {:+.2}%, base {:.4} -> {:.4}; top {top:?}; best between-run {between:?}",
                        r.between_run.named, r.extended.gain_pct, r.base.heldout_rms_dph, r.extended.heldout_rms_dph
                    );
        let mark = if ok { "ok  " } else { "FAIL" };
        format!("{mark} {line}")
    });
    for l in &results {
        println!("{l}");
    }
    assert!(results.iter().all(|l| l.starts_with("ok")), "{results:#?}");
}

#[test]
fn finds_drift_proportional_to_a_column_value() {
    check(Effect::ColumnValue);
}

#[test]
fn finds_drift_proportional_to_a_column_rate() {
    check(Effect::ColumnRate);
}

#[test]
fn finds_the_shupe_gradient_term_d2t_dt2() {
    check(Effect::TempAccel);
}

#[test]
fn finds_a_temperature_independent_power_on_transient() {
    check(Effect::PowerOnTransient);
}

#[test]
fn finds_a_heading_dependent_magnetic_bias() {
    check(Effect::HeadingMagnetic);
}

#[test]
fn names_nothing_when_nothing_is_planted() {
    check(Effect::Null);
}
