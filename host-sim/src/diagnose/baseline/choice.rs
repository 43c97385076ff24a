//! Choosing the base model from the data before any candidate is screened: a base that is
//! too weak lets artefacts (lags of T, power-on decays) rank first; one that is too rich
//! is worse held out. Tried, all with one free offset per run: constant; polynomial in T
//! of degree 1-3, each with and without dT/dt as a linear term; the paper's RBF on
//! (T, dT/dt). Each is validated on held-out data the same way (same folds, ridge chosen
//! from the same grid). The lowest held-out rms is the reference; the base the diagnosis
//! runs on is the simplest within one standard error of it, alone and with the causes
//! named on it (`selection::parsimony`, issue 18 item 6). Every score, its standard error
//! and the paired p that the lowest beats it are reported.

use crate::diagnose::baseline::levels::{score, Law, LevelSystems, Score};
use crate::diagnose::baseline::models::{fit_rbf, Stacked, RIDGES};
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::validation::cv::{CvResult, Prepared};
use crate::diagnose::validation::design::Design;
use crate::diagnose::validation::folds::Folds;
use serde::Serialize;

/// Highest polynomial degree in T tried.
pub const MAX_POLY_DEGREE: u8 = 3;
/// |correlation| of T with time (within a run) above which the record is called one
/// monotonic ramp: T, time and any lag of T are then nearly the same regressor.
pub const RAMP_CORRELATION: f64 = 0.98;

/// What a base model is made of.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BaseSpec {
    /// `constant`, `poly_t3_rate`, `rbf_t_rate`, ...
    pub name: String,
    /// Polynomial degree in T (None for the constant and the RBF).
    pub poly_degree_t: Option<u8>,
    /// Whether dT/dt is an input.
    pub uses_rate: bool,
    /// Whether this is the paper's RBF.
    pub rbf: bool,
}

impl BaseSpec {
    /// The input labels, as the report lists them.
    pub fn inputs(&self) -> Vec<String> {
        let mut v = Vec::new();
        if self.rbf || self.poly_degree_t.is_some() {
            v.push("temp_c:value".to_owned());
        }
        if self.uses_rate {
            v.push("temp_c:rate".to_owned());
        }
        v
    }
}

/// A fitted and validated base.
#[derive(Clone, Debug)]
pub struct BaseFit {
    pub spec: BaseSpec,
    pub prepared: Prepared,
    pub cv: CvResult,
    /// RBF centres (0 for polynomial bases).
    pub centres: usize,
    pub width_factor: f64,
    pub ridge: f64,
    /// The RBF basis (None for polynomial and constant bases).
    pub basis: Option<crate::diagnose::baseline::rbf_basis::RbfBasis>,
}

impl BaseFit {
    /// The base's design (rows computed on demand) before run offsets are removed.
    pub fn raw_design(&self) -> std::sync::Arc<dyn Design> {
        self.prepared.design()
    }
}

/// One base's held-out score, for the report.
#[derive(Clone, Debug, Serialize)]
pub struct BaseScore {
    #[serde(flatten)]
    pub spec: BaseSpec,
    /// Within runs (free offsets, residual about each held-out run's mean).
    pub heldout_rms_dph: f64,
    /// Its standard error over the validation units.
    pub heldout_se_dph: f64,
    /// Absolute held-out scores (levels included) of the law shared across runs and of
    /// free offsets (`levels`; empty when runs are too few to hold out whole).
    pub levels: Vec<LevelScore>,
    /// Parameters of the within-run law (`complexity`), for the parsimony rule.
    pub parameters: usize,
    /// One-sided paired sign-flip p that the lowest-rms base is better than this one over
    /// the validation units (None for that base itself).
    pub paired_p_vs_best: Option<f64>,
    /// Held-out squared error per validation unit (the parsimony rule's paired
    /// differences).
    #[serde(skip)]
    pub unit_sse: Vec<f64>,
}

