//! Equivalent degrees of freedom of the Allan-family estimators: Greenhall's algorithm
//! (C. A. Greenhall, W. J. Riley, "Uncertainty of stability variances based on finite
//! differences", PTTI 2003) for ADEV, MDEV/TDEV and HDEV, and NIST SP 1065 Table 7 for
//! TOTDEV, with the same cases, tables and fallbacks as allantools' `edf_greenhall`,
//! `edf_totdev` and `edf_simple`. `alpha` is the power-law exponent of the rate noise
//! (S_y ~ f^alpha: 2 white angle/quantisation, 0 white rate = ARW, -1 flicker rate =
//! bias instability, -2 random walk of the rate = RRW).

use super::deviation::Kind;

/// Summation length above which Greenhall's tables replace the exact sum.
const J_MAX: f64 = 100.0;

/// Greenhall's generalized autocovariance w(t) for noise exponent `alpha` (eq. 7).
fn sw(t: f64, alpha: i32) -> f64 {
    let log_term = |p: i32| {
        if t == 0.0 {
            0.0
        } else {
            t.powi(p) * t.abs().ln()
        }
    };
    match alpha {
        2 => -t.abs(),
        1 => log_term(2),
        0 => t.abs().powi(3),
        -1 => log_term(4),
        -2 => t.abs().powi(5),
        -3 => log_term(6),
        _ => t.abs().powi(7), // -4, the lowest exponent the estimators accept
    }
}

/// Eq. 8: the filter of `F` (infinite F: the unfiltered limit).
fn sx(t: f64, f: f64, alpha: i32) -> f64 {
    if f.is_infinite() {
        return sw(t, alpha + 2);
    }
    f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha))
}

/// Eq. 9: the d-th difference (binomial weights).
fn sz(t: f64, f: f64, alpha: i32, d: usize) -> f64 {
    let weights: &[f64] = match d {
        1 => &[2.0, -1.0],
        2 => &[6.0, -4.0, 1.0],
        _ => &[20.0, -15.0, 6.0, -1.0],
    };
    weights
        .iter()
        .enumerate()
        .map(|(k, w)| {
            if k == 0 {
                w * sx(t, f, alpha)
            } else {
                let k = k as f64;
                w * (sx(t - k, f, alpha) + sx(t + k, f, alpha))
            }
        })
        .sum()
}

/// Eq. 10: the basic sum.
fn basic_sum(j: f64, m: f64, s: f64, f: f64, alpha: i32, d: usize) -> f64 {
    let first = sz(0.0, f, alpha, d).powi(2);
    let second = (1.0 - j / m) * sz(j / s, f, alpha, d).powi(2);
    let third: f64 = (1..j as usize)
        .map(|i| {
            let i = i as f64;
            2.0 * (1.0 - i / m) * sz(i / s, f, alpha, d).powi(2)
        })
        .sum();
    first + second + third
}

/// Row of Greenhall's tables for alpha (2 -> 0 ... -4 -> 6).
fn row(alpha: i32) -> usize {
    (2 - alpha) as usize
}

/// Table 1 (modified variances), (a0, a1); None where undefined.
fn table1(alpha: i32, d: usize) -> Option<(f64, f64)> {
    const T: [[(f64, f64); 3]; 7] = [
        [
            (2.0 / 3.0, 1.0 / 3.0),
            (7.0 / 9.0, 1.0 / 2.0),
            (22.0 / 25.0, 2.0 / 3.0),
        ],
        [(0.840, 0.345), (0.997, 0.616), (1.141, 0.843)],
        [(1.079, 0.368), (1.033, 0.607), (1.184, 0.848)],
        [(-1.0, -1.0), (1.048, 0.534), (1.180, 0.816)],
        [(-1.0, -1.0), (1.302, 0.535), (1.175, 0.777)],
        [(-1.0, -1.0), (-1.0, -1.0), (1.194, 0.703)],
        [(-1.0, -1.0), (-1.0, -1.0), (1.489, 0.702)],
    ];
    let v = T[row(alpha)][d - 1];
    (v.0 > 0.0).then_some(v)
}

