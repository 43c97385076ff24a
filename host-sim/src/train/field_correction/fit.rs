//! The field correction's fit: the field observations and their power-ons, the linear
//! terms it regresses on, the weighted ridge fit and its fold into the model's bias and
//! linear terms. One job: given the observations, the terms and the weight W, the
//! correction and the model it makes (which terms and which W are `terms` and `weight`).

use anyhow::{bail, Result};
use fog_core::model::format::RbfModel;

/// The weight at which the field alone counts (the prior rows negligible): the largest
/// of `WEIGHT_GRID`.
pub(super) const FIELD_ALONE_WEIGHT: f64 = 1.0e5;

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
    pub(super) fn input(&self, kind: usize) -> f64 {
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
