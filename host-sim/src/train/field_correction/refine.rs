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
//! coefficient.
//!
//! **Validated where it is used: on other power-ons.** The correction is used on the
//! device's later power-ons, at whatever ambient and warm-up they have. So the weight W and
//! the terms kept (the constant alone, + T, + T + dT/dt) are chosen together by
//! leave-one-power-on-out (`power_ons`: a record whose time since power-on does not rise
//! over the one before starts a new power-on): each power-on's seeks are held out in turn
//! and predicted by the fit on the other power-ons. For each number of terms the W with
//! the lowest held-out rms is taken (W = 0 included: the model unchanged), and of those the
//! fewest terms whose held-out mean square is within one standard error (over power-ons)
//! of the lowest (the one-standard-error rule): a term is kept only if it wins by more
//! than the power-ons' scatter (without the rule the null twin kept a T term at W = 0.1
//! that moved its azimuths by a resolved +0.4 % rms, `--ambient-c 10,20,30`, 20 seeks). A term fitted on power-ons at one ambient and held out
//! at another is scored on exactly the extrapolation it will make in use. Leave-one-seek-out
//! could not see that: the seeks of one power-on lie inside each other's range, and the
//! first version of this refinement, validated that way, fitted a T term on the 5 seeks of
//! one power-on at 10 degC that made the residual bias 4x worse at 20 and 30 degC
//! (`fogsim field aging --ambient-c 10,20,30`, Shupe twin: 0.0105 -> 0.0409 deg/h). With
//! field records from fewer than `MIN_POWER_ONS` power-ons (or fewer than `MIN_RECORDS`
//! records) nothing can be scored on another power-on: no test power, no correction. The
//! report states, per term refused, the held-out rms with and without it, and the field's
//! range of each input against the model's trained range.
//!
//! A term whose field spread is below its floor is left out (not identifiable from the
//! field), and so is a term whose field values correlate with an already kept term's beyond
//! `MAX_TERM_CORRELATION` (T is tried first, then dT/dt): at one ambient every warm-up
//! follows the same path, T and dT/dt of the field seeks correlate at r = -0.99
//! (`fogsim field aging`), and a fit of both makes large opposite coefficients that fit
//! the seeks' half-sums but move the difference between a seek's two positions, which is
//! its azimuth (measured: rms x1.14 on the null twin with T and dT/dt, x1.003 with T
//! alone); a held-out half-sum cannot see that either.
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
//! **Coverage** (`supported_terms`): the device applies a folded term over the model's
//! whole range in use, so a term is refused where, at the far end of that range, its own
//! leave-one-power-on-out standard error exceeds the records' scatter (refused, not
//! clamped: the model format has no per-term bound).
//!
//! **Azimuth score** (`HeldOut::az_rms_deg`): beside the half-sum, every candidate is
//! scored by what its held-out residual's drift between seeks does to a seek's azimuth;
//! `TERM_CRITERION` says which score chooses the terms (measured: the half-sum).
//!
//! The correction is folded exactly into the model's bias and linear terms
//! (x_j = offset_j + scale_j xn_j), so the device applies it with no new code.

use anyhow::{bail, Result};

use crate::train::seek_score::SeekGeometry;
use fog_core::compensation::compensator::CompensatorConfig;
use fog_core::model::format::{FeatureKind, RbfModel};

/// Fewer field seeks than this: no test power, no correction.
pub const MIN_RECORDS: usize = 4;
/// Fewer field power-ons than this: nothing can be scored on another power-on, no
/// correction.
pub const MIN_POWER_ONS: usize = 2;
/// Weights tried by leave-one-power-on-out (0: the chamber model unchanged).
pub const WEIGHT_GRID: [f64; 12] = [
    0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 1000.0, 1.0e5,
];
/// The grid's largest weight: the field alone (the prior rows negligible).
const FIELD_ALONE_WEIGHT: f64 = WEIGHT_GRID[WEIGHT_GRID.len() - 1];
/// Spread below which a term is not fitted, per input kind (degC, degC/s).
const SPREAD_FLOOR: [f64; 2] = [0.05, 1.0e-5];
/// |correlation| of a term's field values with a kept term's above which it is not fitted.
pub const MAX_TERM_CORRELATION: f64 = 0.9;

