//! Gaussian RBF evaluation in f32 (with `exp_neg_f32`, a range-reduced polynomial
//! exponential that is about twice as cheap as `libm::expf` on the Cortex-M4F), plus the
//! f64 reference (`libm::exp`) the other evaluation paths are measured against.
//!
//! drift_dph = bias + sum_j linear[j] * xn_j + sum_k poly[k-1] t^k
//!             + sum_i w_i * exp(-||xn - c_i||^2 / (2 s_i^2)),
//! xn_j = (x_j - input_offset[j]) / input_scale[j] held to +-`XN_CLAMP`, t = xn_0 held
//! to the trained range of input 0; only the first `n_rbf_inputs` normalised inputs enter
//! the Gaussian distance (see `model`).
//! No range check happens here: the compensator flags inputs outside the trained range.

use crate::model::{RbfModel, MAX_INPUTS, XN_CLAMP};

/// Why an RBF evaluation was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RbfError {
    /// The input vector length differs from the model's number of inputs.
    WrongInputCount { expected: u8, got: u8 },
    /// Input `index` is NaN or infinite.
    NonFiniteInput { index: u8 },
    /// The model's vectors are inconsistent; run `RbfModel::validate` first.
    InvalidModel,
}

impl core::fmt::Display for RbfError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            RbfError::WrongInputCount { expected, got } => {
                write!(f, "rbf: model needs {expected} inputs, got {got}")
            }
            RbfError::NonFiniteInput { index } => {
                write!(f, "rbf: input {index} is NaN or infinite")
            }
            RbfError::InvalidModel => {
                write!(f, "rbf: model vectors are inconsistent (not validated)")
            }
        }
    }
}

impl core::error::Error for RbfError {}

/// Check the input vector against the model; returns the number of inputs.
pub(crate) fn check_inputs<T: Copy>(
    model: &RbfModel,
    x_raw: &[T],
    is_finite: impl Fn(T) -> bool,
) -> Result<usize, RbfError> {
    let n = model.inputs.len();
    if x_raw.len() != n {
        return Err(RbfError::WrongInputCount {
            expected: n as u8,
            got: x_raw.len().min(u8::MAX as usize) as u8,
        });
    }
    let m = model.centers.len();
    if n == 0
        || n > MAX_INPUTS
        || model.input_offset.len() != n
        || model.input_scale.len() != n
        || model.linear.len() != n
        || model.widths.len() != m
        || model.weights.len() != m
        || model.n_rbf_inputs as usize > n
    {
        return Err(RbfError::InvalidModel);
    }
    if let Some(i) = x_raw.iter().position(|&v| !is_finite(v)) {
        return Err(RbfError::NonFiniteInput { index: i as u8 });
    }
    Ok(n)
}

/// Raw inputs -> normalised inputs (f32), as the f32 evaluator sees them.
pub fn normalise_f32(model: &RbfModel, x_raw: &[f32]) -> Result<[f32; MAX_INPUTS], RbfError> {
    let n = check_inputs(model, x_raw, f32::is_finite)?;
    let mut xn = [0.0f32; MAX_INPUTS];
    for (j, (out, &x)) in xn.iter_mut().zip(x_raw.iter()).enumerate().take(n) {
        *out = ((x - model.input_offset[j]) / model.input_scale[j]).clamp(-XN_CLAMP, XN_CLAMP);
    }
    Ok(xn)
}

