//! exp(-u), u >= 0, in f32 for the Gaussian terms of the RBF model: two kernels with the
//! same accuracy (relative error < 1e-6 over the whole range a Gaussian uses, u in
//! [0, 87]; measured by the tests below and by `core/tests/rbf_accuracy.rs`) but made for
//! different machines:
//!
//! - [`exp_neg_f32`]: a degree-6 polynomial on [-ln2/2, ln2/2], branch free, so the host
//!   trainer's loops over millions of design-matrix entries vectorise it (a table lookup
//!   would be a gather, which the baseline x86-64 target does not have);
//! - [`exp_neg_table_f32`]: a 512-entry table of 2^(j/512) (2 KiB) and a degree-1
//!   polynomial on [-ln2/1024, ln2/1024], the scalar kernel of `rbf::predict_f32` on the
//!   Cortex-M4F, where every Horner step costs two instructions (a register copy and a
//!   multiply-add) and the table costs one load: 13 instructions against the degree-6
//!   kernel's 27.
//!
//! Both take 2^k apart and back together with exponent-bit arithmetic (`f32::from_bits`,
//! no `unsafe`, no libm call) and give exactly 0 beyond [`EXP_NEG_MAX_U`], where exp(-u)
//! leaves f32's normal range, and for NaN.

/// Largest u for which the kernels return exp(-u); above it (and for NaN) they return 0.
/// exp(-87) = 1.6e-38 is just above f32's smallest normal number (1.2e-38).
pub const EXP_NEG_MAX_U: f32 = 87.0;

/// 1.5 * 2^23: adding it to |v| < 2^22 rounds v to an integer, found in the low mantissa bits.
const ROUND: f32 = 12_582_912.0;

/// exp(-u) for u >= 0: u log2(e) = n + f with n an integer, exp(-u) = 2^-n exp(-r),
/// r = u - n ln 2 in [-ln2/2, ln2/2] (Cody-Waite two-part ln 2), exp(-r) by a degree-6
/// polynomial (Cephes expf coefficients). Branch-free apart from the cut-off, so the host
/// trainer's loops vectorise it. Relative error 8.3e-8 at worst over [0, 87] (tests below
/// and `exp_neg_f32_relative_error` in `core/tests/rbf_accuracy.rs`).
#[inline]
pub fn exp_neg_f32(u: f32) -> f32 {
    const LOG2E: f32 = core::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    // A compare and select, not `f32::min` (a libm call with NaN handling on the M4F).
    let x = if u < EXP_NEG_MAX_U {
        -u
    } else {
        -EXP_NEG_MAX_U
    };
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
    // All-ones mask while u <= EXP_NEG_MAX_U (also drops NaN): a select, not a branch.
    let keep = u32::from(u <= EXP_NEG_MAX_U).wrapping_neg();
    f32::from_bits((p * scale).to_bits() & keep)
}

/// Entries of the 2^(j/512) table (2 KiB of flash).
const TABLE_BITS: u32 = 9;
const TABLE_LEN: usize = 1 << TABLE_BITS;
/// 256 / ln 2: v = 2u times it is the table's step count, n.
const STEPS_PER_TWO_UNITS: f32 = 369.329_93;
/// 2 ln2/512 in two parts: the first has 8 significant bits, so n * TWO_STEP_HI is exact
/// for the |n| <= 87 * 512 / ln 2 < 2^16 of the range, the second is the rest.
const TWO_STEP_HI: f32 = 0.002_700_805_7;
const TWO_STEP_LO: f32 = 6.800_51e-6;
/// 2 exp(-s) ~ TWO_A0 - 2s on |s| <= ln2/1024: A0 = 1 + 2^-23 is the minimax constant
/// (relative error 1.2e-7; 1 would give 2.3e-7), the slope 1 is minimax as it is.
const TWO_A0: f32 = 2.000_000_2;
/// Largest v = 2u the table kernel evaluates.
const MAX_V: f32 = 2.0 * EXP_NEG_MAX_U;

/// 2^(j/512) for j in 0..512, each as its f32 bit pattern minus j << 14, so that adding
/// the step count's float bits shifted left by 14 both removes the index bits and adds
/// the whole power of two to the exponent field (see `twice_exp_neg_half`).
static EXP2_STEP_BITS: [u32; TABLE_LEN] = exp2_step_bits();

/// Builds `EXP2_STEP_BITS` at compile time: exp(j ln2/512) by its Taylor series in f64
/// (20 terms, far past f64 precision for arguments below ln 2), rounded to f32.
const fn exp2_step_bits() -> [u32; TABLE_LEN] {
    let mut table = [0u32; TABLE_LEN];
    let mut j = 0;
    while j < TABLE_LEN {
        let x = j as f64 * core::f64::consts::LN_2 / TABLE_LEN as f64;
        let (mut sum, mut term, mut k) = (1.0f64, 1.0f64, 1);
        while k < 20 {
            term = term * x / k as f64;
            sum += term;
            k += 1;
        }
        table[j] = (sum as f32)
            .to_bits()
            .wrapping_sub((j as u32) << (23 - TABLE_BITS));
        j += 1;
    }
    table
}

/// exp(-u) for u >= 0, the scalar kernel for the M4F: exactly `twice_exp_neg_half(2u) / 2`
/// (both scalings by 2 are exact). Measured relative error 2.9e-7 at worst against f64
/// `exp` over [0, 87] (tests below; exp(0) gives 1 + 2^-23); exactly 0 for
/// u > `EXP_NEG_MAX_U` and for NaN.
#[inline]
pub fn exp_neg_table_f32(u: f32) -> f32 {
    0.5 * twice_exp_neg_half(2.0 * u)
}

