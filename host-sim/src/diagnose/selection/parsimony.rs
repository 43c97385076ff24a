//! Parsimony (issue 18 item 6): the base is the simplest whose held-out score is within
//! one standard error of the lowest one's, judged twice: as a base (the standard error of
//! the lowest score), and then with the causes the selection names on it against the
//! lowest base with the causes named on that one (the standard error of the paired
//! per-unit difference: the two are scored on the same validation units).
//!
//! Why twice: an effect that no base contains stays in every base's residual and spreads
//! the per-unit scores, so at the base stage a base too simple for the drift (T without
//! T^2) sits within one standard error of the lowest; the effect's own test then runs on
//! a residual that still holds the simpler base's misfit and loses its power. Measured
//! (docs/record/diagnose.md, "Parsimony (item 6)"): a 1-sigma (supply_v - 24) x dT/dt product,
//! +29.7 % and p 0.0005 on poly_t2_rate, fell to +19.1 % and p 0.024 on poly_t1_rate,
//! whose base score was 0.00020 deg/h (0.3 of a standard error) above poly_t2_rate's but
//! 0.0046 deg/h (4 paired standard errors) above it once the product was in.
//!
//! Why the paired standard error for the second: where nothing is named within runs the
//! two scores are the bases' own, and the lowest score's standard error let poly_t2_rate
//! replace poly_t3_rate where T^3 was better in every run but by little; the shared law's
//! run levels then lost a 1-sigma `# mount` offset (p 0.0054 -> 0.020) and a 1-sigma
//! heading harmonic (`diagnose_between`, p 0.0001 -> 0.123). The paired form keeps a
//! difference that holds in every unit, however small.
//!
//! Cost: one more selection for each simpler base within one standard error as a base,
//! simplest first, until one is within it with its causes too.

use crate::diagnose::baseline::choice::{complexity, BaseChoice, BaseScore};
use crate::diagnose::baseline::levels::{ratio_estimate, score};
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::candidates::transforms::Candidate;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::selection::screen::{screen, Screening};
use crate::diagnose::validation::folds::Folds;
use serde::Serialize;

/// The rule, as the report states it.
pub const RULE: &str = "simplest base within one standard error of the lowest held-out rms (that score's), and with the causes named on each within one standard error (of the paired difference) of the lowest with its causes";

/// One simpler base weighed against the lowest: alone and with its named causes.
#[derive(Clone, Debug, Serialize)]
pub struct Weighed {
    pub base: String,
    /// Its held-out rms minus the lowest's, and the lowest score's standard error, deg/h
    /// (bases alone).
    pub base_excess_dph: f64,
    pub base_excess_se_dph: f64,
    /// The same with the causes named on each, with the standard error of the paired
    /// difference (None when the base alone is already beyond one standard error and was
    /// not screened).
    pub whole_excess_dph: Option<f64>,
    pub whole_excess_se_dph: Option<f64>,
    /// Within-run causes named on this base.
    pub causes: Vec<String>,
    /// Within one standard error, alone and with its causes.
    pub within_one_se: bool,
}

/// How the base was chosen, for the report (`base.rule`).
#[derive(Clone, Debug, Serialize)]
pub struct BaseRule {
    /// The rule in words ([`RULE`]).
    pub rule: String,
    /// The base with the lowest held-out rms.
    pub lowest: String,
    /// Its held-out rms with the causes named on it, deg/h.
    pub lowest_whole_rms_dph: f64,
    /// The simpler bases weighed, simplest first, up to the one chosen.
    pub weighed: Vec<Weighed>,
    /// Why the chosen base is the chosen one.
    pub reason: String,
}

/// `a`'s held-out rms minus `b`'s and the standard error of that difference: `a` and `b`
/// are per-unit held-out SSEs on the same units of `points` rows each (ratio estimator
/// over units as `levels::score`, delta method to the rms).
pub fn excess(a: &[f64], b: &[f64], points: &[f64]) -> (f64, f64) {
    let rms_a = score(a, points).heldout_rms_dph;
    let rms_b = score(b, points).heldout_rms_dph;
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let (_, var) = ratio_estimate(&d, points);
    (rms_a - rms_b, var.sqrt() / (2.0 * rms_b.max(1e-300)))
}

