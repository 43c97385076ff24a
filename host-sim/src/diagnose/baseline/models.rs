//! The models `diagnose` compares, all with one free offset per run: the paper's RBF on
//! (T, dT/dt) as the baseline, and that model extended by one candidate feature either
//! as a linear term or as a further RBF input. Width and ridge are chosen on held-out
//! data from a small grid, the same way for every model, so comparisons are fair.

use crate::diagnose::baseline::rbf_basis::{RbfBasis, RbfDesign};
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::derivatives;
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::cv::{CvResult, Prepared};
use crate::diagnose::validation::folds::Folds;
use std::sync::Arc;

/// Width factors tried (x mean centre spacing).
pub const WIDTH_FACTORS: [f64; 3] = [0.5, 1.0, 2.0];
/// Relative ridge values tried.
pub const RIDGES: [f64; 4] = [1e-6, 1e-4, 1e-2, 1e-1];
/// Centre counts tried, as fractions of `centre_count`.
pub const CENTRE_FRACTIONS: [f64; 2] = [0.5, 1.0];

/// The campaign stacked run after run. Temperature and dT/dt are shared (`Arc`) with the
/// bases built on them (memory: an RBF's inputs and a polynomial's rows are read from
/// these columns, never copied).
#[derive(Clone, Debug)]
pub struct Stacked {
    pub y: Vec<f64>,
    pub t_s: Vec<f64>,
    pub temp_c: Arc<Vec<f64>>,
    pub temp_rate_cps: Arc<Vec<f64>>,
    /// Half-width of the centred window `temp_rate_cps` was computed over, s.
    pub temp_rate_half_s: f64,
    pub run_lengths: Vec<usize>,
}

impl Stacked {
    /// Stacks drift, time, temperature and dT/dt (a centred local polynomial over
    /// +/-`rate_half_s`, `input::derivatives`; the window is chosen with the base, `baseline::choice`).
    pub fn with_rate_half_width(c: &Campaign, rate_half_s: f64) -> Self {
        let cat = |f: &dyn Fn(&crate::diagnose::input::Series) -> Vec<f64>| {
            c.runs.iter().flat_map(f).collect::<Vec<f64>>()
        };
        Self {
            y: cat(&|s| s.drift_dph.clone()),
            t_s: cat(&|s| s.t_s.clone()),
            temp_c: Arc::new(cat(&|s| s.temp_c.clone())),
            temp_rate_cps: Arc::new(Self::rate_column(c, rate_half_s)),
            temp_rate_half_s: rate_half_s,
            run_lengths: c.runs.iter().map(|s| s.t_s.len()).collect(),
        }
    }

    /// dT/dt of every run, stacked: a centred local polynomial over +/-`rate_half_s`.
    pub fn rate_column(c: &Campaign, rate_half_s: f64) -> Vec<f64> {
        c.runs
            .iter()
            .flat_map(|s| derivatives::centred(&s.t_s, &s.temp_c, 1, rate_half_s))
            .collect()
    }
}

/// A fitted and validated RBF model.
#[derive(Clone, Debug)]
pub struct RbfFit {
    pub basis: RbfBasis,
    pub prepared: Prepared,
    pub cv: CvResult,
    pub centres: usize,
    pub width_factor: f64,
    pub ridge: f64,
}

/// Centres for `n` points (more data, more centres; at most 30).
pub fn centre_count(n: usize, inputs: usize) -> usize {
    (n / 25).clamp(3, 18 + 4 * inputs)
}

/// Fits an RBF on `inputs` (plus `linear` columns) choosing width and ridge on held-out data.
pub fn fit_rbf(
    folds: &Folds,
    inputs: Vec<Arc<Vec<f64>>>,
    linear: Vec<Vec<f64>>,
    y: &[f64],
) -> Result<RbfFit, DiagnoseError> {
    let k_max = centre_count(y.len(), inputs.len());
    // Only the best setting is remembered and rebuilt at the end. Designs are rows
    // computed on demand (`RbfDesign`): only the inputs are held, never n x centres.
    let mut best: Option<(usize, f64, f64, f64, RbfBasis)> = None;
    // The inputs are shared, never copied (memory: the stacked columns serve every fit).
    let shared_inputs = Arc::new(inputs);
    let shared_linear = Arc::new(linear);
    let views: Vec<&[f64]> = shared_inputs.iter().map(|c| c.as_slice()).collect();
    let design = |basis: &RbfBasis| {
        let rows = RbfDesign {
            basis: basis.clone(),
            inputs: shared_inputs.clone(),
            linear: shared_linear.clone(),
        };
        Prepared::from_design(folds, Arc::new(rows), y, RIDGES[0])
    };
    let mut tried_k = Vec::with_capacity(CENTRE_FRACTIONS.len());
    for frac in CENTRE_FRACTIONS {
        let k = ((k_max as f64 * frac).round() as usize).max(3);
        if tried_k.contains(&k) {
            continue; // the same fits again: a tie never replaces the best
        }
        tried_k.push(k);
        // k-means once per centre count: the centres do not depend on the width.
        let unit = RbfBasis::fit_centres(&views, k);
        for wf in WIDTH_FACTORS {
            let basis = unit.with_width_factor(wf);
            let prepared = design(&basis);
            for (ridge, cv) in RIDGES
                .into_iter()
                .zip(prepared.validate_ridges(folds, &RIDGES))
            {
                let Ok(cv) = cv else {
                    continue;
                };
                if best.as_ref().is_none_or(|b| cv.rms() < b.3) {
                    best = Some((k, wf, ridge, cv.rms(), basis.clone()));
                }
            }
        }
    }
    let (k, wf, ridge, _, basis) = best.ok_or(DiagnoseError::Singular { what: "RBF fit" })?;
    let mut prepared = design(&basis);
    prepared.set_ridge(ridge);
    let cv = prepared.validate(folds)?;
    Ok(RbfFit {
        basis,
        prepared,
        cv,
        centres: k,
        width_factor: wf,
        ridge,
    })
}
