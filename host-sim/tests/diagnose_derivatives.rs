//! Derivatives on a quantised thermometer (issue 9, item 3): a d2T/dt2 drift term at 1
//! noise sigma, hidden in campaigns of the independent generator (`common/independent.rs`,
//! `Hidden::TempAccel`: a critically damped gyro under a cycling chamber, 1 Hz rows, a
//! 0.0625 degC thermometer), must be named `temp_c:accel` by the family-wise decision, and
//! its null twin (the same cycling campaigns, nothing hidden) must name nothing. The
//! chosen derivative windows and, for the named cause, the device's causal estimate are
//! printed per seed. Seeds: `DIAG_SEEDS` (default 11, 22, 33).

use crate::common::independent;
use fog_sim::diagnose::diagnose;
use independent::{campaign, Hidden};

use crate::common::seeds;

/// One line per seed: (right?, what happened).
fn per_seed(hidden: Hidden) -> Vec<(bool, String)> {
    seeds::per_seed_parallel(|seed| {
        let (runs, expected) = campaign(hidden, seed);
        let r = diagnose(&runs).expect("diagnose runs").report;
        let named = r.named_cause.as_ref().map(|c| c.label());
        // a named derivative must come with the device's causal estimate and
        // its measured delay (half the trailing span for a least-squares fit)
        let causal_ok = r.causal_derivative.as_ref().is_some_and(|c| {
            !c.causal.is_empty()
                && c.causal
                    .iter()
                    .all(|k| (k.delay_s - k.span_s / 2.0).abs() < 1.0)
        });
        let ok = named.as_deref() == expected
            && (expected.is_none() || (r.extended.gain_pct > 0.0 && causal_ok));
        let accel = r
            .candidates
            .iter()
            .position(|c| c.column == "temp_c" && c.transform.name() == "accel")
            .map(|i| (i + 1, &r.candidates[i]));
        let widths: Vec<String> = r
            .derivative_widths
            .iter()
            .filter(|w| w.column == "temp_c")
            .map(|w| format!("{} +/-{:.0} s", w.derivative, w.half_width_s))
            .collect();
        let line = format!(
                "{hidden:?} seed {seed}: named {named:?}; temp_c:accel rank {:?} gain {:+.2}% p {:.4}; base {}; \
                 base dT/dt +/-{:.0} s; temp_c windows {widths:?}; top {:?} {:+.2}% p {:.4}",
                accel.map(|a| a.0),
                accel.map_or(f64::NAN, |a| a.1.gain_pct),
                accel.map_or(f64::NAN, |a| a.1.p_value),
                r.base.name,
                r.base.rate_half_width_s,
                r.candidates.first().map(|c| fog_core::compensation::label::feature_label(&c.column, c.transform.name(), c.tau_s).to_string()),
                r.candidates.first().map_or(f64::NAN, |c| c.gain_pct),
                r.candidates.first().map_or(f64::NAN, |c| c.p_value),
            );
        let causal = r.causal_derivative.as_ref().map(|c| {
            let k: Vec<String> = c
                .causal
                .iter()
                .map(|k| {
                    format!(
                        "span {:.0} s delay {:.1} s gain {:+.2}%",
                        k.span_s, k.delay_s, k.gain_pct
                    )
                })
                .collect();
            format!("centred {:+.2}% vs causal {k:?}", c.centred_gain_pct)
        });
        let line = format!("{line}; causal: {causal:?}");
        (ok, line)
    })
}

fn check(hidden: Hidden) {
    let lines = per_seed(hidden);
    for (ok, l) in &lines {
        println!("{} {l}", if *ok { "ok  " } else { "FAIL" });
    }
    assert!(lines.iter().all(|(ok, _)| *ok), "see the FAIL lines above");
}

#[test]
fn a_one_sigma_d2t_dt2_term_on_a_quantised_thermometer_is_named() {
    check(Hidden::TempAccel(1.0));
}

#[test]
fn its_null_twin_names_nothing() {
    check(Hidden::TempAccel(0.0));
}
