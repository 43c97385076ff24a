//! Which terms the field can carry: the model inputs a correction can use, those the field
//! records identify (spread, collinearity), those the records support over the range the
//! device applies them (coverage), and the coverage lines. One job: the terms offered to
//! the weight choice (`weight`), before any of them is chosen.

use fog_core::compensation::compensator::CompensatorConfig;
use fog_core::model::format::{FeatureKind, RbfModel};

use super::fit::{fit, FieldObservation, Term, FIELD_ALONE_WEIGHT};

/// Spread below which a term is not fitted, per input kind (degC, degC/s).
const SPREAD_FLOOR: [f64; 2] = [0.05, 1.0e-5];
/// |correlation| of a term's field values with a kept term's above which it is not fitted.
pub const MAX_TERM_CORRELATION: f64 = 0.9;

/// Name of a record value (0 T, 1 dT/dt).
pub fn kind_name(kind: usize) -> &'static str {
    ["T", "dT/dt"][kind]
}

/// The model inputs a correction can use: plain T and dT/dt (T first).
fn candidate_terms(model: &RbfModel) -> Vec<(usize, usize)> {
    let mut terms = model
        .inputs
        .iter()
        .enumerate()
        .filter_map(|(j, s)| {
            let kind = match s.kind {
                FeatureKind::TempC => 0,
                FeatureKind::TempRateCps if s.tau_s == 0.0 => 1,
                FeatureKind::TempRateDiffusionCps => 1,
                _ => return None,
            };
            Some((j, kind))
        })
        .collect::<Vec<_>>();
    terms.sort_by_key(|&(_, kind)| kind);
    terms
}