/// Table 2 (unmodified variances), (a0, a1); None where undefined.
fn table2(alpha: i32, d: usize) -> Option<(f64, f64)> {
    const T: [[(f64, f64); 3]; 7] = [
        [
            (3.0 / 2.0, 1.0 / 2.0),
            (35.0 / 18.0, 1.0),
            (231.0 / 100.0, 3.0 / 2.0),
        ],
        [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
        [
            (2.0 / 3.0, 1.0 / 6.0),
            (2.0 / 3.0, 1.0 / 3.0),
            (7.0 / 9.0, 1.0 / 2.0),
        ],
        [(-1.0, -1.0), (0.852, 0.375), (0.997, 0.617)],
        [(-1.0, -1.0), (1.079, 0.368), (1.033, 0.607)],
        [(-1.0, -1.0), (-1.0, -1.0), (1.053, 0.553)],
        [(-1.0, -1.0), (-1.0, -1.0), (1.302, 0.535)],
    ];
    let v = T[row(alpha)][d - 1];
    (v.0 > 0.0).then_some(v)
}

/// Table 3 (alpha = 1, unmodified), (b0, b1).
fn table3(d: usize) -> (f64, f64) {
    [(6.0, 4.0), (15.23, 12.0), (47.8, 40.0)][d - 1]
}

fn binomial(n: u64, k: u64) -> f64 {
    (1..=k).fold(1.0, |acc, i| acc * (n + 1 - i) as f64 / i as f64)
}

/// Greenhall's EDF of a d-th difference variance at factor `m` on `n` phase points,
/// overlapping (stride 1) or not, modified (MDEV) or not. None where the algorithm has
/// no case (alpha + 2d <= 1, or alpha = 2 with too few terms).
pub fn greenhall(
    alpha: i32,
    d: usize,
    m: usize,
    n: usize,
    overlapping: bool,
    modified: bool,
) -> Option<f64> {
    if !(1..=3).contains(&d) || !(-4..=2).contains(&alpha) || alpha + 2 * d as i32 <= 1 {
        return None;
    }
    let mf = m as f64;
    let f = if modified { 1.0 } else { mf };
    let s = if overlapping { mf } else { 1.0 };
    let df = d as f64;
    let l = mf / f + mf * df;
    let big_m = 1.0 + (s * (n as f64 - l) / mf).floor();
    if big_m < 1.0 {
        return None;
    }
    let j = big_m.min((df + 1.0) * s);
    let r = big_m / s;
    let inv = if modified {
        if j <= J_MAX {
            basic_sum(j, big_m, s, 1.0, alpha, d) / (sz(0.0, 1.0, alpha, d).powi(2) * big_m)
        } else if r > df + 1.0 {
            let (a0, a1) = table1(alpha, d)?;
            (a0 - a1 / r) / r
        } else {
            let mp = J_MAX / r;
            basic_sum(J_MAX, J_MAX, mp, 1.0, alpha, d) / (sz(0.0, 1.0, alpha, d).powi(2) * J_MAX)
        }
    } else if alpha <= 0 {
        if j <= J_MAX {
            let mp = if mf * (df + 1.0) <= J_MAX {
                mf
            } else {
                f64::INFINITY
            };
            basic_sum(j, big_m, s, mp, alpha, d) / (sz(0.0, mp, alpha, d).powi(2) * big_m)
        } else if r > df + 1.0 {
            let (a0, a1) = table2(alpha, d)?;
            (a0 - a1 / r) / r
        } else {
            let mp = J_MAX / r;
            basic_sum(J_MAX, J_MAX, mp, f64::INFINITY, alpha, d)
                / (sz(0.0, f64::INFINITY, alpha, d).powi(2) * J_MAX)
        }
    } else if alpha == 1 {
        let (b0, b1) = table3(d);
        if j <= J_MAX {
            basic_sum(j, big_m, s, mf, 1, d) / (sz(0.0, mf, 1, d).powi(2) * big_m)
        } else if r > df + 1.0 {
            let (a0, a1) = table2(alpha, d)?;
            (a0 - a1 / r) / ((b0 + b1 * mf.ln()).powi(2) * r)
        } else {
            let mp = J_MAX / r;
            basic_sum(J_MAX, J_MAX, mp, mp, 1, d) / ((b0 + b1 * mf.ln()).powi(2) * J_MAX)
        }
    } else {
        // alpha = 2, unmodified.
        if r.ceil() <= df {
            return None;
        }
        let d64 = d as u64;
        let a0 = binomial(4 * d64, 2 * d64) / binomial(2 * d64, d64).powi(2);
        (a0 - (df / 2.0) / r) / big_m
    };
    (inv > 0.0 && inv.is_finite()).then(|| 1.0 / inv)
}

/// NIST SP 1065's simple EDF formulas (Table 5), allantools' `edf_simple`; n - 1 outside
/// alpha 2..-2.
pub fn simple(n: usize, m: usize, alpha: i32) -> f64 {
    let (n, m) = (n as f64, m as f64);
    match alpha {
        2 => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        1 => {
            let a = (n - 1.0) / (2.0 * m);
            let b = (2.0 * m + 1.0) * (n - 1.0) / 4.0;
            (a.ln() * b.ln()).sqrt().exp()
        }
        0 => {
            (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n)
                * (4.0 * m * m / (4.0 * m * m + 5.0))
        }
        -1 if m < 2.0 => 2.0 * (n - 2.0) / (2.3 * n - 4.9),
        -1 => 5.0 * n * n / (4.0 * m * (n + 3.0 * m)),
        -2 => {
            (n - 2.0) / (m * (n - 3.0).powi(2))
                * ((n - 1.0).powi(2) - 3.0 * m * (n - 1.0) + 4.0 * m * m)
        }
        _ => n - 1.0,
    }
}

/// EDF of the total deviation, NIST SP 1065 Table 7: b n / m - c for alpha 0, -1, -2.
pub fn totdev(n: usize, m: usize, alpha: i32) -> f64 {
    let (b, c) = match alpha {
        0 => (1.50, 0.0),
        -1 => (1.17, 0.22),
        -2 => (0.93, 0.36),
        _ => return simple(n, m, alpha),
    };
    b * n as f64 / m as f64 - c
}

/// The EDF of `kind` (as computed here: ADEV and HDEV overlapping) at factor `m` on `n`
/// phase points for noise exponent `alpha`, clamped to the exponents the estimator
/// accepts; the simple formulas where Greenhall's algorithm has no case.
pub fn for_kind(kind: Kind, alpha: i32, m: usize, n: usize) -> f64 {
    let d = kind.difference_order();
    let lowest = 2 - 2 * d as i32;
    let alpha = alpha.clamp(lowest, 2);
    let edf = match kind {
        Kind::Adev | Kind::Hdev => greenhall(alpha, d, m, n, true, false),
        Kind::Mdev | Kind::Tdev => greenhall(alpha, d, m, n, true, true),
        Kind::Totdev => Some(totdev(n, m, alpha)),
    };
    edf.filter(|e| *e > 0.0)
        .unwrap_or_else(|| simple(n, m, alpha.max(-2)).max(1.0))
}
