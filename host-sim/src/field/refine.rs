//! The field correction of a chamber model (`fogsim train --field`).
//!
//! Each field record is one observation of the residual bias r (deg/h, measured after the
//! chamber model) at a temperature state x. The correction is linear in the model's own
//! plain inputs (T and dT/dt, whichever the model has) plus a constant:
//!
//!   c(x) = b0 + sum_j b_j (x_j - m_j) / s_j     (m_j, s_j: mean and std of x_j in the field)
//!
//! fitted by weighted ridge least squares: every field seek is a row of weight W, and the
//! chamber model (zero correction) enters as one prior row of weight 1 per coefficient:
//!
//!   minimise  W * sum_i (r_i - c(x_i))^2  +  sum_k b_k^2
//!
//! W = 0 leaves the chamber model alone; W -> infinity trusts the field alone (plain
//! least squares). With normalised regressors, the prior counts like 1/W field seeks per
//! coefficient. The default W is chosen from the data: leave-one-out over the field seeks
//! (each held out in turn, predicted by the fit on the others), the grid value with the
//! lowest held-out rms wins, W = 0 included, so a field that does not predict itself leaves
//! the model unchanged. With fewer than `MIN_RECORDS` records there is no test power and
//! no correction. A term whose field spread is below its floor is left out (not
//! identifiable from the field), and so is a term whose field values correlate with an
//! already kept term's beyond `MAX_TERM_CORRELATION` (T is tried first, then dT/dt): at one
//! ambient every warm-up follows the same path, T and dT/dt of the field seeks correlate at
//! r = -0.99 (`fogsim field aging`), and a fit of both makes large opposite coefficients
//! that fit the seeks' half-sums but move the difference between a seek's two positions,
//! which is its azimuth (measured: rms x1.14 on the null twin with T and dT/dt, x1.003
//! with T alone).
//!
//! d2T/dt2 is not fitted. A record's d2T/dt2 was once the least-squares slope of dT/dt over
//! the seek, which early in a warm-up differs from the model's own per-window input by
//! orders of magnitude (seek 1 of a 20 degC cold start: slope -1.5e-6 degC/s^2, window
//! inputs from +5e-4 down to -2e-5); a coefficient fitted on the one and applied to the
//! other moved seek azimuths (rms x2.5 on the null twin). A record now carries the mean of
//! the model's own window input (`SeekTempState`), what a linear correction in it averages
//! to over the seek, but no measurement has checked such a correction yet: the aging
//! measurement's chamber model (`north-seek`'s own) has no d2T/dt2 input.
//!
//! The correction is folded exactly into the model's bias and linear terms
//! (x_j = offset_j + scale_j xn_j), so the device applies it with no new code.

use anyhow::{bail, Result};
use fog_core::model::format::{FeatureKind, RbfModel};

/// Fewer field seeks than this: no test power, no correction.
pub const MIN_RECORDS: usize = 4;
/// Weights tried by leave-one-out (0: the chamber model unchanged).
pub const WEIGHT_GRID: [f64; 12] = [
    0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 1000.0, 1.0e5,
];
/// Spread below which a term is not fitted, per input kind (degC, degC/s).
const SPREAD_FLOOR: [f64; 2] = [0.05, 1.0e-5];
/// |correlation| of a term's field values with a kept term's above which it is not fitted.
pub const MAX_TERM_CORRELATION: f64 = 0.9;

/// One field observation: the model's plain inputs at the seek and its residual bias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldObservation {
    pub temp_c: f64,
    pub temp_rate_cps: f64,
    pub temp_accel_cps2: f64,
    pub residual_bias_dph: f64,
}

impl FieldObservation {
    fn input(&self, kind: usize) -> f64 {
        [self.temp_c, self.temp_rate_cps, self.temp_accel_cps2][kind]
    }
}

/// A linear term: which model input (index) carries it, which record value (0 T, 1 rate,
/// 2 accel), and its field mean and std.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Term {
    pub input: usize,
    pub kind: usize,
    pub mean: f64,
    pub std: f64,
}

/// A fitted correction.
#[derive(Clone, Debug, PartialEq)]
pub struct Correction {
    pub weight: f64,
    pub terms: Vec<Term>,
    /// b0 then one coefficient per term, deg/h.
    pub coef_dph: Vec<f64>,
    /// Model inputs the field did not fit, and why.
    pub not_fitted: Vec<String>,
}

impl Correction {
    pub fn predict_dph(&self, o: &FieldObservation) -> f64 {
        let mut c = self.coef_dph[0];
        for (t, b) in self.terms.iter().zip(&self.coef_dph[1..]) {
            c += b * (o.input(t.kind) - t.mean) / t.std;
        }
        c
    }
}

