//! Gaussian RBF evaluation in f32 (`libm::expf`), plus the f64 reference the other
//! evaluation paths are measured against.
//!
//! drift_dph = bias + sum_j linear[j] * xn_j + sum_i w_i * exp(-||xn - c_i||^2 / (2 s_i^2)),
//! xn_j = (x_j - input_offset[j]) / input_scale[j]; only the first `n_rbf_inputs`
//! normalised inputs enter the Gaussian distance (see `model`).
//! No range check happens here: the compensator flags inputs outside the trained range.

use crate::model::{RbfModel, MAX_INPUTS};

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
        *out = (x - model.input_offset[j]) / model.input_scale[j];
    }
    Ok(xn)
}

/// Predicted drift, deg/h, in f32 with `libm::expf`. `x_raw` is in the order of `model.inputs`.
pub fn predict_f32(model: &RbfModel, x_raw: &[f32]) -> Result<f32, RbfError> {
    let xn = normalise_f32(model, x_raw)?;
    let n = model.inputs.len();
    let nr = model.n_rbf_inputs as usize;
    let mut acc = model.bias_dph;
    for (&l, &x) in model.linear.iter().zip(xn.iter()).take(n) {
        acc += l * x;
    }
    for ((c, &s), &w) in model
        .centers
        .iter()
        .zip(model.widths.iter())
        .zip(model.weights.iter())
    {
        let mut d2 = 0.0f32;
        for j in 0..nr {
            let d = xn[j] - c[j];
            d2 += d * d;
        }
        acc += w * libm::expf(-d2 / (2.0 * s * s));
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
        *out = (x - model.input_offset[j] as f64) / model.input_scale[j] as f64;
    }
    let mut acc = model.bias_dph as f64;
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
