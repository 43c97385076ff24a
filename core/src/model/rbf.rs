//! Gaussian RBF evaluation in f32 (with `exp_neg::exp_neg_table_f32`, a table-based
//! exponential made for the Cortex-M4F's instruction count), plus the f64 reference
//! (`libm::exp`) the other evaluation paths are measured against.
//!
//! drift_dph = bias + sum_j (linear[j] + linear_by_t[j] t) * xn_j + sum_k poly[k-1] t^k
//!             + sum_i w_i * exp(-||xn - c_i||^2 / (2 s_i^2)),
//! xn_j = (x_j - input_offset[j]) / input_scale[j] held to +-`XN_CLAMP`, t = xn_0 held
//! to the trained range of input 0; only the first `n_rbf_inputs` normalised inputs enter
//! the Gaussian distance (see `model`).
//! No range check happens here: the compensator flags inputs outside the trained range.

pub use crate::model::exp_neg::exp_neg_f32;
use crate::model::exp_neg::{twice_exp_neg_half, GAUSS_MAX_V};
use crate::model::format::{RbfModel, MAX_INPUTS, MAX_RBF_INPUTS, XN_CLAMP};

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
        || model.n_rbf_inputs as usize > n.min(MAX_RBF_INPUTS)
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
    check_inputs(model, x_raw, f32::is_finite)?;
    // Written element by element (no zero-fill loop, no bounds checks): inputs beyond
    // the model's count stay 0.
    Ok(core::array::from_fn(|j| {
        match (
            x_raw.get(j),
            model.input_offset.get(j),
            model.input_scale.get(j),
        ) {
            (Some(&x), Some(&offset), Some(&scale)) => {
                ((x - offset) / scale).clamp(-XN_CLAMP, XN_CLAMP)
            }
            _ => 0.0,
        }
    }))
}

/// t = xn0 held to the trained range of input 0 (`RbfModel::poly_domain`), compared and
/// selected as `f32::max` then `f32::min` would (a NaN bound is ignored, a reversed pair
/// gives `hi`), without their libm calls on the M4F.
fn held_t_f32(model: &RbfModel, xn0: f32) -> f32 {
    let (lo, hi) = model.poly_domain();
    let t = if xn0 < lo { lo } else { xn0 };
    if t > hi {
        hi
    } else {
        t
    }
}

/// The terms in t: the polynomial base sum_k poly[k-1] t^k (Horner) and the
/// temperature-coupled linear terms t sum_j linear_by_t[j] xn_j; 0 without either, which
/// skips computing the range.
fn t_terms_f32(model: &RbfModel, xn: &[f32; MAX_INPUTS]) -> f32 {
    if model.poly.is_empty() && model.linear_by_t.is_empty() {
        return 0.0;
    }
    let t = held_t_f32(model, xn[0]);
    let poly = model
        .poly
        .iter()
        .rev()
        .fold(0.0f32, |acc, &p| (acc + p) * t);
    let coupled = model
        .linear_by_t
        .iter()
        .zip(xn.iter())
        .fold(0.0f32, |acc, (&l, &x)| acc + l * x);
    poly + coupled * t
}

/// The square of `d`.
#[inline(always)]
fn sq(d: f32) -> f32 {
    d * d
}

/// acc + sum_i w_i exp(-d2(c_i) / (2 s_i^2)) over the model's centres, with the squared
/// distance `d2` written out for the model's number of RBF inputs (no inner loop per
/// centre). Each term is computed as w_i 2 exp(-v/2), v = d2 / s^2, and summed doubled
/// (exact scalings by 2: the result has the bits of the plain sum); a centre whose v
/// is beyond the f32 underflow threshold costs a compare and a branch.
#[inline(always)]
fn add_gaussians(model: &RbfModel, acc: f32, d2: impl Fn(&[f32; MAX_RBF_INPUTS]) -> f32) -> f32 {
    let mut twice_acc = 2.0 * acc;
    for ((c, &s), &w) in model
        .centers
        .iter()
        .zip(model.widths.iter())
        .zip(model.weights.iter())
    {
        let v = d2(c) / (s * s);
        if v <= GAUSS_MAX_V {
            twice_acc += w * twice_exp_neg_half(v);
        }
    }
    0.5 * twice_acc
}

/// Predicted drift, deg/h, in f32 (`exp_neg::exp_neg_table_f32`'s arithmetic). `x_raw` is in the order of
/// `model.inputs`.
pub fn predict_f32(model: &RbfModel, x_raw: &[f32]) -> Result<f32, RbfError> {
    let xn = normalise_f32(model, x_raw)?;
    let n = model.inputs.len();
    let mut acc = model.bias_dph + t_terms_f32(model, &xn);
    for (&l, &x) in model.linear.iter().zip(xn.iter()).take(n) {
        acc += l * x;
    }
    // Summed in input order as a loop over the inputs would, so the result does not
    // depend on which arm runs; `check_inputs` bounds n_rbf_inputs by the input count and
    // by `MAX_RBF_INPUTS` (4): the last arm is the four-input one.
    let [x0, x1, x2, x3, ..] = xn;
    Ok(match model.n_rbf_inputs {
        0 => add_gaussians(model, acc, |_| 0.0),
        1 => add_gaussians(model, acc, |c| sq(x0 - c[0])),
        2 => add_gaussians(model, acc, |c| sq(x0 - c[0]) + sq(x1 - c[1])),
        3 => add_gaussians(model, acc, |c| {
            sq(x0 - c[0]) + sq(x1 - c[1]) + sq(x2 - c[2])
        }),
        _ => add_gaussians(model, acc, |c| {
            sq(x0 - c[0]) + sq(x1 - c[1]) + sq(x2 - c[2]) + sq(x3 - c[3])
        }),
    })
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
    for (&l, &x) in model.linear_by_t.iter().zip(xn.iter()).take(n) {
        acc += l as f64 * t * x;
    }
    for ((c, &s), &w) in model
        .centers
        .iter()
        .zip(model.widths.iter())
        .zip(model.weights.iter())
    {
        let mut d2 = 0.0f64;
        for (&x, &cj) in xn.iter().zip(c.iter()).take(nr) {
            let d = x - cj as f64;
            d2 += d * d;
        }
        let s = s as f64;
        acc += w as f64 * libm::exp(-d2 / (2.0 * s * s));
    }
    Ok(acc)
}