/// One level treatment's absolute held-out score.
#[derive(Clone, Debug, Serialize)]
pub struct LevelScore {
    pub law: Law,
    #[serde(flatten)]
    pub score: Score,
    /// Law columns plus level parameters (1 shared intercept, or one offset per run).
    pub parameters: usize,
    /// Offsets the law fitted on every run leaves (per run), deg/h.
    #[serde(skip)]
    pub offsets_left: Vec<f64>,
    /// Run-level standard deviation left by the shared law (the turn-on repeatability as
    /// a variance component), deg/h; NaN for free offsets.
    pub sigma_u_dph: f64,
    /// Quasi-demeaning of the shared law, chosen on held-out runs (1 for free offsets).
    pub theta: f64,
    /// The law's per-run sums (between-run candidates are refitted inside it).
    #[serde(skip)]
    pub systems: Option<std::sync::Arc<LevelSystems>>,
}

/// Which base and level treatment holds across runs (`levels`), chosen on held-out runs
/// by the one-standard-error rule.
#[derive(Clone, Debug, Serialize)]
pub struct LevelChoice {
    pub base: String,
    pub law: Law,
    #[serde(flatten)]
    pub score: Score,
    /// Best absolute held-out rms over every base and treatment, and its standard error.
    pub best_heldout_rms_dph: f64,
    pub best_standard_error_dph: f64,
    pub best: String,
    /// Offsets the chosen law leaves (per run), deg/h: the between-run stage's data.
    #[serde(skip)]
    pub offsets_left: Vec<f64>,
    /// Turn-on repeatability, deg/h: the variance component of the shared law, else the
    /// spread of the free offsets about their mean.
    pub repeatability_dph: f64,
    pub theta: f64,
    #[serde(skip)]
    pub systems: Option<std::sync::Arc<LevelSystems>>,
}

/// The chosen base, every score, and the collinearity warning if any.
#[derive(Clone, Debug)]
pub struct BaseChoice {
    pub chosen: BaseFit,
    pub scores: Vec<BaseScore>,
    pub collinearity_warning: Option<String>,
    /// The level treatment (None for time-block layouts: runs are not held out whole).
    pub levels: Option<LevelChoice>,
}

/// Significance (paired sign flips over validation units) a dT/dt window other than the
/// device's must reach to replace it in the base.
pub const RATE_WINDOW_ALPHA: f64 = 0.05;

/// Half-width of the base's default dT/dt window: the device's least-squares span, centred, s.
pub fn device_rate_half_s() -> f64 {
    fog_core::compensation::features::DEFAULT_RATE_SPAN_S / 2.0
}

/// The base and the window of its dT/dt. By default dT/dt is the device's least-squares
/// span (fog-core `DEFAULT_RATE_SPAN_S`, the `TempRateCps` input the deployed model runs
/// on), centred. The temperature's own leave-one-out window (`derivatives`) replaces it
/// when the best base with it is better held out in significantly many validation units
/// (paired sign flips, `RATE_WINDOW_ALPHA`), as a coarse thermometer needs: a base whose
/// choice flips on noise would move every candidate's p-value. Returns the stacked
/// campaign with the chosen dT/dt.
///
/// `device` is the campaign stacked with the device's span (`device_rate_half_s`) and the
/// base chosen on it with `folds` (already computed when the folds were laid out).
pub fn choose_with_rate_window(
    campaign: &crate::diagnose::input::Campaign,
    folds: &Folds,
    (mut st, device): (Stacked, BaseChoice),
) -> Result<(Stacked, BaseChoice), DiagnoseError> {
    let device_half_s = st.temp_rate_half_s;
    let loo_half_s = campaign.half_width_s("temp_c", 1);
    if (loo_half_s - device_half_s).abs() < 1e-9 {
        return Ok((st, device));
    }
    // Only dT/dt differs between the two stacks: it is swapped in, and back if the
    // device's window stays (memory: never two stacked campaigns).
    let loo_rate = std::sync::Arc::new(Stacked::rate_column(campaign, loo_half_s));
    let device_rate = std::mem::replace(&mut st.temp_rate_cps, loo_rate);
    st.temp_rate_half_s = loo_half_s;
    let back_to_device = |mut st: Stacked| {
        st.temp_rate_cps = device_rate;
        st.temp_rate_half_s = device_half_s;
        st
    };
    let Ok(loo) = choose(folds, &st) else {
        return Ok((back_to_device(st), device));
    };
    let gains =
        crate::diagnose::validation::signflip::unit_gains(&device.chosen.cv, &loo.chosen.cv);
    let p = crate::diagnose::validation::signflip::paired_pvalue(
        &gains,
        crate::diagnose::validation::signflip::FLIP_SEED,
    );
    if loo.chosen.cv.rms() < device.chosen.cv.rms() && p < RATE_WINDOW_ALPHA {
        Ok((st, loo))
    } else {
        Ok((back_to_device(st), device))
    }
}