/// How the weight was chosen.
#[derive(Clone, Debug, PartialEq)]
pub struct WeightChoice {
    /// (W, leave-one-out rms of the residual bias after the correction, deg/h).
    pub loo_rms_dph: Vec<(f64, f64)>,
    pub weight: f64,
    /// `None`: too few records, nothing was chosen ("no test power").
    pub verdict: Option<&'static str>,
}

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

/// Correlation of two terms' values over the field seeks.
fn correlation(obs: &[FieldObservation], a: &Term, b: &Term) -> f64 {
    let n = obs.len().max(1) as f64;
    obs.iter()
        .map(|o| (o.input(a.kind) - a.mean) * (o.input(b.kind) - b.mean))
        .sum::<f64>()
        / (n * a.std * b.std)
}

/// Fits the correction with weight `w` on `obs` (terms fixed by the caller).
pub fn fit(obs: &[FieldObservation], terms: &[Term], w: f64) -> Correction {
    let p = terms.len() + 1;
    let mut a = vec![vec![0.0; p]; p];
    let mut b = vec![0.0; p];
    for o in obs {
        let mut z = vec![1.0];
        z.extend(terms.iter().map(|t| (o.input(t.kind) - t.mean) / t.std));
        for ((row, bi), &zi) in a.iter_mut().zip(b.iter_mut()).zip(&z) {
            *bi += w * zi * o.residual_bias_dph;
            for (x, &zk) in row.iter_mut().zip(&z) {
                *x += w * zi * zk;
            }
        }
    }
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1.0;
    }
    Correction {
        weight: w,
        terms: terms.to_vec(),
        coef_dph: solve_spd(a, b),
        not_fitted: Vec::new(),
    }
}

/// Solves the (symmetric positive definite: the prior rows make it so) normal equations.
fn solve_spd(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let p = b.len();
    for c in 0..p {
        let (top, rest) = a.split_at_mut(c + 1);
        let pivot_row = &top[c];
        let bc = b[c];
        for (row, br) in rest.iter_mut().zip(b[c + 1..].iter_mut()) {
            let f = row[c] / pivot_row[c];
            for (x, &y) in row[c..].iter_mut().zip(&pivot_row[c..]) {
                *x -= f * y;
            }
            *br -= f * bc;
        }
    }
    let mut x = vec![0.0; p];
    for c in (0..p).rev() {
        let s: f64 = (c + 1..p).map(|k| a[c][k] * x[k]).sum();
        x[c] = (b[c] - s) / a[c][c];
    }
    x
}

/// Leave-one-out rms of the residual bias after the correction fitted with `w`.
pub fn loo_rms_dph(obs: &[FieldObservation], terms: &[Term], w: f64) -> f64 {
    let mut ss = 0.0;
    for i in 0..obs.len() {
        let rest: Vec<FieldObservation> = obs
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != i)
            .map(|(_, o)| *o)
            .collect();
        let c = fit(&rest, terms, w);
        ss += (obs[i].residual_bias_dph - c.predict_dph(&obs[i])).powi(2);
    }
    (ss / obs.len().max(1) as f64).sqrt()
}

/// Chooses W by leave-one-out over the field seeks (`fixed`: use it instead, still
/// reporting the held-out rms of every grid value).
pub fn choose_weight(obs: &[FieldObservation], terms: &[Term], fixed: Option<f64>) -> WeightChoice {
    if obs.len() < MIN_RECORDS {
        return WeightChoice {
            loo_rms_dph: Vec::new(),
            weight: 0.0,
            verdict: Some("no test power: fewer field seeks than needed, model unchanged"),
        };
    }
    let loo: Vec<(f64, f64)> = WEIGHT_GRID
        .iter()
        .map(|&w| (w, loo_rms_dph(obs, terms, w)))
        .collect();
    let best = loo
        .iter()
        .copied()
        .fold((0.0, f64::INFINITY), |b, x| if x.1 < b.1 { x } else { b });
    WeightChoice {
        loo_rms_dph: loo,
        weight: fixed.unwrap_or(best.0),
        verdict: None,
    }
}

