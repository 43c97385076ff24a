//! Local-polynomial (Savitzky-Golay) first and second derivatives of any column, with the
//! window half-width chosen on the column itself by leave-one-out validation.
//!
//! Why: one fixed window is wrong for somebody. A thermometer quantised to 0.0625 degC
//! needs a wide window before its slope means anything; a clean, fast-changing column
//! needs a narrow one or its derivative is smeared. For derivative order `nu` the column is
//! fitted by least squares with a polynomial of degree p = nu + 1 (p - nu odd: no extra
//! boundary bias) over the samples within `h` of each point; the derivative is the fit's
//! nu-th coefficient. That fit is a linear smoother of the column, so its leave-one-out
//! error is known in closed form: (x_i - xhat_i) / (1 - h_ii), h_ii the leverage of point i
//! in its own window. For every column and order the half-width with the smallest pooled
//! leave-one-out mean square over all runs is chosen from a log-spaced grid
//! ([`HALF_WIDTHS_ROWS`], 2 to 64 row spacings): a general rule, no constant tuned to a
//! generator.
//!
//! Edges are honest: a window holds only samples that exist (one-sided near the ends of a
//! run), widened on the side that has samples until it holds p + 2 points; nothing is
//! padded or mirrored. Cost: one (p + 1)-square solve per point, half-width and column,
//! on the 10 s means (never on raw rows).
//!
//! Part of the input stage: the widths are chosen once per column when the campaign is
//! prepared, and every later stage (baseline, candidates) reads them from there.

use nalgebra::{Matrix4, Vector4};
use serde::Serialize;

/// Half-widths tried, in row spacings: 2 x 2^(k/2), k = 0..=10 (2 .. 64 rows; for 10 s
/// means 20 .. 640 s). In rows, so that sparse records (one mean per burst) get a choice too.
pub const HALF_WIDTHS_ROWS: [f64; 11] = [
    2.0, 2.828, 4.0, 5.657, 8.0, 11.31, 16.0, 22.63, 32.0, 45.25, 64.0,
];

/// Median spacing of the rows over every run, s (`fallback_s` with fewer than two rows).
pub fn median_spacing_s(runs: &[(&[f64], &[f64])], fallback_s: f64) -> f64 {
    let mut dt: Vec<f64> = runs
        .iter()
        .flat_map(|(t, _)| t.windows(2).map(|w| w[1] - w[0]))
        .collect();
    dt.sort_by(f64::total_cmp);
    dt.get(dt.len() / 2).copied().unwrap_or(fallback_s)
}

/// Polynomial degree used for derivative order `order` (1 or 2).
pub fn degree_for(order: usize) -> usize {
    order + 1
}

/// One local fit: the polynomial's coefficients in u = (t - t_i) / scale, the scale, and
/// the leverage of point i in its own window.
struct LocalFit {
    coef: [f64; 4],
    scale: f64,
    leverage: f64,
}

/// Fits a polynomial of `degree` (<= 3) to `x` over `t[lo..=hi]`, centred at `t0`.
fn fit_window(t: &[f64], x: &[f64], t0: f64, degree: usize) -> Option<LocalFit> {
    let p = degree + 1;
    let scale = t.iter().map(|v| (v - t0).abs()).fold(0.0, f64::max);
    if scale <= 0.0 || t.len() < p {
        return None;
    }
    // The upper triangle summed in plain arrays, then mirrored (a product and its mirror
    // are the same number, so this is the full sum's every bit at half the work).
    let mut upper = [[0.0f64; 4]; 4];
    let mut rhs = [0.0f64; 4];
    for (&ti, &xi) in t.iter().zip(x) {
        let u = (ti - t0) / scale;
        let pw = [1.0, u, u * u, u * u * u];
        for r in 0..p {
            rhs[r] += pw[r] * xi;
            for c in r..p {
                upper[r][c] += pw[r] * pw[c];
            }
        }
    }
    let mut a = Matrix4::<f64>::zeros();
    let b = Vector4::from(rhs);
    for r in 0..p {
        for c in r..p {
            a[(r, c)] = upper[r][c];
            a[(c, r)] = upper[r][c];
        }
    }
    // unused dimensions: identity rows, so they solve to 0 and leave the rest unchanged
    for r in p..4 {
        a[(r, r)] = 1.0;
    }
    let chol = a.cholesky()?;
    let c = chol.solve(&b);
    let e0 = chol.solve(&Vector4::new(1.0, 0.0, 0.0, 0.0));
    let coef = [c[0], c[1], c[2], c[3]];
    if coef.iter().any(|v| !v.is_finite()) || !e0[0].is_finite() {
        return None;
    }
    Some(LocalFit {
        coef,
        scale,
        leverage: e0[0],
    })
}