/// The terms the field can identify (spread above the floor, not collinear with a kept
/// term), and a note for each model input left out.
pub fn terms_for(model: &RbfModel, obs: &[FieldObservation]) -> (Vec<Term>, Vec<String>) {
    let n = obs.len().max(1) as f64;
    let mut notes: Vec<String> = model
        .inputs
        .iter()
        .filter(|s| {
            matches!(
                s.kind,
                FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2
            )
        })
        .map(|_| "d2T/dt2 (no measurement has checked a field correction in it yet)".into())
        .collect();
    let mut terms: Vec<Term> = Vec::new();
    for (input, kind) in candidate_terms(model) {
        let mean = obs.iter().map(|o| o.input(kind)).sum::<f64>() / n;
        let std = (obs
            .iter()
            .map(|o| (o.input(kind) - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        if std <= SPREAD_FLOOR[kind] {
            notes.push(format!(
                "{} (field spread {std:.2e} below {:.0e})",
                kind_name(kind),
                SPREAD_FLOOR[kind]
            ));
            continue;
        }
        let term = Term {
            input,
            kind,
            mean,
            std,
        };
        if let Some((kept, r)) = terms
            .iter()
            .map(|k| (k, correlation(obs, k, &term)))
            .find(|(_, r)| r.abs() > MAX_TERM_CORRELATION)
        {
            notes.push(format!(
                "{} (collinear with {} in the field, r = {r:+.3})",
                kind_name(kind),
                kind_name(kept.kind)
            ));
            continue;
        }
        terms.push(term);
    }
    (terms, notes)
}

/// The field records' range of a record value (0 T, 1 dT/dt).
fn field_range(obs: &[FieldObservation], kind: usize) -> (f64, f64) {
    obs.iter()
        .map(|o| o.input(kind))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        })
}

/// Where the device applies a term in model input `input`: the compensator clamps every
/// input to the trained range widened by its margin
/// (`CompensatorConfig::range_margin_frac`), so a term folded into the model's linear
/// coefficients acts as a straight line over all of that range.
fn range_in_use(model: &RbfModel, input: usize) -> (f64, f64) {
    let (lo, hi) = (
        f64::from(model.input_min[input]),
        f64::from(model.input_max[input]),
    );
    let margin = f64::from(CompensatorConfig::default().range_margin_frac) * (hi - lo);
    (lo - margin, hi + margin)
}

/// The leave-one-power-on-out (jackknife) standard error, deg/h, of what the term `t`
/// (fitted with the constant on the field alone) adds at input value `x`: each power-on
/// left out in turn, the term's contribution at `x` refitted on the others.
pub fn term_se_at_dph(obs: &[FieldObservation], t: &Term, x: f64) -> f64 {
    let mut groups: Vec<usize> = obs.iter().map(|o| o.power_on).collect();
    groups.sort_unstable();
    groups.dedup();
    if groups.len() < 2 {
        return f64::INFINITY;
    }
    let at_x: Vec<f64> = groups
        .iter()
        .map(|&g| {
            let rest: Vec<FieldObservation> =
                obs.iter().filter(|o| o.power_on != g).copied().collect();
            fit(&rest, std::slice::from_ref(t), FIELD_ALONE_WEIGHT).coef_dph[1] * (x - t.mean)
                / t.std
        })
        .collect();
    let g = at_x.len() as f64;
    let mean = at_x.iter().sum::<f64>() / g;
    ((g - 1.0) / g * at_x.iter().map(|d| (d - mean).powi(2)).sum::<f64>()).sqrt()
}

/// The terms the device may apply: a term is refused when, at the far end of where the
/// device applies it (`range_in_use`), its own leave-one-power-on-out standard error
/// (`term_se_at_dph`) exceeds the records' scatter (std of their residual biases): out
/// there the term would add more uncertainty than the whole error the refinement works
/// against. One line for each refused.
///
/// Why refuse and not clamp: the correction reaches the device folded into the model's
/// bias and linear coefficients (`apply`), which the firmware evaluates as they are over
/// the whole trained range (its compensator clamps inputs to that range only); the model
/// format has no per-term bound, so a clamp to the records' range would be a new format
/// and new firmware code, and the model the host scored would not be the one the device
/// runs until both exist. The threshold is the data's own: the term's standard error
/// against the records' scatter. Records from one ambient span a few degC of one warm-up
/// path: a T slope from them, carried 20 degC further, is uncertain by more than the
/// records scatter, and is refused however well it fits there; records from three
/// ambients span the range and keep it.
pub fn supported_terms(
    model: &RbfModel,
    obs: &[FieldObservation],
    terms: &[Term],
) -> (Vec<Term>, Vec<String>) {
    let n = obs.len().max(1) as f64;
    let mean_r = obs.iter().map(|o| o.residual_bias_dph).sum::<f64>() / n;
    let scatter = (obs
        .iter()
        .map(|o| (o.residual_bias_dph - mean_r).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let mut refused = Vec::new();
    let kept = terms
        .iter()
        .copied()
        .filter(|t| {
            let (lo, hi) = field_range(obs, t.kind);
            let (ulo, uhi) = range_in_use(model, t.input);
            let far = if (ulo - t.mean).abs() > (uhi - t.mean).abs() {
                ulo
            } else {
                uhi
            };
            let se = term_se_at_dph(obs, t, far);
            if se <= scatter {
                return true;
            }
            refused.push(format!(
                "{name} refused: the records span {lo:.4} .. {hi:.4}, the device applies the \
                 model over {ulo:.4} .. {uhi:.4}; at {far:.4} the term's leave-one-power-on-out \
                 standard error is {se:.5} dph, more than the records' scatter {scatter:.5} dph \
                 (record seeks at other ambients to support it)",
                name = kind_name(t.kind)
            ));
            false
        })
        .collect();
    (kept, refused)
}

/// Correlation of two terms' values over the field seeks.
fn correlation(obs: &[FieldObservation], a: &Term, b: &Term) -> f64 {
    let n = obs.len().max(1) as f64;
    obs.iter()
        .map(|o| (o.input(a.kind) - a.mean) * (o.input(b.kind) - b.mean))
        .sum::<f64>()
        / (n * a.std * b.std)
}

/// Per candidate input: the field's range against the model's trained range.
pub(super) fn coverage(model: &RbfModel, obs: &[FieldObservation]) -> Vec<String> {
    candidate_terms(model)
        .into_iter()
        .map(|(input, kind)| {
            let (lo, hi) = field_range(obs, kind);
            let (tlo, thi) = (
                f64::from(model.input_min[input]),
                f64::from(model.input_max[input]),
            );
            let covered = (hi.min(thi) - lo.max(tlo)).max(0.0) / (thi - tlo);
            format!(
                "{}: field {lo:.4} .. {hi:.4}, trained {tlo:.4} .. {thi:.4} ({:.0} % of the trained range)",
                kind_name(kind),
                100.0 * covered
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::train::field_correction::test_fixtures::model;

    #[test]
    fn collinear_terms_are_not_fitted_and_say_why() {
        // Warm-ups at one ambient: dT/dt falls as T rises (r = -1).
        let o: Vec<FieldObservation> = (0..20)
            .map(|i| FieldObservation {
                temp_c: 20.0 + 0.2 * i as f64,
                temp_rate_cps: 0.012 - 0.0005 * i as f64,
                temp_accel_cps2: 0.0,
                residual_bias_dph: 0.001 * i as f64,
                power_on: i / 5,
                t_since_power_on_s: 300.0 * (1 + i % 5) as f64,
            })
            .collect();
        let (terms, notes) = terms_for(&model(), &o);
        assert_eq!(terms.iter().map(|t| t.kind).collect::<Vec<_>>(), vec![0]);
        assert!(notes[0].starts_with("dT/dt (collinear with T"), "{notes:?}");
        // Twin: independent T and dT/dt are both fitted.
        let spread: Vec<FieldObservation> = o
            .iter()
            .enumerate()
            .map(|(i, x)| FieldObservation {
                temp_rate_cps: 0.001 * ((i * 7) % 5) as f64,
                ..*x
            })
            .collect();
        let (terms, notes) = terms_for(&model(), &spread);
        assert_eq!(terms.len(), 2, "{notes:?}");
    }
}