/// The model with `c` folded into its bias and linear terms.
pub fn apply(model: &RbfModel, c: &Correction) -> Result<RbfModel> {
    let mut out = model.clone();
    let mut bias = f64::from(model.bias_dph) + c.coef_dph[0];
    for (t, &b) in c.terms.iter().zip(&c.coef_dph[1..]) {
        let off = f64::from(model.input_offset[t.input]);
        let scale = f64::from(model.input_scale[t.input]);
        bias += b * (off - t.mean) / t.std;
        out.linear[t.input] = (f64::from(model.linear[t.input]) + b * scale / t.std) as f32;
    }
    out.bias_dph = bias as f32;
    if !out.bias_dph.is_finite() || out.linear.iter().any(|l| !l.is_finite()) {
        bail!("field correction is not finite: not applied");
    }
    Ok(out)
}

/// The whole refinement: terms, weight (chosen or `fixed`), fit, folded model.
pub fn refine(
    model: &RbfModel,
    obs: &[FieldObservation],
    fixed: Option<f64>,
) -> Result<(RbfModel, Correction, WeightChoice)> {
    let (terms, not_fitted) = terms_for(model, obs);
    let choice = choose_weight(obs, &terms, fixed);
    let c = Correction {
        not_fitted,
        ..fit(obs, &terms, choice.weight)
    };
    Ok((apply(model, &c)?, c, choice))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::model::rbf::predict_f64;

    fn model() -> RbfModel {
        let mut m = RbfModel::empty();
        m.n_rbf_inputs = 0;
        for (k, off, scale) in [
            (FeatureKind::TempC, 25.0f32, 10.0f32),
            (FeatureKind::TempRateCps, 0.0, 0.01),
        ] {
            m.inputs
                .push(fog_core::model::format::FeatureSpec::plain(k))
                .unwrap();
            m.input_offset.push(off).unwrap();
            m.input_scale.push(scale).unwrap();
            m.input_min.push(-100.0).unwrap();
            m.input_max.push(100.0).unwrap();
            m.linear.push(0.0).unwrap();
        }
        m.bias_dph = 0.5;
        m
    }

    fn obs(n: usize, k_dph_per_c: f64, noise: f64, seed: u64) -> Vec<FieldObservation> {
        let mut rng = fog_core::model::synthetic::SplitMix64::new(seed);
        (0..n)
            .map(|i| {
                let t = 10.0 + 30.0 * (i as f64 / n as f64);
                let u = (rng.next_u64() as f64 / u64::MAX as f64) - 0.5;
                FieldObservation {
                    temp_c: t,
                    temp_rate_cps: 0.001 * (i % 3) as f64,
                    temp_accel_cps2: 0.0,
                    residual_bias_dph: 0.01 + k_dph_per_c * (t - 25.0) + noise * u,
                }
            })
            .collect()
    }

    #[test]
    fn a_clean_aging_law_is_learnt_and_folded_exactly() {
        let m = model();
        let o = obs(40, 0.0005, 0.0, 1);
        let (refined, c, choice) = refine(&m, &o, None).unwrap();
        assert!(choice.weight >= 10.0, "{choice:?}");
        for x in &o {
            let before = predict_f64(&m, &[x.temp_c, x.temp_rate_cps]).unwrap();
            let after = predict_f64(&refined, &[x.temp_c, x.temp_rate_cps]).unwrap();
            assert!(
                (after - before - c.predict_dph(x)).abs() < 2e-6,
                "fold exact"
            );
            assert!((after - before - x.residual_bias_dph).abs() < 1e-4, "{x:?}");
        }
    }

    #[test]
    fn pure_noise_keeps_the_model_nearly_unchanged_and_few_records_have_no_power() {
        let m = model();
        let o = obs(40, 0.0, 0.02, 2)
            .into_iter()
            .map(|x| FieldObservation {
                residual_bias_dph: x.residual_bias_dph - 0.01,
                ..x
            })
            .collect::<Vec<_>>();
        let (_, c, choice) = refine(&m, &o, None).unwrap();
        let worst = o.iter().map(|x| c.predict_dph(x).abs()).fold(0.0, f64::max);
        assert!(
            worst < 0.006,
            "noise (+-0.01) mostly not learnt: {worst} {choice:?}"
        );
        let (same, _, choice) = refine(&m, &o[..3], None).unwrap();
        assert!(choice.verdict.is_some());
        assert_eq!(same, m);
    }

    #[test]
    fn collinear_terms_are_not_fitted_and_say_why() {
        // Warm-ups at one ambient: dT/dt falls as T rises (r = -1).
        let o: Vec<FieldObservation> = (0..20)
            .map(|i| FieldObservation {
                temp_c: 20.0 + 0.2 * i as f64,
                temp_rate_cps: 0.012 - 0.0005 * i as f64,
                temp_accel_cps2: 0.0,
                residual_bias_dph: 0.001 * i as f64,
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
