//! Integer-only RBF evaluation for FPU-less parts (Cortex-M0, fixed-point DSPs).
//!
//! `FixedModel::from_model` converts a validated `RbfModel` once (this step may use
//! floats: it runs at model load). `FixedModel::predict` then uses integers only:
//! inputs are taken apart from their IEEE-754 bits, the distance, the exponential and the
//! weighted sum are integer arithmetic, and the result is assembled back into f32 bits.
//!
//! Number formats:
//! - raw input j: i64 with `F_j` fraction bits chosen from its trained range (|x| < 2^(40-F_j)
//!   gets full precision, larger values saturate; such inputs are out of range anyway);
//! - normalised inputs and centres: Q.28 (`XN_FRAC`) in i64;
//! - per-centre gain g_i = 1/(sqrt(2) s_i): Q.24 (`GAIN_FRAC`), so ||xn - c||^2/(2 s^2) =
//!   sum (g (xn - c))^2 is a sum of squares of Q.28 values, in Q.56;
//! - exp(-u): range-reduced as 2^-(u log2 e) = 2^-n * 2^-(k/32) * 2^-r with r < 1/32, a
//!   32-entry Q.30 table and a 4th-order polynomial (truncation error < 5e-11); Q.30 result;
//! - weights, bias, linear and polynomial terms: Q.`w_frac`, scaled per model so the
//!   largest fits in 31 bits; the weighted sum accumulates in i64;
//! - polynomial base: Horner in i128 on t = xn_0 (Q.28) held to input 0's trained range;
//!   temperature-coupled linear terms: (t xn_j >> 28) times their Q.`w_frac` coefficient.
//!
//! Worst error against the f64 reference: see `docs/explain/core.md` (measured by the
//! `fixed_worst_error_*` tests: `cargo test -p fog-core --test rbf_accuracy fixed_worst -- --nocapture`).

use crate::model::error::ModelError;
use crate::model::format::{RbfModel, MAX_CENTERS, MAX_INPUTS, MAX_POLY_DEGREE, MAX_RBF_INPUTS};
use crate::model::rbf::RbfError;

/// Fraction bits of normalised inputs and centres.
pub const XN_FRAC: u32 = 28;
/// Fraction bits of the per-centre gains 1/(sqrt(2) s).
pub const GAIN_FRAC: u32 = 24;
/// Fraction bits of the exponential's result.
pub const EXP_FRAC: u32 = 30;
/// exp(-u) is taken as 0 for u >= this (exp(-23) = 1e-10 < 2^-30).
pub const EXP_CUTOFF: u64 = 23;
/// Bits of precision kept for raw inputs inside their trained range.
const RAW_BITS: i32 = 40;
/// Largest |normalised input| accepted (about 120; beyond it inputs saturate).
const XN_LIMIT: i64 = 120 << XN_FRAC;

/// 2^(-k/32) in Q.30 for k = 0..32.
const EXP2_TABLE_Q30: [u32; 32] = [
    1073741824, 1050733751, 1028218693, 1006186087, 984625594, 963527098, 942880699, 922676710,
    902905651, 883558244, 864625413, 846098274, 827968132, 810226483, 792865000, 775875538,
    759250125, 742980960, 727060411, 711481005, 696235434, 681316545, 666717336, 652430958,
    638450708, 624770026, 611382493, 598281827, 585461881, 572916640, 560640218, 548626854,
];
/// log2(e) in Q.30.
const LOG2E_Q30: u64 = 1_549_082_005;
/// ln(2) in Q.30.
const LN2_Q30: u64 = 744_261_118;
/// 1/3 in Q.30.
const INV3_Q30: u64 = 357_913_941;
const ONE_Q30: u64 = 1 << 30;

/// Why a model cannot be converted to fixed point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FixedError {
    /// The model itself is invalid.
    Model(ModelError),
    /// Width too small for Q.24 gains (needs s >= 0.0056 in normalised units).
    WidthTooSmall { center: u8 },
    /// A centre coordinate beyond +-100 normalised units.
    CenterOutOfRange { center: u8 },
    /// An input's range, offset or scale cannot be represented.
    InputRange { input: u8 },
    /// A weight, bias or linear term beyond 2^30 deg/h.
    WeightTooLarge,
}