/// One field observation: the model's plain inputs at the seek, its residual bias, and
/// the power-on it came from (`power_ons`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldObservation {
    pub temp_c: f64,
    pub temp_rate_cps: f64,
    pub temp_accel_cps2: f64,
    pub residual_bias_dph: f64,
    pub power_on: usize,
    /// End of the seek, s since power-on (orders a power-on's seeks for the azimuth score).
    pub t_since_power_on_s: f64,
}

impl FieldObservation {
    fn input(&self, kind: usize) -> f64 {
        [self.temp_c, self.temp_rate_cps, self.temp_accel_cps2][kind]
    }
}

/// The power-on of each record, numbered from 0: records in ring order (one gyro), a
/// record whose time since power-on does not rise over the previous one's starts a new
/// power-on (the device's clock restarts at every power-on; within one, seeks follow each
/// other).
/// `records`: (gyro id, time since power-on, s) in ring order per gyro; a new gyro starts a
/// new power-on too.
pub fn power_ons(records: &[(&str, f64)]) -> Vec<usize> {
    let mut k = 0;
    records
        .iter()
        .enumerate()
        .map(|(i, &(gyro, t))| {
            if let Some(&(prev_gyro, prev_t)) = i.checked_sub(1).map(|p| &records[p]) {
                if gyro != prev_gyro || t.partial_cmp(&prev_t) != Some(std::cmp::Ordering::Greater)
                {
                    k += 1;
                }
            }
            k
        })
        .collect()
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
    /// Per candidate input: the field's range against the model's trained range.
    pub coverage: Vec<String>,
    /// Terms refused because the device would apply them beyond what the records
    /// support (`supported_terms`), one line each.
    pub coverage_refused: Vec<String>,
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

/// One candidate scored by leave-one-power-on-out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// How many of the identifiable terms (in order: T, dT/dt) it keeps.
    pub terms: usize,
    pub weight: f64,
    /// Held-out rms of the residual bias after the correction, deg/h.
    pub rms_dph: f64,
    /// Standard error of its mean square over the power-ons, (deg/h)^2.
    pub ms_se_dph2: f64,
    /// Held-out azimuth score, deg (`HeldOut::az_rms_deg`), and the standard error of its
    /// mean square over the power-ons, deg^2.
    pub az_rms_deg: f64,
    pub az_ms_se_deg2: f64,
}

/// Which held-out score chooses the number of terms (the weight of each is chosen by the
/// half-sum either way: a constant cancels in a seek's azimuth, so the azimuth score
/// cannot weigh it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TermCriterion {
    /// Held-out rms of the residual bias (the seeks' half-sums), deg/h.
    HalfSum,
    /// Held-out azimuth score, deg.
    Azimuth,
}

impl TermCriterion {
    pub fn name(self) -> &'static str {
        match self {
            TermCriterion::HalfSum => "half-sum",
            TermCriterion::Azimuth => "azimuth",
        }
    }
}

/// The criterion that chooses the terms. Measured with each (`fogsim field aging` seeds 1
/// and 2, the independent gyro's full table seeds 1 and 2): the same choices everywhere
/// except the independent gyro at seed 2, where the azimuth score drops T for the knee
/// (azimuth rms ratio 0.975 / 0.972 after 20 / 50 seeks, resolved, becomes 1.000) and adds
/// it for the gradient lag after 50 (1.000 becomes 0.984): the half-sum keeps more.
pub const TERM_CRITERION: TermCriterion = TermCriterion::HalfSum;