/// The window `[lo, hi]` around `i`: every sample within `half_s`, widened on the side
/// with samples (the nearer one first) until it holds `need` points (or the whole run).
fn window(t: &[f64], i: usize, half_s: f64, need: usize) -> (usize, usize) {
    let n = t.len();
    let (mut lo, mut hi) = (i, i);
    while lo > 0 && t[i] - t[lo - 1] <= half_s * (1.0 + 1e-9) {
        lo -= 1;
    }
    while hi + 1 < n && t[hi + 1] - t[i] <= half_s * (1.0 + 1e-9) {
        hi += 1;
    }
    while hi - lo + 1 < need && (lo > 0 || hi + 1 < n) {
        let left = (lo > 0).then(|| t[i] - t[lo - 1]);
        let right = (hi + 1 < n).then(|| t[hi + 1] - t[i]);
        match (left, right) {
            (Some(l), Some(r)) if l <= r => lo -= 1,
            (Some(_), None) => lo -= 1,
            _ => hi += 1,
        }
    }
    (lo, hi)
}

fn factorial(k: usize) -> f64 {
    (1..=k).product::<usize>() as f64
}

/// Derivative of `order` (1 or 2) of `x(t)` at every sample, from the local polynomial of
/// degree `order + 1` over a centred window of `half_s` (see the module header for the
/// edges). 0 where no fit exists (fewer than `order + 2` samples in the whole run).
pub fn centred(t: &[f64], x: &[f64], order: usize, half_s: f64) -> Vec<f64> {
    let degree = degree_for(order);
    (0..t.len())
        .map(|i| {
            let (lo, hi) = window(t, i, half_s, degree + 2);
            fit_window(&t[lo..=hi], &x[lo..=hi], t[i], degree).map_or(0.0, |f| {
                factorial(order) * f.coef[order] / f.scale.powi(order as i32)
            })
        })
        .collect()
}

/// Pooled leave-one-out sum of squares and count of the degree-`order + 1` local fit with
/// half-width `half_s` over every run of one column.
fn loo_sum(runs: &[(&[f64], &[f64])], order: usize, half_s: f64) -> (f64, usize) {
    let degree = degree_for(order);
    let mut sum = 0.0;
    let mut count = 0;
    for &(t, x) in runs {
        for i in 0..t.len() {
            let (lo, hi) = window(t, i, half_s, degree + 2);
            let Some(f) = fit_window(&t[lo..=hi], &x[lo..=hi], t[i], degree) else {
                continue;
            };
            let keep = 1.0 - f.leverage;
            if keep > 1e-9 {
                let r = (x[i] - f.coef[0]) / keep;
                sum += r * r;
                count += 1;
            }
        }
    }
    (sum, count)
}

/// Median over every point of every run of the window's actual half-span (the farthest
/// sample from the centre), s: larger than `half_s` where rows are sparse (the window is
/// widened to `order + 3` points), smaller where the run is short.
pub fn effective_half_width_s(runs: &[(&[f64], &[f64])], order: usize, half_s: f64) -> f64 {
    let need = degree_for(order) + 2;
    let mut spans: Vec<f64> = runs
        .iter()
        .flat_map(|&(t, _)| {
            (0..t.len()).map(move |i| {
                let (lo, hi) = window(t, i, half_s, need);
                (t[i] - t[lo]).max(t[hi] - t[i])
            })
        })
        .collect();
    spans.sort_by(f64::total_cmp);
    spans.get(spans.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A grid point's leave-one-out rms.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GridScore {
    pub half_width_s: f64,
    /// Leave-one-out rms of the local fit, in the column's units.
    pub loo_rms: f64,
}

/// The half-width chosen for one column and derivative order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WidthChoice {
    pub column: String,
    /// `rate` (d/dt) or `accel` (d2/dt2).
    pub derivative: &'static str,
    pub poly_degree: usize,
    pub half_width_s: f64,
    /// The windows' actual half-span at that width (median), s: see
    /// [`effective_half_width_s`].
    pub effective_half_width_s: f64,
    /// Leave-one-out rms at the chosen half-width, column units.
    pub loo_rms: f64,
    /// Every half-width tried.
    pub grid: Vec<GridScore>,
}