impl core::fmt::Display for FixedError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            FixedError::Model(e) => write!(f, "fixed: {e}"),
            FixedError::WidthTooSmall { center } => write!(
                f,
                "fixed: width of centre {center} is below 0.0056 normalised units (Q.24 limit)"
            ),
            FixedError::CenterOutOfRange { center } => {
                write!(
                    f,
                    "fixed: centre {center} lies beyond +-100 normalised units"
                )
            }
            FixedError::InputRange { input } => write!(
                f,
                "fixed: input {input}'s range/offset/scale cannot be represented in fixed point"
            ),
            FixedError::WeightTooLarge => write!(f, "fixed: a weight exceeds 2^30 deg/h"),
        }
    }
}

impl core::error::Error for FixedError {}

/// A model prepared for integer-only evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct FixedModel {
    n_inputs: u8,
    n_rbf: u8,
    n_centers: u8,
    /// Fraction bits of raw input j.
    in_frac: [u8; MAX_INPUTS],
    /// Offset of input j in Q.in_frac.
    in_offset_q: [i64; MAX_INPUTS],
    /// 1/scale of input j, Q.in_gain_frac (about 2^40).
    in_gain_q: [i64; MAX_INPUTS],
    /// Right shift that brings (x - offset) * gain to Q.28.
    in_shift: [u8; MAX_INPUTS],
    centers_q: [[i64; MAX_RBF_INPUTS]; MAX_CENTERS],
    gain_q: [i32; MAX_CENTERS],
    weights_q: [i32; MAX_CENTERS],
    linear_q: [i32; MAX_INPUTS],
    /// Temperature-coupled linear terms (Q.w_frac) of t * xn_j; `n_linear_by_t` of them
    /// (0: none, and no cost).
    linear_by_t_q: [i32; MAX_INPUTS],
    n_linear_by_t: u8,
    bias_q: i64,
    w_frac: u8,
    /// Polynomial coefficients (Q.w_frac) of t^1..t^n_poly.
    poly_q: [i32; MAX_POLY_DEGREE],
    n_poly: u8,
    /// Trained range of normalised input 0, Q.28: the polynomial's domain.
    poly_lo_q: i64,
    poly_hi_q: i64,
}

/// Smallest e with v <= 2^e, for v > 0.
fn ceil_log2(v: f64) -> i32 {
    let (m, e) = libm::frexp(v);
    if m == 0.5 {
        e - 1
    } else {
        e
    }
}

fn to_q(v: f64, frac: i32) -> i64 {
    libm::round(libm::ldexp(v, frac)) as i64
}

impl FixedModel {
    /// A model with no inputs and no centres (every prediction is a wrong-input-count
    /// error): the initial value of storage that `fill_from` overwrites in place.
    pub const fn empty() -> Self {
        FixedModel {
            n_inputs: 0,
            n_rbf: 0,
            n_centers: 0,
            in_frac: [0; MAX_INPUTS],
            in_offset_q: [0; MAX_INPUTS],
            in_gain_q: [0; MAX_INPUTS],
            in_shift: [0; MAX_INPUTS],
            centers_q: [[0; MAX_RBF_INPUTS]; MAX_CENTERS],
            gain_q: [0; MAX_CENTERS],
            weights_q: [0; MAX_CENTERS],
            linear_q: [0; MAX_INPUTS],
            linear_by_t_q: [0; MAX_INPUTS],
            n_linear_by_t: 0,
            bias_q: 0,
            w_frac: 0,
            poly_q: [0; MAX_POLY_DEGREE],
            n_poly: 0,
            poly_lo_q: 0,
            poly_hi_q: 0,
        }
    }

    /// Convert a model (validated here) for integer-only evaluation.
    pub fn from_model(model: &RbfModel) -> Result<FixedModel, FixedError> {
        let mut fm = FixedModel::empty();
        fm.fill_from(model)?;
        Ok(fm)
    }

