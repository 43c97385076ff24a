//! Levels: does the bias level follow one law across runs, or is every run's level free?
//!
//! Within a run the base is fitted with a free offset per run, which throws away what the
//! run levels say about the law (a bias-vs-temperature law holds at every ambient, so the
//! runs' levels pin down its shape across the whole temperature range). Two treatments of
//! the levels are scored on the same held-out runs, on the *absolute* drift of a run never
//! seen (its level included):
//!
//! - `shared`: one law with one intercept across runs plus a random turn-on offset per run
//!   (the repeatability, a variance component). Fitted by random-effects GLS: each run is
//!   quasi-demeaned by theta = 1 - sqrt(s2 / (s2 + n sigma_u^2)), theta chosen from a grid
//!   on held-out runs (a misfit within runs makes the moment estimate of sigma_u useless:
//!   it then sits near the free fit). The repeatability is the spread of the offsets the
//!   chosen fit leaves minus the run means' own noise (white variance x the AR(1)
//!   inflation of the residual, / n). A held-out run is predicted with its offset at 0.
//! - `free`: the law fitted within runs only (free offsets); a held-out run's level is
//!   predicted by the mean of the training runs' offsets.
//!
//! Everything is computed from per-run sums (Gram, X'y, means), so a leave-one-run-out fit
//! or a bootstrap replicate is one small solve.

use crate::diagnose::linalg::solve_spd;
use crate::diagnose::validation::design::Design;
use serde::Serialize;

/// How a law treats the runs' levels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Law {
    /// One law and intercept across runs, random turn-on offsets.
    Shared,
    /// Free offset per run.
    Free,
}

/// Quasi-demeaning weights tried for the shared law, chosen on held-out runs: theta =
/// 1 - sqrt(s2 / (s2 + n sigma_u^2)) ranges from 0 (levels carry as much weight as any
/// row: pooled) to near 1 (within runs dominate); which ratio of turn-on spread to row
/// noise holds is read from the data, not assumed.
pub const THETAS: [f64; 8] = [0.0, 0.5, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995];

/// Per-run sums of the design z = [1, x...] and the target.
#[derive(Clone, Debug)]
struct RunSums {
    n: f64,
    /// Column means of z (first = 1).
    zbar: Vec<f64>,
    ybar: f64,
    /// sum z z' (q x q, row-major), sum z y, sum y^2.
    gram: Vec<f64>,
    zy: Vec<f64>,
    yy: f64,
}

/// A design's per-run sums, ready for any level treatment, run subset or weights.
#[derive(Clone, Debug)]
pub struct LevelSystems {
    runs: Vec<RunSums>,
    /// Columns including the intercept.
    q: usize,
    /// Ridge added to every non-intercept column, relative to its within-run energy.
    ridge: f64,
    diag_scale: Vec<f64>,
    /// Run-mean noise variance numerator: white variance x AR(1) inflation (s2_r = this / n_r).
    noise_var_inflated: f64,
}