/// Chooses the base (module header) and runs the selection on it: returns the choice,
/// its selection and how it was chosen. `choice.chosen` comes in as the lowest-rms base;
/// `groups` and `max_steps` as [`screen`].
pub fn choose_and_screen(
    campaign: &Campaign,
    folds: &Folds,
    st: &Stacked,
    choice: BaseChoice,
    library: &[Candidate],
    groups: f64,
    max_steps: usize,
) -> Result<(BaseChoice, Screening, BaseRule), DiagnoseError> {
    let points: Vec<f64> = folds.unit_rows.iter().map(|r| r.len() as f64).collect();
    let select = |c: &BaseChoice| {
        screen(
            campaign,
            folds,
            &c.chosen,
            library.to_vec(),
            groups,
            max_steps,
        )
    };
    let lowest_screen = select(&choice)?;
    let lowest = choice.chosen.spec.name.clone();
    let lowest_whole = lowest_screen.final_cv(&choice.chosen).unit_sse.clone();
    let mut rule = BaseRule {
        rule: RULE.into(),
        lowest: lowest.clone(),
        lowest_whole_rms_dph: score(&lowest_whole, &points).heldout_rms_dph,
        weighed: Vec::new(),
        reason: String::new(),
    };
    let Some((lowest_rms, lowest_se)) = choice
        .scores
        .iter()
        .find(|s| s.spec.name == lowest)
        .map(|s| (s.heldout_rms_dph, s.heldout_se_dph))
    else {
        return Ok((choice, lowest_screen, rule));
    };
    let mut simpler: Vec<&BaseScore> = choice
        .scores
        .iter()
        .filter(|s| complexity(&s.spec) < complexity(&choice.chosen.spec))
        .collect();
    simpler.sort_by(|a, b| {
        complexity(&a.spec)
            .cmp(&complexity(&b.spec))
            .then(a.heldout_rms_dph.total_cmp(&b.heldout_rms_dph))
    });
    for s in simpler {
        let base_excess = s.heldout_rms_dph - lowest_rms;
        let base_se = lowest_se;
        let mut w = Weighed {
            base: s.spec.name.clone(),
            base_excess_dph: base_excess,
            base_excess_se_dph: base_se,
            whole_excess_dph: None,
            whole_excess_se_dph: None,
            causes: vec![],
            within_one_se: false,
        };
        let within_alone = base_excess <= base_se;
        if !within_alone {
            rule.weighed.push(w);
            continue;
        }
        let candidate = choice.with_chosen(folds, st, &s.spec)?;
        let sc = select(&candidate)?;
        let whole = &sc.final_cv(&candidate.chosen).unit_sse;
        let (whole_excess, whole_se) = excess(whole, &lowest_whole, &points);
        w.whole_excess_dph = Some(whole_excess);
        w.whole_excess_se_dph = Some(whole_se);
        w.causes = sc
            .steps
            .iter()
            .map(|step| step.scored.cand.label())
            .collect();
        w.within_one_se = whole_excess <= whole_se;
        let within = w.within_one_se;
        rule.weighed.push(w);
        if within {
            rule.reason = format!(
                "{} is the simplest base within one standard error of {lowest} (the lowest), alone ({:+.5} +/- {:.5} deg/h) and with the causes named on each ({whole_excess:+.5} +/- {whole_se:.5} deg/h){}",
                s.spec.name,
                base_excess,
                base_se,
                as_simple_and_as_good(&choice.scores, &s.spec, lowest_rms, lowest_se)
            );
            return Ok((candidate, sc, rule));
        }
    }
    rule.reason = format!(
        "{lowest} has the lowest held-out rms; no simpler base is within one standard error of it, alone and with the causes named on each{}",
        as_simple_and_as_good(&choice.scores, &choice.chosen.spec, lowest_rms, lowest_se)
    );
    Ok((choice, lowest_screen, rule))
}