    /// `from_model` in place (no 2.7 KB temporary on the stack). On error `self` is left
    /// partly written: fill it again (or discard it) before predicting.
    pub fn fill_from(&mut self, model: &RbfModel) -> Result<(), FixedError> {
        model.validate().map_err(FixedError::Model)?;
        let n = model.inputs.len();
        let fm = self;
        fm.n_inputs = n as u8;
        fm.n_rbf = model.n_rbf_inputs;
        fm.n_centers = model.centers.len() as u8;
        fm.in_frac = [0; MAX_INPUTS];
        fm.in_offset_q = [0; MAX_INPUTS];
        fm.in_gain_q = [0; MAX_INPUTS];
        fm.in_shift = [0; MAX_INPUTS];
        fm.centers_q = [[0; MAX_RBF_INPUTS]; MAX_CENTERS];
        fm.gain_q = [0; MAX_CENTERS];
        fm.weights_q = [0; MAX_CENTERS];
        fm.linear_q = [0; MAX_INPUTS];
        fm.linear_by_t_q = [0; MAX_INPUTS];
        fm.n_linear_by_t = model.linear_by_t.len() as u8;
        fm.bias_q = 0;
        fm.w_frac = 0;
        fm.poly_q = [0; MAX_POLY_DEGREE];
        fm.n_poly = model.poly.len() as u8;
        let (lo, hi) = model.poly_domain();
        fm.poly_lo_q = to_q(lo as f64, XN_FRAC as i32);
        fm.poly_hi_q = to_q(hi as f64, XN_FRAC as i32);
        for j in 0..n {
            let off = model.input_offset[j] as f64;
            let bound = (model.input_min[j] as f64)
                .abs()
                .max((model.input_max[j] as f64).abs())
                .max(off.abs())
                .max(1e-30);
            let frac = RAW_BITS - ceil_log2(bound);
            let gain = 1.0 / model.input_scale[j] as f64;
            let gain_frac = RAW_BITS - ceil_log2(gain);
            let shift = frac + gain_frac - XN_FRAC as i32;
            if !(0..=126).contains(&frac) || !(0..=120).contains(&shift) {
                return Err(FixedError::InputRange { input: j as u8 });
            }
            fm.in_frac[j] = frac as u8;
            fm.in_offset_q[j] = to_q(off, frac);
            fm.in_gain_q[j] = to_q(gain, gain_frac);
            fm.in_shift[j] = shift as u8;
        }
        for (i, c) in model.centers.iter().enumerate() {
            for (q, &v) in fm.centers_q[i]
                .iter_mut()
                .zip(c.iter())
                .take(model.n_rbf_inputs as usize)
            {
                if v.abs() >= 100.0 {
                    return Err(FixedError::CenterOutOfRange { center: i as u8 });
                }
                *q = to_q(v as f64, XN_FRAC as i32);
            }
            let g = 1.0 / (core::f64::consts::SQRT_2 * model.widths[i] as f64);
            if g >= 127.0 {
                return Err(FixedError::WidthTooSmall { center: i as u8 });
            }
            fm.gain_q[i] = to_q(g, GAIN_FRAC as i32) as i32;
        }
        let max_abs = model
            .weights
            .iter()
            .chain(model.linear.iter())
            .chain(model.linear_by_t.iter())
            .chain(model.poly.iter())
            .chain(core::iter::once(&model.bias_dph))
            .fold(0.0f64, |m, &w| m.max((w as f64).abs()));
        if max_abs >= (1u64 << 30) as f64 {
            return Err(FixedError::WeightTooLarge);
        }
        let w_frac = if max_abs > 0.0 {
            (30 - ceil_log2(max_abs)).clamp(0, 60)
        } else {
            30
        };
        fm.w_frac = w_frac as u8;
        for (q, &w) in fm.weights_q.iter_mut().zip(model.weights.iter()) {
            *q = to_q(w as f64, w_frac) as i32;
        }
        for (q, &w) in fm.linear_q.iter_mut().zip(model.linear.iter()) {
            *q = to_q(w as f64, w_frac) as i32;
        }
        for (q, &w) in fm.linear_by_t_q.iter_mut().zip(model.linear_by_t.iter()) {
            *q = to_q(w as f64, w_frac) as i32;
        }
        for (q, &p) in fm.poly_q.iter_mut().zip(model.poly.iter()) {
            *q = to_q(p as f64, w_frac) as i32;
        }
        fm.bias_q = to_q(model.bias_dph as f64, w_frac);
        Ok(())
    }