/// Mean and (population) standard deviation used to normalise a column (1 when constant).
pub fn zscore_params(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n).sqrt();
    (m, if sd > 1e-300 { sd } else { 1.0 })
}

fn zscore(v: &[f64]) -> Vec<f64> {
    let (m, sd) = zscore_params(v);
    v.iter().map(|x| (x - m) / sd).collect()
}

/// A stacked column (shared, never copied) with the mean and standard deviation that
/// normalise it (`zscore_params`).
#[derive(Debug)]
struct Normalised {
    values: std::sync::Arc<Vec<f64>>,
    mean: f64,
    sd: f64,
}

impl Normalised {
    fn new(values: &std::sync::Arc<Vec<f64>>) -> Self {
        let (mean, sd) = zscore_params(values);
        Self {
            values: values.clone(),
            mean,
            sd,
        }
    }

    fn at(&self, i: usize) -> f64 {
        (self.values[i] - self.mean) / self.sd
    }
}

/// A polynomial base's design, rows on demand from the stacked columns: z, z^2, ..
/// z^degree of normalised T, then normalised dT/dt.
#[derive(Debug)]
struct PolyRows {
    temp: Normalised,
    degree: u8,
    /// dT/dt, when the base uses it.
    rate: Option<Normalised>,
}

impl PolyRows {
    fn new(st: &Stacked, degree: u8, uses_rate: bool) -> Self {
        Self {
            temp: Normalised::new(&st.temp_c),
            degree,
            rate: uses_rate.then(|| Normalised::new(&st.temp_rate_cps)),
        }
    }
}

impl Design for PolyRows {
    fn width(&self) -> usize {
        usize::from(self.degree) + usize::from(self.rate.is_some())
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        let z = self.temp.at(i);
        let d = usize::from(self.degree);
        for (k, o) in out[..d].iter_mut().enumerate() {
            *o = z.powi(k as i32 + 1);
        }
        if let Some(rate) = &self.rate {
            out[d] = rate.at(i);
        }
    }
}

/// Fits a linear-in-parameters base choosing the ridge on held-out data. Its rows are
/// computed on demand (memory: nothing per row is held but the fit's own target).
fn fit_linear(
    folds: &Folds,
    spec: BaseSpec,
    design: std::sync::Arc<dyn Design>,
    y: &[f64],
) -> Result<BaseFit, DiagnoseError> {
    let mut prepared = Prepared::from_design(folds, design, y, RIDGES[0]);
    let mut best: Option<(f64, f64)> = None;
    for (ridge, cv) in RIDGES
        .into_iter()
        .zip(prepared.validate_ridges(folds, &RIDGES))
    {
        let Ok(cv) = cv else {
            continue;
        };
        if best.is_none_or(|b| cv.rms() < b.1) {
            best = Some((ridge, cv.rms()));
        }
    }
    let (ridge, _) = best.ok_or(DiagnoseError::Singular { what: "base fit" })?;
    prepared.set_ridge(ridge);
    let cv = prepared.validate(folds)?;
    Ok(BaseFit {
        spec,
        prepared,
        cv,
        centres: 0,
        width_factor: 0.0,
        ridge,
        basis: None,
    })
}