/// 2 exp(-v/2) for 0 <= v <= `MAX_V` (v = 2u: the RBF's d^2 / s^2 without the factor 2
/// of 2 s^2, whose halving is folded into the constants). With n = round(-v 256/ln2)
/// (the ROUND trick leaves n in the low bits of `t`), exp(-v/2) = 2^(n/512) exp(-s),
/// s = v/2 + n ln2/512 in [-ln2/1024, ln2/1024]; 2^(n/512) = 2^floor(n/512) 2^((n mod 512)/512)
/// from the table and exponent-bit arithmetic, 2 exp(-s) ~ TWO_A0 - 2s. On the M4F:
/// 13 instructions, one of them a table load. The result is undefined (but no panic)
/// outside [0, MAX_V]: the caller checks the range.
#[inline(always)]
pub(crate) fn twice_exp_neg_half(v: f32) -> f32 {
    let t = ROUND - v * STEPS_PER_TWO_UNITS;
    // t's bits are those of 1.5 * 2^23 (a multiple of 2^22) plus n, -64263 <= n <= 0.
    let t_bits = t.to_bits();
    let n = t - ROUND;
    let two_s = v + n * TWO_STEP_HI + n * TWO_STEP_LO;
    let two_p = TWO_A0 - two_s;
    // (t_bits << 14) mod 2^32 = floor(n/512) << 23 (the exponent) + (n mod 512) << 14
    // (which the table entry subtracts again); ROUND's own bits shift out.
    let index = (t_bits % TABLE_LEN as u32) as usize;
    let scale_bits = EXP2_STEP_BITS
        .get(index)
        .map_or(0, |&b| b.wrapping_add(t_bits << (23 - TABLE_BITS)));
    let e = two_p * f32::from_bits(scale_bits);
    // A select, not a branch (false for NaN).
    if v <= MAX_V {
        e
    } else {
        0.0
    }
}

/// The largest v = d^2/s^2 whose Gaussian `twice_exp_neg_half` evaluates; beyond it the
/// term underflows f32 and is skipped.
pub(crate) const GAUSS_MAX_V: f32 = MAX_V;

#[cfg(test)]
mod tests {
    use super::*;

    /// Worst relative error of `f` against f64 `exp(-u)` on a grid of [0, 87] fine
    /// enough to put many points in every table step (ln2/32 = 0.0217), plus the ends.
    fn worst_relative_error(f: fn(f32) -> f32) -> f64 {
        let mut worst = 0.0f64;
        let mut check = |u: f32| {
            let want = libm::exp(-f64::from(u));
            worst = worst.max((f64::from(f(u)) - want).abs() / want);
        };
        for i in 0..=870_000 {
            check(i as f32 * 1e-4);
        }
        // Every f32 in the first table steps, where s and the polynomial are exercised
        // at full f32 resolution.
        let mut u = 0.0f32;
        while u < 0.05 {
            check(u);
            u = f32::from_bits(u.to_bits() + 97);
        }
        check(EXP_NEG_MAX_U);
        worst
    }

    #[test]
    fn table_entries_are_powers_of_two_to_the_512ths() {
        for (j, &bits) in EXP2_STEP_BITS.iter().enumerate() {
            let want = libm::exp2(j as f64 / TABLE_LEN as f64) as f32;
            let entry = bits.wrapping_add((j as u32) << (23 - TABLE_BITS));
            assert_eq!(entry, want.to_bits(), "{j}");
        }
    }

    #[test]
    fn table_kernel_relative_error_below_1e_6() {
        let worst = worst_relative_error(exp_neg_table_f32);
        println!("exp_neg_table_f32 worst relative error over [0, 87]: {worst:.3e}");
        assert!(worst <= 1e-6, "{worst:e}");
    }

    #[test]
    fn polynomial_kernel_relative_error_below_1e_6() {
        let worst = worst_relative_error(exp_neg_f32);
        println!("exp_neg_f32 worst relative error over [0, 87]: {worst:.3e}");
        assert!(worst <= 1e-6, "{worst:e}");
    }

    #[test]
    fn kernels_give_zero_beyond_the_range_and_one_at_zero() {
        assert_eq!(exp_neg_f32(0.0), 1.0);
        // The table kernel's minimax constant is 1 + 2^-23 (one f32 step above 1).
        assert_eq!(exp_neg_table_f32(0.0), 1.0 + f32::EPSILON);
        for f in [exp_neg_f32 as fn(f32) -> f32, exp_neg_table_f32] {
            assert_eq!(f(87.001), 0.0);
            assert_eq!(f(1e30), 0.0);
            assert_eq!(f(f32::INFINITY), 0.0);
            assert_eq!(f(f32::NAN), 0.0);
            assert!(f(EXP_NEG_MAX_U) > 0.0);
        }
    }

    /// The kernels are monotone where the Gaussian's ranking of centres relies on it.
    #[test]
    fn table_kernel_is_non_increasing() {
        let mut prev = exp_neg_table_f32(0.0);
        for i in 1..=87_000 {
            let v = exp_neg_table_f32(i as f32 * 1e-3);
            assert!(v <= prev, "at u = {}", i as f32 * 1e-3);
            prev = v;
        }
    }
}