    /// Number of inputs the model expects.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs as usize
    }

    /// Fraction bits of the internal drift accumulator.
    pub fn weight_frac_bits(&self) -> u32 {
        self.w_frac as u32
    }

    /// Raw inputs -> normalised Q.28 (`XN_FRAC`), integer-only.
    pub fn normalise_q28(&self, x_raw: &[f32]) -> Result<[i64; MAX_INPUTS], RbfError> {
        let n = self.n_inputs as usize;
        if x_raw.len() != n {
            return Err(RbfError::WrongInputCount {
                expected: n as u8,
                got: x_raw.len().min(u8::MAX as usize) as u8,
            });
        }
        let mut xn = [0i64; MAX_INPUTS];
        for (j, (out, &x)) in xn.iter_mut().zip(x_raw.iter()).enumerate() {
            let x_q = f32_to_fixed(x, self.in_frac[j] as i32)
                .ok_or(RbfError::NonFiniteInput { index: j as u8 })?;
            let diff = x_q.saturating_sub(self.in_offset_q[j]) as i128;
            let prod = (diff * self.in_gain_q[j] as i128) >> self.in_shift[j];
            *out = prod.clamp(-XN_LIMIT as i128, XN_LIMIT as i128) as i64;
        }
        Ok(xn)
    }

    /// Drift in Q.`weight_frac_bits()` deg/h from normalised Q.28 inputs (integer-only core).
    /// Inputs beyond +-`XN_LIMIT` (about 120 normalised units) are clamped to it.
    pub fn predict_from_normalised(&self, xn: &[i64; MAX_INPUTS]) -> i64 {
        let xn = xn.map(|x| x.clamp(-XN_LIMIT, XN_LIMIT));
        let n = self.n_inputs as usize;
        let nr = self.n_rbf as usize;
        let mut acc = self.bias_q + self.poly_from_normalised(xn[0]);
        for (&l, &x) in self.linear_q.iter().zip(xn.iter()).take(n) {
            // |l| < 2^31 and |x| < 2^35: exact in i128 (only n_inputs products).
            acc += ((l as i128 * x as i128) >> XN_FRAC) as i64;
        }
        let t = xn[0].max(self.poly_lo_q).min(self.poly_hi_q) as i128;
        let n_coupled = (self.n_linear_by_t as usize).min(n);
        for (&l, &x) in self.linear_by_t_q.iter().zip(xn.iter()).take(n_coupled) {
            // |t|, |x| < 2^35: t x < 2^70, >> 28 < 2^42, times |l| < 2^31: exact in i128.
            acc += ((l as i128 * ((t * x as i128) >> XN_FRAC)) >> XN_FRAC) as i64;
        }
        let z_limit: i64 = 5 << XN_FRAC; // z^2 >= 25 > EXP_CUTOFF
        let u_limit: i64 = (EXP_CUTOFF as i64) << (2 * XN_FRAC);
        'centres: for i in 0..self.n_centers as usize {
            let g = self.gain_q[i] as i64; // < 127 * 2^24 < 2^31
            let c = &self.centers_q[i];
            let mut u: i64 = 0;
            for (&x, &cj) in xn.iter().zip(c.iter()).take(nr) {
                let d = x - cj; // Q.28, |d| < 220 * 2^28
                let z = if d.unsigned_abs() < 1 << 32 {
                    (d * g) >> GAIN_FRAC
                } else {
                    // |d| >= 16 normalised units: only very wide Gaussians get here; drop
                    // 8 bits first so that d * g cannot overflow.
                    ((d >> 8) * g) >> (GAIN_FRAC - 8)
                };
                if z.abs() >= z_limit {
                    continue 'centres;
                }
                u += z * z;
            }
            if u >= u_limit {
                continue;
            }
            // u is Q.56 (< 23 * 2^56); the exponential takes Q.28.
            let e = exp_neg_q30((u >> (2 * XN_FRAC - 28)) as u64);
            acc += (self.weights_q[i] as i64 * e as i64) >> EXP_FRAC;
        }
        acc
    }

    /// The polynomial base in Q.w_frac: Horner on t = xn0 (Q.28) held to the trained
    /// range; |t| <= 120 * 2^28 and every partial sum < 2^31 * 120^3 fit in i128.
    fn poly_from_normalised(&self, xn0: i64) -> i64 {
        let t = xn0.max(self.poly_lo_q).min(self.poly_hi_q) as i128;
        let n = (self.n_poly as usize).min(MAX_POLY_DEGREE);
        let mut acc: i128 = 0;
        for &p in self.poly_q[..n].iter().rev() {
            acc = ((acc + p as i128) * t) >> XN_FRAC;
        }
        acc as i64
    }

    /// Predicted drift, deg/h (integer-only; f32 only at the boundary, by bit manipulation).
    pub fn predict(&self, x_raw: &[f32]) -> Result<f32, RbfError> {
        let xn = self.normalise_q28(x_raw)?;
        Ok(fixed_to_f32(
            self.predict_from_normalised(&xn),
            self.w_frac as u32,
        ))
    }

    /// Predicted drift as Q16.16 deg/h (saturating), integer-only end to end.
    pub fn predict_q16(&self, x_raw: &[f32]) -> Result<i32, RbfError> {
        let xn = self.normalise_q28(x_raw)?;
        let acc = self.predict_from_normalised(&xn);
        let wf = self.w_frac as i32;
        let q16 = if wf >= 16 {
            acc >> (wf - 16)
        } else {
            acc.saturating_mul(1 << (16 - wf))
        };
        Ok(q16.clamp(i32::MIN as i64, i32::MAX as i64) as i32)
    }
}