/// Every base spec tried, simplest first.
pub fn specs() -> Vec<BaseSpec> {
    let mut v = vec![BaseSpec {
        name: "constant".into(),
        poly_degree_t: None,
        uses_rate: false,
        rbf: false,
    }];
    for d in 1..=MAX_POLY_DEGREE {
        for uses_rate in [false, true] {
            v.push(BaseSpec {
                name: format!("poly_t{d}{}", if uses_rate { "_rate" } else { "" }),
                poly_degree_t: Some(d),
                uses_rate,
                rbf: false,
            });
        }
    }
    v.push(BaseSpec {
        name: "rbf_t_rate".into(),
        poly_degree_t: None,
        uses_rate: true,
        rbf: true,
    });
    v
}

/// Fits one base.
pub fn fit(folds: &Folds, st: &Stacked, spec: &BaseSpec) -> Result<BaseFit, DiagnoseError> {
    if spec.rbf {
        let r = fit_rbf(
            folds,
            vec![st.temp_c.clone(), st.temp_rate_cps.clone()],
            Vec::new(),
            &st.y,
        )?;
        return Ok(BaseFit {
            spec: spec.clone(),
            prepared: r.prepared,
            cv: r.cv,
            centres: r.centres,
            width_factor: r.width_factor,
            ridge: r.ridge,
            basis: Some(r.basis),
        });
    }
    let design = PolyRows::new(st, spec.poly_degree_t.unwrap_or(0), spec.uses_rate);
    fit_linear(folds, spec.clone(), std::sync::Arc::new(design), &st.y)
}

/// Within-run parameters of a base: polynomial degree + 1 for dT/dt (the constant 0);
/// the RBF counts as the most complex. Reported beside every score.
pub fn complexity(spec: &BaseSpec) -> usize {
    if spec.rbf {
        return usize::MAX;
    }
    usize::from(spec.poly_degree_t.unwrap_or(0)) + usize::from(spec.uses_rate)
}

/// Fits every base and returns the one with the lowest held-out rms as `chosen`; every
/// base's score, standard error, per-unit errors and paired p against the lowest are kept.
/// The base the diagnosis runs on is then chosen by parsimony among these
/// (`selection::parsimony`: the simplest within one standard error of the lowest, alone and
/// with the causes named on it), which needs the selection and so lives a stage above.
pub fn choose(folds: &Folds, st: &Stacked) -> Result<BaseChoice, DiagnoseError> {
    // Each base is scored as it is fitted and only the best so far is kept (memory: a
    // fitted base holds its design, n x columns).
    let mut chosen: Option<BaseFit> = None;
    let mut scores: Vec<BaseScore> = Vec::new();
    for spec in specs() {
        let Ok(f) = fit(folds, st, &spec) else {
            continue;
        };
        scores.push(BaseScore {
            spec: f.spec.clone(),
            heldout_rms_dph: f.cv.rms(),
            heldout_se_dph: unit_score(folds, &f.cv).standard_error_dph,
            levels: level_scores(folds, st, &f),
            parameters: complexity(&f.spec),
            paired_p_vs_best: None,
            unit_sse: f.cv.unit_sse.clone(),
        });
        if chosen.as_ref().is_none_or(|c| f.cv.rms() < c.cv.rms()) {
            chosen = Some(f);
        }
    }
    let chosen = chosen.ok_or(DiagnoseError::Singular { what: "every base" })?;
    paired_against_best(&mut scores, &chosen.spec.name);
    Ok(BaseChoice {
        levels: choose_levels(&scores, &chosen.spec.name),
        chosen,
        scores,
        collinearity_warning: ramp_warning(folds, st),
    })
}

impl BaseChoice {
    /// The same scores with `spec` fitted as the chosen base, and its level treatment
    /// (the parsimony rule, `selection::parsimony`, weighs simpler bases with it).
    pub fn with_chosen(
        &self,
        folds: &Folds,
        st: &Stacked,
        spec: &BaseSpec,
    ) -> Result<BaseChoice, DiagnoseError> {
        Ok(BaseChoice {
            levels: choose_levels(&self.scores, &spec.name),
            chosen: fit(folds, st, spec)?,
            scores: self.scores.clone(),
            collinearity_warning: self.collinearity_warning.clone(),
        })
    }
}