/// Solved law: w = [intercept, coefficients...] and the variance component.
#[derive(Clone, Debug)]
pub struct LawFit {
    pub w: Vec<f64>,
    /// Run-level standard deviation left by the law (Shared), deg/h.
    pub sigma_u_dph: f64,
    /// Quasi-demeaning the law was fitted with.
    pub theta: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl LevelSystems {
    /// Sums of the `design`'s rows (raw, not demeaned; the intercept is added here) and
    /// `y` over `run_rows`, accumulated row by row; `ridge` relative as in `cv`.
    pub fn new<D: Design + ?Sized>(
        run_rows: &[std::ops::Range<usize>],
        design: &D,
        y: &[f64],
        ridge: f64,
    ) -> Self {
        let q = design.width() + 1;
        let mut runs = Vec::with_capacity(run_rows.len());
        let mut diag_scale = vec![0.0; q];
        let mut z = vec![1.0; q];
        for r in run_rows {
            let n = r.len() as f64;
            let mut gram = vec![0.0; q * q];
            let mut zy = vec![0.0; q];
            let mut zbar = vec![0.0; q];
            for row in r.clone() {
                design.row(row, &mut z[1..]);
                for i in 0..q {
                    let zi = z[i];
                    zbar[i] += zi;
                    zy[i] += zi * y[row];
                    for j in 0..=i {
                        gram[i * q + j] += zi * z[j];
                    }
                }
            }
            for i in 0..q {
                for j in 0..i {
                    gram[j * q + i] = gram[i * q + j];
                }
            }
            zbar.iter_mut().for_each(|v| *v /= n.max(1.0));
            let ybar = y[r.clone()].iter().sum::<f64>() / n.max(1.0);
            for i in 1..q {
                diag_scale[i] += gram[i * q + i] - n * zbar[i] * zbar[i];
            }
            runs.push(RunSums {
                n,
                zbar,
                ybar,
                gram,
                zy,
                yy: dot(&y[r.clone()], &y[r.clone()]),
            });
        }
        let mut s = Self {
            runs,
            q,
            ridge,
            diag_scale,
            noise_var_inflated: 0.0,
        };
        s.noise_var_inflated = s.within_noise(run_rows, design, y);
        s
    }

    /// Number of runs.
    pub fn runs(&self) -> usize {
        self.runs.len()
    }

    /// Run lengths (points).
    pub fn run_points(&self) -> Vec<f64> {
        self.runs.iter().map(|r| r.n).collect()
    }

    /// White-noise variance of the free-offset fit's residual times its AR(1) inflation
    /// (1 + rho) / (1 - rho): n_r x the variance of a run mean of that noise.
    fn within_noise<D: Design + ?Sized>(
        &self,
        run_rows: &[std::ops::Range<usize>],
        design: &D,
        y: &[f64],
    ) -> f64 {
        let all = vec![1.0; self.runs.len()];
        let Some(w) = self.solve_free(&all) else {
            return 0.0;
        };
        let (mut s0, mut s1, mut n) = (0.0, 0.0, 0.0);
        let mut z = vec![0.0; design.width()];
        for (k, r) in run_rows.iter().enumerate() {
            let rs = &self.runs[k];
            let off = rs.ybar - dot(&rs.zbar[1..], &w[1..]);
            let mut prev: Option<f64> = None;
            for row in r.clone() {
                design.row(row, &mut z);
                let e = y[row] - off - z.iter().zip(&w[1..]).map(|(c, b)| c * b).sum::<f64>();
                s0 += e * e;
                n += 1.0;
                if let Some(p) = prev {
                    s1 += e * p;
                }
                prev = Some(e);
            }
        }
        if n < 2.0 || s0 <= 0.0 {
            return 0.0;
        }
        let rho = (s1 / s0).clamp(-0.9, 0.99);
        s0 / n * (1.0 + rho) / (1.0 - rho)
    }

    /// Normal equations summed over runs with weights `counts` (0 leaves a run out) and
    /// quasi-demeaning `theta[r]` (1 = within runs only).
    fn system(&self, counts: &[f64], theta: &dyn Fn(usize) -> f64) -> (Vec<f64>, Vec<f64>) {
        let q = self.q;
        let mut a = vec![0.0; q * q];
        let mut b = vec![0.0; q];
        for (k, rs) in self.runs.iter().enumerate() {
            let c = counts[k];
            if c == 0.0 {
                continue;
            }
            let th = theta(k);
            let s = (2.0 * th - th * th) * rs.n;
            for i in 0..q {
                b[i] += c * (rs.zy[i] - s * rs.zbar[i] * rs.ybar);
                for j in 0..q {
                    a[i * q + j] += c * (rs.gram[i * q + j] - s * rs.zbar[i] * rs.zbar[j]);
                }
            }
        }
        (a, b)
    }

    fn solve_system(&self, mut a: Vec<f64>, mut b: Vec<f64>, free: bool) -> Option<Vec<f64>> {
        let q = self.q;
        let mean_diag = self.diag_scale[1..].iter().sum::<f64>() / (q - 1).max(1) as f64;
        for i in 1..q {
            a[i * q + i] += self.ridge * self.diag_scale[i] + 1e-12 * mean_diag + 1e-300;
        }
        if free {
            // The intercept is not identified within runs: pin it to 0.
            for j in 0..q {
                a[j] = 0.0;
                a[j * q] = 0.0;
            }
            a[0] = 1.0;
            b[0] = 0.0;
        }
        solve_spd(&mut a, &mut b, q).ok()?;
        Some(b)
    }

    /// The free-offset law (intercept = mean offset of the runs with weight).
    pub fn solve_free(&self, counts: &[f64]) -> Option<Vec<f64>> {
        let (a, b) = self.system(counts, &|_| 1.0);
        let mut w = self.solve_system(a, b, true)?;
        let (mut s, mut m) = (0.0, 0.0);
        for (k, rs) in self.runs.iter().enumerate() {
            s += counts[k] * (rs.ybar - dot(&rs.zbar[1..], &w[1..]));
            m += counts[k];
        }
        w[0] = s / m.max(1e-300);
        Some(w)
    }

    /// Run-level offsets left by the law `w` (run mean of drift minus the law).
    pub fn offsets_left(&self, w: &[f64]) -> Vec<f64> {
        self.runs
            .iter()
            .map(|rs| rs.ybar - dot(&rs.zbar, w))
            .collect()
    }

    /// The shared law with quasi-demeaning `theta` (0: pooled, near 1: mostly within runs).
    pub fn solve_shared(&self, counts: &[f64], theta: f64) -> Option<LawFit> {
        let (a, b) = self.system(counts, &|_| theta);
        let w = self.solve_system(a, b, false)?;
        let sigma_u_dph = self.level_variance(&w, counts).sqrt();
        Some(LawFit {
            w,
            sigma_u_dph,
            theta,
        })
    }

    /// Variance of the offsets the law leaves (weighted), minus the run means' own noise.
    fn level_variance(&self, w: &[f64], counts: &[f64]) -> f64 {
        let o = self.offsets_left(w);
        let m_tot: f64 = counts.iter().sum();
        if m_tot < 2.0 {
            return 0.0;
        }
        let mean = o.iter().zip(counts).map(|(v, c)| v * c).sum::<f64>() / m_tot;
        let var = o
            .iter()
            .zip(counts)
            .map(|(v, c)| c * (v - mean) * (v - mean))
            .sum::<f64>()
            / (m_tot - 1.0);
        let noise = self
            .runs
            .iter()
            .zip(counts)
            .map(|(rs, c)| c * self.noise_var_inflated / rs.n.max(1.0))
            .sum::<f64>()
            / m_tot;
        (var - noise).max(0.0)
    }

    /// Squared error of the law `w` (absolute: level included) over run k.
    fn run_sse(&self, k: usize, w: &[f64]) -> f64 {
        let rs = &self.runs[k];
        let q = self.q;
        let mut gw = 0.0;
        for i in 0..q {
            gw += w[i] * dot(&rs.gram[i * q..(i + 1) * q], w);
        }
        (rs.yy - 2.0 * dot(w, &rs.zy) + gw).max(0.0)
    }

    /// Leave-one-run-out per-run held-out SSE of the absolute drift with free offsets.
    pub fn heldout_free(&self) -> Option<Vec<f64>> {
        self.heldout_with(&|c| self.solve_free(c))
    }

    /// Leave-one-run-out per-run held-out SSE of the shared law at every quasi-demeaning
    /// of `THETAS`; the best total and its theta.
    pub fn heldout_shared(&self) -> Option<(Vec<f64>, f64)> {
        THETAS
            .iter()
            .filter_map(|&th| {
                let sse = self.heldout_with(&|c| self.solve_shared(c, th).map(|f| f.w))?;
                Some((sse, th))
            })
            .min_by(|a, b| a.0.iter().sum::<f64>().total_cmp(&b.0.iter().sum::<f64>()))
    }

    /// Leave-one-run-out level errors of the shared law at `theta`: run mean of the drift
    /// minus the law's prediction for a run it never saw (its offset at 0).
    pub fn heldout_level_errors(&self, theta: f64) -> Option<Vec<f64>> {
        let r = self.runs.len();
        (0..r)
            .map(|k| {
                let mut counts = vec![1.0; r];
                counts[k] = 0.0;
                let w = self.solve_shared(&counts, theta)?.w;
                let rs = &self.runs[k];
                Some(rs.ybar - dot(&rs.zbar, &w))
            })
            .collect()
    }

    /// This design plus run-level columns (`features[run]`, constant within each run):
    /// a between-run candidate inside the law, so it is tested as fitted with it.
    pub fn with_run_features(&self, features: &[Vec<f64>]) -> Self {
        let k = features.first().map_or(0, Vec::len);
        let (q0, q) = (self.q, self.q + k);
        let mut runs = Vec::with_capacity(self.runs.len());
        let mut between = vec![0.0; k];
        let fmean: Vec<f64> = (0..k)
            .map(|j| features.iter().map(|f| f[j]).sum::<f64>() / features.len().max(1) as f64)
            .collect();
        for (rs, f) in self.runs.iter().zip(features) {
            let mut gram = vec![0.0; q * q];
            for i in 0..q0 {
                gram[i * q..i * q + q0].copy_from_slice(&rs.gram[i * q0..(i + 1) * q0]);
            }
            for a in 0..k {
                for i in 0..q0 {
                    let v = f[a] * rs.n * rs.zbar[i];
                    gram[i * q + q0 + a] = v;
                    gram[(q0 + a) * q + i] = v;
                }
                for b in 0..k {
                    gram[(q0 + a) * q + q0 + b] = rs.n * f[a] * f[b];
                }
                between[a] += rs.n * (f[a] - fmean[a]).powi(2);
            }
            let mut zbar = rs.zbar.clone();
            zbar.extend_from_slice(f);
            let mut zy = rs.zy.clone();
            zy.extend(f.iter().map(|v| v * rs.n * rs.ybar));
            runs.push(RunSums {
                n: rs.n,
                zbar,
                ybar: rs.ybar,
                gram,
                zy,
                yy: rs.yy,
            });
        }
        let mut diag_scale = self.diag_scale.clone();
        diag_scale.extend(between.iter().map(|b| b * 1e-6));
        Self {
            runs,
            q,
            ridge: self.ridge,
            diag_scale,
            noise_var_inflated: self.noise_var_inflated,
        }
    }

    fn heldout_with(&self, solve: &dyn Fn(&[f64]) -> Option<Vec<f64>>) -> Option<Vec<f64>> {
        let r = self.runs.len();
        (0..r)
            .map(|k| {
                let mut counts = vec![1.0; r];
                counts[k] = 0.0;
                Some(self.run_sse(k, &solve(&counts)?))
            })
            .collect()
    }
}

/// A held-out score with its standard error over the held-out runs.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Score {
    pub heldout_rms_dph: f64,
    pub standard_error_dph: f64,
}