/// exp(-u) in Q.30 for u in Q.28, 0 <= u < 23 * 2^28. Integer-only.
pub fn exp_neg_q30(u_q28: u64) -> u32 {
    if u_q28 >= EXP_CUTOFF << 28 {
        return 0;
    }
    // t = u * log2(e) in Q.58: < 23 * 1.443 * 2^58 < 2^64.
    let t = u_q28 * LOG2E_Q30;
    let n = (t >> 58) as u32;
    let f = t & ((1u64 << 58) - 1);
    let k = (f >> 53) as usize;
    let r_q30 = (f & ((1u64 << 53) - 1)) >> 28; // r < 1/32
                                                // y = r ln 2 < 0.0217, Q.30
    let y = mul_q30(r_q30, LN2_Q30);
    // exp(-y) = 1 - y (1 - y/2 (1 - y/3 (1 - y/4))), Horner in Q.30.
    let mut p = ONE_Q30 - (y >> 2);
    p = ONE_Q30 - mul_q30(mul_q30(y, p), INV3_Q30);
    p = ONE_Q30 - (mul_q30(y, p) >> 1);
    p = ONE_Q30 - mul_q30(y, p);
    let e = mul_q30(EXP2_TABLE_Q30[k] as u64, p);
    if n >= 32 {
        0
    } else {
        ((e + ((1u64 << n) >> 1)) >> n) as u32
    }
}

/// a * b in Q.30, rounded to nearest (a * b < 2^64 - 2^29).
#[inline(always)]
fn mul_q30(a: u64, b: u64) -> u64 {
    (a * b + (1 << 29)) >> 30
}

/// f32 -> fixed with `frac` fraction bits, truncating toward zero and saturating at
/// +-2^(RAW_BITS+1); `None` for NaN or infinity. Integer-only (IEEE-754 bit fields).
pub fn f32_to_fixed(x: f32, frac: i32) -> Option<i64> {
    let bits = x.to_bits();
    let neg = bits >> 31 != 0;
    let exp = ((bits >> 23) & 0xff) as i32;
    if exp == 0xff {
        return None;
    }
    let (mant, exp) = if exp == 0 {
        ((bits & 0x7f_ffff) as i64, 1)
    } else {
        (((bits & 0x7f_ffff) | 0x80_0000) as i64, exp)
    };
    let limit = 1i64 << (RAW_BITS + 1);
    let shift = exp - 150 + frac;
    let mag = if mant == 0 {
        0
    } else if shift >= 0 {
        if shift > 40 || (mant << shift) > limit {
            limit
        } else {
            mant << shift
        }
    } else if shift <= -25 {
        0
    } else {
        mant >> (-shift)
    };
    Some(if neg { -mag } else { mag })
}

/// Fixed (`frac` fraction bits) -> f32, round to nearest even. Integer-only.
pub fn fixed_to_f32(v: i64, frac: u32) -> f32 {
    if v == 0 {
        return 0.0;
    }
    let neg = v < 0;
    let mag = v.unsigned_abs();
    let top = 63 - mag.leading_zeros() as i32; // index of the leading one
                                               // Keep 24 significant bits, rounding the rest to nearest even.
    let (mut mant, mut top) = if top > 23 {
        let drop = (top - 23) as u32;
        let m = mag >> drop;
        let rest = mag & ((1u64 << drop) - 1);
        let half = 1u64 << (drop - 1);
        let m = if rest > half || (rest == half && m & 1 == 1) {
            m + 1
        } else {
            m
        };
        (m, top)
    } else {
        (mag << (23 - top) as u32, top)
    };
    if mant >= 1 << 24 {
        mant >>= 1;
        top += 1;
    }
    let exp = top - frac as i32 + 127;
    let bits = if exp >= 255 {
        0x7f80_0000 // overflow: infinity (cannot happen for drift values)
    } else if exp <= 0 {
        // Subnormal or zero; such tiny drifts are below any resolution that matters.
        let shift = (1 - exp) as u32;
        if shift >= 24 {
            0
        } else {
            (mant >> shift) as u32
        }
    } else {
        ((exp as u32) << 23) | (mant as u32 & 0x7f_ffff)
    };
    f32::from_bits(bits | if neg { 0x8000_0000 } else { 0 })
}