/// Fills every base's one-sided paired sign-flip p that the lowest-rms base `best` beats
/// it over the validation units.
fn paired_against_best(scores: &mut [BaseScore], best: &str) {
    let Some(lowest) = scores
        .iter()
        .find(|s| s.spec.name == best)
        .map(|s| s.unit_sse.clone())
    else {
        return;
    };
    for s in scores.iter_mut().filter(|s| s.spec.name != best) {
        let gains: Vec<f64> = s
            .unit_sse
            .iter()
            .zip(&lowest)
            .map(|(other, lowest)| other - lowest)
            .collect();
        s.paired_p_vs_best = Some(crate::diagnose::validation::signflip::paired_pvalue(
            &gains,
            crate::diagnose::validation::signflip::FLIP_SEED,
        ));
    }
}

/// The within-run held-out score with its standard error over validation units.
fn unit_score(folds: &Folds, cv: &CvResult) -> Score {
    let pts: Vec<f64> = folds.unit_rows.iter().map(|r| r.len() as f64).collect();
    score(&cv.unit_sse, &pts)
}

/// Both level treatments of one base, scored leaving one run out (run-grouped layouts).
fn level_scores(folds: &Folds, st: &Stacked, f: &BaseFit) -> Vec<LevelScore> {
    if folds.offsets != crate::diagnose::validation::folds::Offsets::PerUnit {
        return vec![];
    }
    let design = f.raw_design();
    let lv = std::sync::Arc::new(LevelSystems::new(
        &folds.run_rows,
        design.as_ref(),
        &st.y,
        f.ridge,
    ));
    let pts = lv.run_points();
    let all = vec![1.0; lv.runs()];
    let mut out = Vec::new();
    if let Some((sse, fit)) = lv
        .heldout_shared()
        .and_then(|(sse, th)| Some((sse, lv.solve_shared(&all, th)?)))
    {
        out.push(LevelScore {
            law: Law::Shared,
            score: score(&sse, &pts),
            parameters: design.width() + 1,
            offsets_left: lv.offsets_left(&fit.w),
            sigma_u_dph: fit.sigma_u_dph,
            theta: fit.theta,
            systems: Some(lv.clone()),
        });
    }
    if let (Some(sse), Some(w)) = (lv.heldout_free(), lv.solve_free(&all)) {
        out.push(LevelScore {
            law: Law::Free,
            score: score(&sse, &pts),
            parameters: design.width() + lv.runs(),
            offsets_left: lv.offsets_left(&w),
            sigma_u_dph: f64::NAN,
            theta: 1.0,
            systems: None,
        });
    }
    out
}

/// For the chosen base (`chosen`, the within-run law): the simpler level treatment
/// (fewer parameters: the shared law) when its absolute held-out rms is within one
/// standard error of the better of the two, else free offsets. (Choosing over every
/// base by absolute score was tried: the level part is a small share of the absolute
/// error, so the one-standard-error rule then picked laws too simple for the levels,
/// e.g. T alone, leaving temperature in the offsets.)
fn choose_levels(scores: &[BaseScore], chosen: &str) -> Option<LevelChoice> {
    let all: Vec<(&BaseScore, &LevelScore)> = scores
        .iter()
        .filter(|b| b.spec.name == chosen)
        .flat_map(|b| b.levels.iter().map(move |l| (b, l)))
        .filter(|(_, l)| l.score.heldout_rms_dph.is_finite())
        .collect();
    let best = all.iter().min_by(|a, b| {
        a.1.score
            .heldout_rms_dph
            .total_cmp(&b.1.score.heldout_rms_dph)
    })?;
    let limit = best.1.score.heldout_rms_dph + best.1.score.standard_error_dph.max(0.0);
    let (b, l) = all
        .iter()
        .filter(|(_, l)| l.score.heldout_rms_dph <= limit)
        .min_by_key(|(_, l)| l.parameters)?;
    let repeatability_dph = match l.law {
        Law::Shared => l.sigma_u_dph,
        Law::Free => {
            let m = l.offsets_left.iter().sum::<f64>() / l.offsets_left.len().max(1) as f64;
            (l.offsets_left.iter().map(|o| (o - m).powi(2)).sum::<f64>()
                / (l.offsets_left.len().max(2) - 1) as f64)
                .sqrt()
        }
    };
    Some(LevelChoice {
        base: b.spec.name.clone(),
        law: l.law,
        score: l.score,
        best_heldout_rms_dph: best.1.score.heldout_rms_dph,
        best_standard_error_dph: best.1.score.standard_error_dph,
        best: format!("{} ({})", best.0.spec.name, law_name(best.1.law)),
        offsets_left: l.offsets_left.clone(),
        repeatability_dph,
        theta: l.theta,
        systems: l.systems.clone(),
    })
}