/// Chooses the half-width of the order-`order` derivative of one column (stacked over
/// `runs`, each `(t_s, x)`): the grid point ([`HALF_WIDTHS_ROWS`] x the median row
/// spacing) with the smallest leave-one-out mean square (the narrowest on a tie). `None`
/// when no grid point can be validated (every run has fewer than `order + 3` samples).
pub fn choose(column: &str, runs: &[(&[f64], &[f64])], order: usize) -> Option<WidthChoice> {
    let dt = median_spacing_s(runs, super::window::WINDOW_S);
    let grid: Vec<GridScore> = HALF_WIDTHS_ROWS
        .iter()
        .map(|k| k * dt)
        .filter_map(|h| {
            let (sum, count) = loo_sum(runs, order, h);
            (count > 0).then(|| GridScore {
                half_width_s: h,
                loo_rms: (sum / count as f64).sqrt(),
            })
        })
        .collect();
    let best = grid
        .iter()
        .min_by(|a, b| a.loo_rms.total_cmp(&b.loo_rms))?
        .clone();
    Some(WidthChoice {
        column: column.to_owned(),
        derivative: if order == 1 { "rate" } else { "accel" },
        poly_degree: degree_for(order),
        half_width_s: best.half_width_s,
        effective_half_width_s: effective_half_width_s(runs, order, best.half_width_s),
        loo_rms: best.loo_rms,
        grid,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn derivatives_of_a_quadratic_are_exact_everywhere() {
        let t: Vec<f64> = (0..40).map(|i| 10.0 * i as f64).collect();
        let x: Vec<f64> = t.iter().map(|t| 3.0 + 0.2 * t + 0.001 * t * t).collect();
        let r = centred(&t, &x, 1, 30.0);
        let a = centred(&t, &x, 2, 60.0);
        for i in 0..t.len() {
            assert!((a[i] - 0.002).abs() < 1e-9, "accel at {i}: {}", a[i]);
            // degree 2 for the rate: exact on a parabola at the edges too
            assert!((r[i] - (0.2 + 0.002 * t[i])).abs() < 1e-9, "rate at {i}");
        }
    }

    #[test]
    fn a_short_run_uses_what_it_has() {
        let t = [10.0, 20.0, 30.0];
        assert_eq!(centred(&t, &[1.0, 2.0, 3.0], 2, 20.0), vec![0.0; 3]);
        let r = centred(&t, &[1.0, 2.0, 3.0], 1, 20.0);
        assert!(r.iter().all(|v| (v - 0.1).abs() < 1e-12), "{r:?}");
    }

    /// A smooth temperature (two exponential modes), `noise` degC white noise, then
    /// quantised to `step_c`.
    fn thermometer(noise: f64, step_c: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let g = Normal::new(0.0, 1.0).unwrap();
        let t: Vec<f64> = (1..=270).map(|k| 10.0 * k as f64).collect();
        let x = t
            .iter()
            .map(|t| {
                let v = 20.0 + 3.0 * (1.0 - (-t / 150.0).exp()) + 4.0 * (1.0 - (-t / 900.0).exp());
                let v = v + noise * g.sample(&mut rng);
                if step_c > 0.0 {
                    (v / step_c).round() * step_c
                } else {
                    v
                }
            })
            .collect();
        (t, x)
    }

    #[test]
    fn coarse_thermometers_get_wider_windows_than_clean_ones() {
        let (t, clean) = thermometer(1e-4, 0.0, 1);
        let (_, coarse) = thermometer(0.01, 0.0625, 1);
        for order in [1, 2] {
            let h_clean = choose("c", &[(&t, &clean)], order).unwrap().half_width_s;
            let h_coarse = choose("q", &[(&t, &coarse)], order).unwrap().half_width_s;
            assert!(
                h_coarse > h_clean,
                "order {order}: coarse {h_coarse} s vs clean {h_clean} s"
            );
        }
    }
}