/// Leave-one-power-on-out scores of one candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldOut {
    pub rms_dph: f64,
    pub ms_se_dph2: f64,
    /// The azimuth consequence of the held-out residual, as `train::seek_score` converts a
    /// slow drift error: the held-out residual's change between a power-on's consecutive
    /// seeks, scaled to one seek dwell (what separates a seek's two positions), over
    /// 2 Omega_H at the site latitude (`SeekGeometry`: `train`'s `--seek-dwell-s` and
    /// `--seek-latitude-deg`; |sin psi| = 1): the error a residual
    /// that drifts along the warm-up puts into the difference of a seek's positions, which
    /// the half-sum cannot see. rms over the pairs, deg (0 with no pair).
    pub az_rms_deg: f64,
    pub az_ms_se_deg2: f64,
}

/// How the weight and the terms were chosen.
#[derive(Clone, Debug, PartialEq)]
pub struct WeightChoice {
    /// Power-ons the field records come from.
    pub power_ons: usize,
    /// Kinds of the identifiable terms (0 T, 1 dT/dt), in the order candidates add them.
    pub kinds: Vec<usize>,
    /// Every candidate, scored by leave-one-power-on-out (empty: no test power).
    pub candidates: Vec<Candidate>,
    pub weight: f64,
    /// Identifiable terms kept (the first this many).
    pub terms_kept: usize,
    /// The terms each criterion chose (`TERM_CRITERION` decides which is kept).
    pub terms_by_half_sum: usize,
    pub terms_by_azimuth: usize,
    pub criterion: TermCriterion,
    /// `None`: too few records or power-ons, nothing was chosen ("no test power").
    pub verdict: Option<String>,
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
        coverage: Vec::new(),
        coverage_refused: Vec::new(),
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

/// Leave-one-power-on-out scores of the correction fitted with `w` on `terms` (each
/// power-on's records predicted by the fit on the other power-ons'): rms of the residual
/// bias and the azimuth score, each with the standard error of its mean square over the
/// power-ons.
pub fn held_out(obs: &[FieldObservation], terms: &[Term], w: f64, seek: SeekGeometry) -> HeldOut {
    let groups = obs.iter().map(|o| o.power_on).max().map_or(0, |g| g + 1);
    let (mut per_group_ms, mut per_group_az) = (Vec::new(), Vec::new());
    let (mut ss, mut az_ss, mut az_n) = (0.0, 0.0, 0usize);
    for g in 0..groups {
        let rest: Vec<FieldObservation> = obs.iter().filter(|o| o.power_on != g).copied().collect();
        let c = fit(&rest, terms, w);
        let held: Vec<(f64, f64)> = obs
            .iter()
            .filter(|o| o.power_on == g)
            .map(|o| (o.t_since_power_on_s, o.residual_bias_dph - c.predict_dph(o)))
            .collect();
        if held.is_empty() {
            continue;
        }
        let sq: f64 = held.iter().map(|(_, e)| e * e).sum();
        ss += sq;
        per_group_ms.push(sq / held.len() as f64);
        let az: Vec<f64> = held
            .windows(2)
            .filter(|p| p[1].0 > p[0].0)
            .map(|p| {
                let drift_dph = (p[1].1 - p[0].1) / (p[1].0 - p[0].0) * seek.dwell_s;
                seek.azimuth_deg(drift_dph).powi(2)
            })
            .collect();
        if !az.is_empty() {
            az_ss += az.iter().sum::<f64>();
            az_n += az.len();
            per_group_az.push(az.iter().sum::<f64>() / az.len() as f64);
        }
    }
    let se = |v: &[f64]| {
        if v.len() >= 2 {
            crate::stats::std_dev(v) / (v.len() as f64).sqrt()
        } else {
            f64::INFINITY
        }
    };
    HeldOut {
        rms_dph: (ss / obs.len().max(1) as f64).sqrt(),
        ms_se_dph2: se(&per_group_ms),
        az_rms_deg: (az_ss / az_n.max(1) as f64).sqrt(),
        az_ms_se_deg2: if az_n == 0 { 0.0 } else { se(&per_group_az) },
    }
}

/// Chooses W and the terms kept (the constant alone, then each of `terms` added in
/// order) by leave-one-power-on-out (`fixed`: that W, the terms still chosen; every
/// candidate's held-out rms is reported).
pub fn choose_weight(
    obs: &[FieldObservation],
    terms: &[Term],
    fixed: Option<f64>,
    seek: SeekGeometry,
) -> WeightChoice {
    let mut distinct: Vec<usize> = obs.iter().map(|o| o.power_on).collect();
    distinct.sort_unstable();
    distinct.dedup();
    let power_ons = distinct.len();
    let kinds: Vec<usize> = terms.iter().map(|t| t.kind).collect();
    let none = |verdict: String| WeightChoice {
        power_ons,
        kinds: kinds.clone(),
        candidates: Vec::new(),
        weight: 0.0,
        terms_kept: 0,
        terms_by_half_sum: 0,
        terms_by_azimuth: 0,
        criterion: TERM_CRITERION,
        verdict: Some(verdict),
    };
    if obs.len() < MIN_RECORDS {
        return none(format!(
            "no test power: {} field seeks, at least {MIN_RECORDS} needed; model unchanged \
             (run more seeks, `fogsim field pull` them, then `train --field` again)",
            obs.len()
        ));
    }
    if power_ons < MIN_POWER_ONS {
        return none(format!(
            "no test power: the {} field seeks come from {power_ons} power-on; the correction \
             is used on other power-ons (other ambients and warm-ups) and leave-one-power-on-out \
             needs at least {MIN_POWER_ONS} to score it there; model unchanged (record seeks \
             after another power-on, at another ambient if you can, `fogsim field pull` them, \
             then `train --field` again)",
            obs.len()
        ));
    }
    // Power-ons renumbered 0.. so that every group is held out once.
    let obs: Vec<FieldObservation> = obs
        .iter()
        .map(|o| FieldObservation {
            power_on: distinct.binary_search(&o.power_on).unwrap_or(0),
            ..*o
        })
        .collect();
    let weights: Vec<f64> = match fixed {
        Some(w) => vec![w],
        None => WEIGHT_GRID.to_vec(),
    };
    let mut candidates = Vec::new();
    for k in 0..=terms.len() {
        for &w in &weights {
            let h = held_out(&obs, &terms[..k], w, seek);
            candidates.push(Candidate {
                terms: k,
                weight: w,
                rms_dph: h.rms_dph,
                ms_se_dph2: h.ms_se_dph2,
                az_rms_deg: h.az_rms_deg,
                az_ms_se_deg2: h.az_ms_se_deg2,
            });
        }
    }
    // The best W for each number of terms (the smaller W on a tie) ...
    let best_of = |k: usize| {
        candidates.iter().filter(|c| c.terms == k).copied().fold(
            None::<Candidate>,
            |b, c| match b {
                Some(b) if b.rms_dph <= c.rms_dph => Some(b),
                _ => Some(c),
            },
        )
    };
    let bests: Vec<Candidate> = (0..=terms.len()).filter_map(best_of).collect();
    // ... and the fewest terms within one standard error of the lowest, once on the
    // half-sums, once on the azimuth score.
    let by_half_sum = fewest_within_se(&bests, |c| (c.rms_dph.powi(2), c.ms_se_dph2));
    let by_azimuth = fewest_within_se(&bests, |c| (c.az_rms_deg.powi(2), c.az_ms_se_deg2));
    let chosen = match TERM_CRITERION {
        TermCriterion::HalfSum => by_half_sum,
        TermCriterion::Azimuth => by_azimuth,
    };
    let best = chosen.unwrap_or(Candidate {
        terms: 0,
        weight: 0.0,
        rms_dph: f64::NAN,
        ms_se_dph2: f64::NAN,
        az_rms_deg: f64::NAN,
        az_ms_se_deg2: f64::NAN,
    });
    WeightChoice {
        power_ons,
        kinds,
        candidates,
        weight: best.weight,
        terms_kept: best.terms,
        terms_by_half_sum: by_half_sum.map_or(0, |c| c.terms),
        terms_by_azimuth: by_azimuth.map_or(0, |c| c.terms),
        criterion: TERM_CRITERION,
        verdict: None,
    }
}

/// Of `bests` (one per number of terms, fewest first), the fewest terms whose held-out
/// mean square (`score`: mean square, its standard error) is within one standard error of
/// the lowest (the one-standard-error rule): a term must win by more than the power-ons'
/// scatter to be kept.
fn fewest_within_se(
    bests: &[Candidate],
    score: impl Fn(&Candidate) -> (f64, f64),
) -> Option<Candidate> {
    let lowest = bests
        .iter()
        .map(&score)
        .fold(None::<(f64, f64)>, |b, s| match b {
            Some(b) if b.0 <= s.0 => Some(b),
            _ => Some(s),
        });
    lowest.and_then(|(ms, se)| bests.iter().copied().find(|c| score(c).0 <= ms + se))
}

/// The lowest held-out rms over the candidates that keep exactly `k` terms.
fn best_rms_with(choice: &WeightChoice, k: usize) -> f64 {
    choice
        .candidates
        .iter()
        .filter(|c| c.terms == k)
        .map(|c| c.rms_dph)
        .fold(f64::INFINITY, f64::min)
}

/// Per candidate input: the field's range against the model's trained range.
fn coverage(model: &RbfModel, obs: &[FieldObservation]) -> Vec<String> {
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

/// The whole refinement: terms, weight and terms kept (chosen, or at a `fixed` W), fit,
/// folded model.
pub fn refine(
    model: &RbfModel,
    obs: &[FieldObservation],
    fixed: Option<f64>,
    seek: SeekGeometry,
) -> Result<(RbfModel, Correction, WeightChoice)> {
    let (identifiable, mut not_fitted) = terms_for(model, obs);
    let (terms, coverage_refused) = supported_terms(model, obs, &identifiable);
    let choice = choose_weight(obs, &terms, fixed, seek);
    if choice.verdict.is_none() {
        let without = best_rms_with(&choice, choice.terms_kept);
        for (k, t) in terms.iter().enumerate().skip(choice.terms_kept) {
            not_fitted.push(format!(
                "{} (leave-one-power-on-out over {} power-ons: held-out rms {:.5} dph with it, \
                 {without:.5} without; kept only if better by more than one standard error)",
                kind_name(t.kind),
                choice.power_ons,
                best_rms_with(&choice, k + 1)
            ));
        }
    }
    let c = Correction {
        not_fitted,
        coverage: coverage(model, obs),
        coverage_refused,
        ..fit(obs, &terms[..choice.terms_kept], choice.weight)
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
        // Trained ranges: T 10 .. 40 degC, dT/dt -0.003 .. 0.015 degC/s.
        for (k, off, scale, lo, hi) in [
            (FeatureKind::TempC, 25.0f32, 10.0f32, 10.0f32, 40.0f32),
            (FeatureKind::TempRateCps, 0.0, 0.01, -0.003, 0.015),
        ] {
            m.inputs
                .push(fog_core::model::format::FeatureSpec::plain(k))
                .unwrap();
            m.input_offset.push(off).unwrap();
            m.input_scale.push(scale).unwrap();
            m.input_min.push(lo).unwrap();
            m.input_max.push(hi).unwrap();
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
                    // 8 power-ons, each over its own part of the T range.
                    power_on: i * 8 / n,
                    t_since_power_on_s: 300.0 * (1 + i % (n / 8).max(1)) as f64,
                }
            })
            .collect()
    }