/// "shared law" / "free offsets", for the report.
pub fn law_name(law: Law) -> &'static str {
    match law {
        Law::Shared => "one law across runs + random turn-on offset",
        Law::Free => "free run offsets",
    }
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let za = zscore(a);
    let zb = zscore(b);
    za.iter().zip(&zb).map(|(x, y)| x * y).sum::<f64>() / a.len().max(1) as f64
}

/// Warns when T is nearly a monotonic function of time in every run (one ramp): then T,
/// time, power-on decays and lags of T are nearly collinear and no data can say which
/// of them the drift follows.
pub fn ramp_warning(folds: &Folds, st: &Stacked) -> Option<String> {
    let corrs: Vec<f64> = folds
        .run_rows
        .iter()
        .map(|r| correlation(&st.temp_c[r.clone()], &st.t_s[r.clone()]).abs())
        .collect();
    let min = corrs.iter().copied().fold(f64::INFINITY, f64::min);
    (min > RAMP_CORRELATION).then(|| {
        format!(
            "T is nearly a straight function of time in every run (|corr(T, t)| >= {min:.3}): T, time, power-on \
             decays and lags of T are nearly collinear; a named T-lag or decay may be any of them"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn a_cubic_law_picks_a_polynomial_and_a_flat_one_the_constant() {
        let lens = [120usize; 6];
        let folds = Folds::new(&lens).unwrap();
        let n = folds.rows();
        let temp: Vec<f64> = (0..n)
            .map(|i| {
                let run = (i / 120) as f64;
                let k = (i % 120) as f64;
                -20.0 + 10.0 * run + 15.0 * (1.0 - (-k / 40.0).exp()) + (k * 0.7).sin()
            })
            .collect();
        let t_s: Vec<f64> = (0..n).map(|i| 10.0 * (i % 120) as f64).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let white: Vec<f64> = (0..n).map(|_| rng.random::<f64>() - 0.5).collect();
        let noise = |i: usize| 0.01 * white[i];
        let mk = |y: Vec<f64>| Stacked {
            temp_rate_cps: std::sync::Arc::new(temp.iter().map(|t| t.sin()).collect()),
            temp_rate_half_s: 0.0,
            y,
            t_s: t_s.clone(),
            temp_c: std::sync::Arc::new(temp.clone()),
            run_lengths: lens.to_vec(),
        };
        let cubic = mk((0..n)
            .map(|i| 1e-4 * temp[i].powi(3) + 0.01 * temp[i] + noise(i) + (i / 120) as f64)
            .collect());
        let c = choose(&folds, &cubic).unwrap();
        assert_eq!(c.chosen.spec.poly_degree_t, Some(3), "{:?}", c.scores);
        assert_eq!(c.scores.len(), specs().len());
        let flat = mk((0..n).map(|i| noise(i) + (i / 120) as f64).collect());
        let c = choose(&folds, &flat).unwrap();
        let constant = c.scores[0].heldout_rms_dph;
        assert_eq!(c.scores[0].spec.name, "constant");
        assert!(
            c.chosen.cv.rms() > 0.99 * constant,
            "nothing to find, yet {:?} gains on the constant: {:?}",
            c.chosen.spec,
            c.scores
        );
    }
}