/// exp(-u) for u >= 0 in f32: u log2(e) = n + f with n an integer, exp(-u) =
/// 2^-n exp(-r), r = u - n ln 2 in [-ln2/2, ln2/2] (Cody-Waite two-part ln 2), exp(-r)
/// by a degree-6 polynomial (Cephes expf coefficients). Measured relative error against
/// f64 `exp` < 2e-7 over the whole range (test `exp_neg_f32_relative_error`); exactly 0
/// for u > 87 (below f32's normal range) and for NaN-free but huge u. Branch-free apart
/// from the cut-off, so the host trainer's loops vectorise it as well.
#[inline]
pub fn exp_neg_f32(u: f32) -> f32 {
    const LOG2E: f32 = core::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    const ROUND: f32 = 12_582_912.0; // 1.5 * 2^23: adding it rounds to an integer.
    const MAX_U: f32 = 87.0;
    // A compare and select, not `f32::min` (a libm call with NaN handling on the M4F).
    let x = if u < MAX_U { -u } else { -MAX_U };
    let n = (x * LOG2E + ROUND) - ROUND;
    let r = x - n * LN2_HI - n * LN2_LO;
    let p = 1.987_569_1e-4f32;
    let p = p * r + 1.398_199_9e-3;
    let p = p * r + 8.333_452e-3;
    let p = p * r + 4.166_579_6e-2;
    let p = p * r + 1.666_666_5e-1;
    let p = p * r + 0.5;
    let p = (p * r * r + r) + 1.0;
    let scale = f32::from_bits(((n as i32 + 127) as u32) << 23);
    // All-ones mask while u <= MAX_U (also drops NaN): a select, not a branch.
    let keep = u32::from(u <= MAX_U).wrapping_neg();
    f32::from_bits((p * scale).to_bits() & keep)
}

/// The polynomial base sum_k poly[k-1] t^k, t = xn0 held to `domain` (Horner).
fn poly_f32(poly: &[f32], domain: (f32, f32), xn0: f32) -> f32 {
    // max/min, not clamp: an unvalidated model's bounds may be NaN or reversed.
    let t = xn0.max(domain.0).min(domain.1);
    poly.iter().rev().fold(0.0f32, |acc, &p| (acc + p) * t)
}

/// Predicted drift, deg/h, in f32 with `libm::expf`. `x_raw` is in the order of `model.inputs`.
pub fn predict_f32(model: &RbfModel, x_raw: &[f32]) -> Result<f32, RbfError> {
    let xn = normalise_f32(model, x_raw)?;
    let n = model.inputs.len();
    let nr = model.n_rbf_inputs as usize;
    let mut acc = model.bias_dph + poly_f32(&model.poly, model.poly_domain(), xn[0]);
    for (&l, &x) in model.linear.iter().zip(xn.iter()).take(n) {
        acc += l * x;
    }
    // Sliced once, outside the loop: no bounds check or index call per centre.
    let xr = xn.get(..nr).unwrap_or(&[]);
    for ((c, &s), &w) in model
        .centers
        .iter()
        .zip(model.widths.iter())
        .zip(model.weights.iter())
    {
        let d2: f32 = xr.iter().zip(c).map(|(x, c)| (x - c) * (x - c)).sum();
        acc += w * exp_neg_f32(d2 / (2.0 * s * s));
    }
    Ok(acc)
}

/// Reference drift, deg/h, in f64 (`libm::exp`) from the same f32 parameters.
/// Used to measure the f32 and fixed-point paths; also handy on the host.
pub fn predict_f64(model: &RbfModel, x_raw: &[f64]) -> Result<f64, RbfError> {
    let n = check_inputs(model, x_raw, f64::is_finite)?;
    let nr = model.n_rbf_inputs as usize;
    let mut xn = [0.0f64; MAX_INPUTS];
    for (j, (out, &x)) in xn.iter_mut().zip(x_raw.iter()).enumerate().take(n) {
        let v = (x - model.input_offset[j] as f64) / model.input_scale[j] as f64;
        *out = v.clamp(-XN_CLAMP as f64, XN_CLAMP as f64);
    }
    let (lo, hi) = model.poly_domain();
    let t = xn[0].max(lo as f64).min(hi as f64);
    let mut acc = model.bias_dph as f64
        + model
            .poly
            .iter()
            .rev()
            .fold(0.0f64, |acc, &p| (acc + p as f64) * t);
    for (&l, &x) in model.linear.iter().zip(xn.iter()).take(n) {
        acc += l as f64 * x;
    }
    for ((c, &s), &w) in model
        .centers
        .iter()
        .zip(model.widths.iter())
        .zip(model.weights.iter())
    {
        let mut d2 = 0.0f64;
        for j in 0..nr {
            let d = xn[j] - c[j] as f64;
            d2 += d * d;
        }
        let s = s as f64;
        acc += w as f64 * libm::exp(-d2 / (2.0 * s * s));
    }
    Ok(acc)
}