/// The bases with as many terms as `chosen` whose held-out rms is also within one standard
/// error of the lowest, as a clause for the rule's reason (empty when there are none): the
/// record cannot tell them from the chosen one, and a reader who expects one of them (a
/// quadratic in T where the chosen base has T and dT/dt) should see that it fits as well.
fn as_simple_and_as_good(
    scores: &[BaseScore],
    chosen: &crate::diagnose::baseline::choice::BaseSpec,
    lowest_rms: f64,
    lowest_se: f64,
) -> String {
    let equals: Vec<String> = scores
        .iter()
        .filter(|b| {
            b.spec.name != chosen.name
                && complexity(&b.spec) == complexity(chosen)
                && b.heldout_rms_dph - lowest_rms <= lowest_se
        })
        .map(|b| format!("{} ({:.5} deg/h)", b.spec.name, b.heldout_rms_dph))
        .collect();
    if equals.is_empty() {
        String::new()
    } else {
        format!(
            "; as many terms and also within one standard error: {} (the record cannot tell them from {}; the choice between them is by held-out rms alone)",
            equals.join(", "),
            chosen.name
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base(name: &str, degree: Option<u8>, rate: bool, rms: f64) -> BaseScore {
        BaseScore {
            spec: crate::diagnose::baseline::choice::BaseSpec {
                name: name.into(),
                poly_degree_t: degree,
                uses_rate: rate,
                rbf: false,
            },
            heldout_rms_dph: rms,
            heldout_se_dph: 1.0,
            levels: vec![],
            parameters: 0,
            paired_p_vs_best: None,
            unit_sse: vec![],
        }
    }

    /// A quadratic in T as good as T with dT/dt (the PAN record's x axis) is said, with as
    /// many terms; a simpler or a worse base is not.
    #[test]
    fn a_base_with_as_many_terms_and_as_good_is_named_beside_the_chosen_one() {
        let scores = vec![
            base("poly_t1", Some(1), false, 31.8),
            base("poly_t1_rate", Some(1), true, 23.7),
            base("poly_t2", Some(2), false, 24.8),
            base("poly_t2_rate", Some(2), true, 24.0),
        ];
        let said = as_simple_and_as_good(&scores, &scores[1].spec, 23.7, 4.0);
        assert!(said.contains("poly_t2 (24.80000 deg/h)"), "{said}");
        assert!(
            !said.contains("poly_t1 ") && !said.contains("poly_t2_rate"),
            "{said}"
        );
        assert_eq!(
            as_simple_and_as_good(&scores, &scores[1].spec, 23.7, 0.5),
            ""
        );
    }

    /// The paired standard error sees a difference that is the same in every unit (so
    /// real however small), which the spread of the scores themselves hides; and a
    /// difference that changes sign from unit to unit gets a standard error as large as
    /// itself or more.
    #[test]
    fn the_paired_standard_error_tells_a_steady_difference_from_a_noisy_one() {
        let points = vec![100.0; 8];
        let lowest: Vec<f64> = (0..8).map(|u| 0.01 * (1.0 + u as f64)).collect();
        let steady: Vec<f64> = lowest.iter().map(|v| v + 0.001).collect();
        let (d, se) = excess(&steady, &lowest, &points);
        assert!(d > 0.0 && se < 1e-9, "{d} +/- {se}");
        let spread = score(&lowest, &points).standard_error_dph;
        assert!(
            d < spread,
            "hidden by the scores' own spread: {d} vs {spread}"
        );
        let noisy: Vec<f64> = lowest
            .iter()
            .enumerate()
            .map(|(u, v)| v + if u % 2 == 0 { 0.003 } else { -0.002 })
            .collect();
        let (d, se) = excess(&noisy, &lowest, &points);
        assert!(d > 0.0 && se > d, "{d} +/- {se}");
        let (d, se) = excess(&lowest, &lowest, &points);
        assert_eq!((d, se), (0.0, 0.0));
    }
}