    #[test]
    fn a_clean_aging_law_is_learnt_and_folded_exactly() {
        let m = model();
        let o = obs(40, 0.0005, 0.0, 1);
        let (refined, c, choice) = refine(&m, &o, None, SeekGeometry::default_site()).unwrap();
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
    fn the_azimuth_score_is_taken_at_the_seeks_of_the_site() {
        let o = obs(40, 0.0005, 0.02, 3);
        let here = SeekGeometry::default_site();
        let north = SeekGeometry {
            dwell_s: 2.0 * here.dwell_s,
            latitude_deg: 60.0,
        };
        let (a, b) = (held_out(&o, &[], 0.0, here), held_out(&o, &[], 0.0, north));
        assert!(a.az_rms_deg > 0.0, "{a:?}");
        assert_eq!(a.rms_dph, b.rms_dph, "the half-sum does not depend on it");
        // Twice the dwell doubles the drift between positions; Omega_H scales by cos(lat).
        let expect = 2.0 * here.latitude_deg.to_radians().cos() / 60f64.to_radians().cos();
        assert!(
            (b.az_rms_deg / a.az_rms_deg - expect).abs() < 1e-9,
            "{} vs {expect}",
            b.az_rms_deg / a.az_rms_deg
        );
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
        let (_, c, choice) = refine(&m, &o, None, SeekGeometry::default_site()).unwrap();
        let worst = o.iter().map(|x| c.predict_dph(x).abs()).fold(0.0, f64::max);
        assert!(
            worst < 0.006,
            "noise (+-0.01) mostly not learnt: {worst} {choice:?}"
        );
        let (same, _, choice) = refine(&m, &o[..3], None, SeekGeometry::default_site()).unwrap();
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

    /// `model()` without its dT/dt input.
    fn t_only_model() -> RbfModel {
        let mut m = model();
        m.inputs.pop();
        m.input_offset.pop();
        m.input_scale.pop();
        m.input_min.pop();
        m.input_max.pop();
        m.linear.pop();
        m
    }

    #[test]
    fn a_term_is_applied_only_as_far_as_the_records_support_it() {
        // The gyro aged by a T law (+ record noise, +-0.004 deg/h); the model is used over
        // T 8.5 .. 41.5 degC (trained 10 .. 40 plus the compensator's margin).
        let m = t_only_model();
        let noisy = |seed: u64, k_dph_per_c: f64| {
            let mut rng = fog_core::model::synthetic::SplitMix64::new(seed);
            move |t: f64, _| {
                k_dph_per_c * (t - 20.0) + 0.008 * (rng.next_u64() as f64 / u64::MAX as f64 - 0.5)
            }
        };
        let at = |model: &RbfModel, t: f64| predict_f64(model, &[t]).unwrap();
        // Four power-ons near 10 degC (records 11.2 .. 17.7 degC): the T term fits there,
        // but carried to 41.5 degC its own standard error exceeds the records' scatter:
        // refused, one line says so, the model moves by its constant only (the same change
        // at 12 and at 40 degC).
        let one_ambient = warm_ups(&[10.0, 10.4, 9.7, 10.2], noisy(4, 0.001));
        let (refined, c, choice) =
            refine(&m, &one_ambient, None, SeekGeometry::default_site()).unwrap();
        assert!(choice.verdict.is_none(), "{choice:?}");
        assert!(choice.kinds.is_empty() && c.terms.is_empty(), "{c:?}");
        assert_eq!(c.coverage_refused.len(), 1, "{c:?}");
        eprintln!("field coverage: {}", c.coverage_refused[0]);
        assert!(
            c.coverage_refused[0].starts_with("T refused: the records span 11.2"),
            "{c:?}"
        );
        let moved_40 = at(&refined, 40.0) - at(&m, 40.0);
        let moved_12 = at(&refined, 12.0) - at(&m, 12.0);
        assert!((moved_40 - moved_12).abs() < 1e-6, "{moved_40} {moved_12}");
        // Twin: power-ons at 10, 20, 30 and 10 degC (records 11.5 .. 37.3 degC): T kept,
        // and the refined model follows the law at 40 degC.
        let three = warm_ups(&[10.0, 20.0, 30.0, 10.0], noisy(4, 0.001));
        let (refined, c, choice) = refine(&m, &three, None, SeekGeometry::default_site()).unwrap();
        assert!(c.coverage_refused.is_empty(), "{c:?}");
        assert_eq!(choice.terms_kept, 1, "{choice:?}");
        let moved_40 = at(&refined, 40.0) - at(&m, 40.0);
        assert!((moved_40 - 0.02).abs() < 0.003, "{moved_40}");
        // Null twin: the same power-ons, no aging (noise only): supported, but no term
        // wins on the held-out power-ons.
        let null = warm_ups(&[10.0, 20.0, 30.0, 10.0], noisy(5, 0.0));
        let (_, c, choice) = refine(&m, &null, None, SeekGeometry::default_site()).unwrap();
        assert!(c.coverage_refused.is_empty(), "{c:?}");
        assert_eq!(choice.terms_kept, 0, "{choice:?}");
    }

    /// Warm-ups from `ambients_c` (one power-on each, 6 seeks): T rises from the ambient,
    /// dT/dt falls; the residual is `law` of (T, dT/dt).
    fn warm_ups(ambients_c: &[f64], mut law: impl FnMut(f64, f64) -> f64) -> Vec<FieldObservation> {
        let mut out = Vec::new();
        for (p, &a) in ambients_c.iter().enumerate() {
            for k in 0..6 {
                let rate = 0.011 * (-(k as f64) / 1.5).exp();
                let t = a + 6.0 * (1.0 - (-(k as f64) / 1.5).exp()) + 1.5;
                out.push(FieldObservation {
                    temp_c: t,
                    temp_rate_cps: rate,
                    temp_accel_cps2: 0.0,
                    residual_bias_dph: law(t, rate),
                    power_on: p,
                    t_since_power_on_s: 300.0 * (k + 1) as f64,
                });
            }
        }
        out
    }

    #[test]
    fn a_term_is_scored_on_other_power_ons_and_one_power_on_has_no_test_power() {
        // A T-only model; the gyro's aging is in dT/dt (Shupe), which within one warm-up
        // looks like a T law (T and dT/dt correlate at r = -1 there).
        let m = t_only_model();
        let shupe = |_t: f64, rate: f64| 1.4 * rate;
        // One power-on at 10 degC: nothing can be scored at another ambient.
        let one = warm_ups(&[10.0], shupe);
        let (same, c, choice) = refine(&m, &one, None, SeekGeometry::default_site()).unwrap();
        assert!(
            choice
                .verdict
                .as_deref()
                .unwrap_or("")
                .contains("1 power-on"),
            "{choice:?}"
        );
        assert_eq!(same, m);
        assert!(c.coverage[0].starts_with("T: field"), "{c:?}");
        // Power-ons at 10, 20, 30 degC: a T slope fitted on two ambients mispredicts the
        // third; the T term is refused and says why.
        let three = warm_ups(&[10.0, 20.0, 30.0, 10.0], shupe);
        let (_, c, choice) = refine(&m, &three, None, SeekGeometry::default_site()).unwrap();
        assert_eq!(choice.power_ons, 4);
        assert_eq!(choice.terms_kept, 0, "{choice:?}");
        assert!(
            c.not_fitted
                .iter()
                .any(|n| n.starts_with("T (leave-one-power-on-out")),
            "{c:?}"
        );
        // Twin: the aging is a T law; the same power-ons keep T and learn its slope.
        let tempco = warm_ups(&[10.0, 20.0, 30.0, 10.0], |t, _| 0.001 * (t - 20.0));
        let (_, c, choice) = refine(&m, &tempco, None, SeekGeometry::default_site()).unwrap();
        assert_eq!(choice.terms_kept, 1, "{choice:?}");
        let slope = c.coef_dph[1] / c.terms[0].std;
        assert!((slope - 0.001).abs() < 1e-4, "{slope}");
        // Power-on numbering: the clock falls or a gyro changes.
        assert_eq!(
            power_ons(&[
                ("a", 270.0),
                ("a", 540.0),
                ("a", 270.0),
                ("b", 540.0),
                ("b", 540.0)
            ]),
            vec![0, 0, 1, 2, 3]
        );
    }
}