/// Sum of per-unit values over the units' `points` (a mean square per point) and its
/// variance (ratio estimator over units; NaN for one unit).
pub fn ratio_estimate(per_unit: &[f64], points: &[f64]) -> (f64, f64) {
    let k = per_unit.len() as f64;
    let n: f64 = points.iter().sum();
    let ratio = per_unit.iter().sum::<f64>() / n.max(1e-300);
    let var = if k > 1.0 {
        k / (k - 1.0)
            * per_unit
                .iter()
                .zip(points)
                .map(|(s, m)| (s - ratio * m).powi(2))
                .sum::<f64>()
            / (n * n)
    } else {
        f64::NAN
    };
    (ratio, var)
}

/// rms of per-run SSEs over `points`, and its standard error (ratio estimator over runs,
/// delta method to the rms).
pub fn score(sse: &[f64], points: &[f64]) -> Score {
    let (ratio, var) = ratio_estimate(sse, points);
    let rms = ratio.sqrt();
    Score {
        heldout_rms_dph: rms,
        standard_error_dph: var.sqrt() / (2.0 * rms.max(1e-300)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs at different ambients: bias 0.002 deg/h/degC across runs, plus a power-on
    /// transient the law does not contain (it biases the within-run slope). The shared
    /// law predicts a held-out run's level from its T, the free one cannot; with levels
    /// unrelated to T the shared law finds no slope.
    #[test]
    fn a_law_across_levels_wins_and_a_null_law_does_not() {
        let runs = 12;
        let n = 50;
        let mut t = Vec::new();
        let (mut y, mut y_null) = (Vec::new(), Vec::new());
        let mut rows = Vec::new();
        for r in 0..runs {
            let amb = -30.0 + 7.0 * r as f64;
            let off = 0.004 * ((r as f64 * 12.9898).sin() * 43_758.5).fract();
            rows.push(t.len()..t.len() + n);
            for k in 0..n {
                let decay = (-(k as f64) / 15.0).exp();
                let temp = amb + 10.0 * (1.0 - decay);
                let noise = 0.002 * ((k as f64 * 78.233 + r as f64).sin() * 43_758.5).fract();
                t.push(temp);
                y.push(0.002 * temp + 0.05 * decay + off + noise);
                y_null.push(off + noise + 0.05 * decay + 0.01 * (r % 3) as f64);
            }
        }
        let cols = vec![t.clone()];
        let lv = LevelSystems::new(&rows, cols.as_slice(), &y, 1e-8);
        let pts = lv.run_points();
        let (sse, theta) = lv.heldout_shared().unwrap();
        let shared = score(&sse, &pts);
        let free = score(&lv.heldout_free().unwrap(), &pts);
        assert!(
            shared.heldout_rms_dph + 2.0 * shared.standard_error_dph < free.heldout_rms_dph,
            "{shared:?} {free:?}"
        );
        let fit = lv.solve_shared(&vec![1.0; runs], theta).unwrap();
        assert!((fit.w[1] - 0.002).abs() < 3e-4, "{:?} theta {theta}", fit.w);
        let free_w = lv.solve_free(&vec![1.0; runs]).unwrap();
        assert!(
            free_w[1] < 0.0,
            "the transient biases the within slope: {free_w:?}"
        );
        let lv0 = LevelSystems::new(&rows, cols.as_slice(), &y_null, 1e-8);
        let (_, theta0) = lv0.heldout_shared().unwrap();
        let null_fit = lv0.solve_shared(&vec![1.0; runs], theta0).unwrap();
        assert!(
            null_fit.w[1].abs() < 5e-4,
            "no law in the levels, yet {:?}",
            null_fit.w
        );
    }
}
