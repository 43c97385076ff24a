//! What the generic peers of `diagnose` share (issue 18, issue 38 item 5): the candidate
//! library, the paper's base, grouped cross-validation over whole runs with the one-
//! standard-error rule, and the family-wise naming test. Kept in one place so that the
//! peers (`peer.rs`, the lasso; `peer_subset.rs`, best subsets) differ only in how they
//! pick the terms the naming test is offered, and a difference in their verdicts is the
//! selection's, not the library's or the test's.
//!
//! Rows are averaged to 10 s means; the library is built from every column and metadata key
//! (value, hinges at the deciles, d/dt and d2/dt2 over a fixed +/-3 row window, first-order
//! lags of 60 / 300 / 1500 s, stop operators (the column less its play, issue 38 item 6) at
//! 2.5 / 5 / 10 % of its median within-run range, products with temp_c and dT/dt, products
//! of the values of every two columns other than t_s and temp_c (issue 38 item 2:
//! `diagnose` screens these down to a few; a peer is offered them all and selects as it
//! selects the rest), sin/cos of `_deg` columns, level indicators of columns with <= 5
//! values, run means of every column, every metadata value); the base is 1, T, T^2, dT/dt
//! (one absolute intercept, no free run offsets). Naming: each selected term enters forward
//! (strongest first, given the base and the terms already named) while a sign-flip max test
//! over whole runs, the max taken over the whole library (family-wise at each step;
//! within-run and run-level columns as two families, Bonferroni), gives p < ALPHA; the
//! first term that fails ends the naming.

use fog_sim::diagnose::candidates::hysteresis::stop;
use fog_sim::io::runs::Run;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::ops::Range;

/// Family-wise level.
pub const ALPHA: f64 = 0.01;
const FLIPS: usize = 999;
const BIN_S: f64 = 10.0;
const DERIV_HALF_ROWS: usize = 3;
const LAGS_S: [f64; 3] = [60.0, 300.0, 1500.0];
const MAX_LEVELS: usize = 5;
/// Half-widths of the stop operators, as shares of a column's median within-run range.
const STOP_SHARES: [f64; 3] = [0.025, 0.05, 0.1];

/// A named term.
#[derive(Clone, Debug)]
pub struct Named {
    pub label: String,
    pub p_value: f64,
}

/// What a peer found.
#[derive(Clone, Debug)]
pub struct PeerReport {
    pub named: Vec<Named>,
    pub selected: usize,
    pub library_size: usize,
    /// Held-out rms gain of the lasso model over the base, %.
    pub cv_gain_pct: f64,
}

/// The stacked 10 s table of a campaign.
pub struct Table {
    /// Rows of each run.
    pub run_rows: Vec<Range<usize>>,
    /// Drift, deg/h.
    pub y: Vec<f64>,
    /// The paper's base: 1, T - Tm, (T - Tm)^2, dT/dt.
    pub base: Vec<Vec<f64>>,
    /// The candidate library: label, values.
    pub lib: Vec<(String, Vec<f64>)>,
}

pub fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// 10 s means of every column (rows already >= 10 s apart stay as they are).
fn binned(run: &Run, cols: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let t = run.t_s();
    let per_bin = run.sample_period_s() < BIN_S;
    let mut out: Vec<Vec<f64>> = vec![Vec::new(); cols.len()];
    let mut k = 0;
    while k < t.len() {
        let bin = (t[k] / BIN_S).floor();
        let mut e = k + 1;
        while per_bin && e < t.len() && (t[e] / BIN_S).floor() == bin {
            e += 1;
        }
        for (o, c) in out.iter_mut().zip(cols) {
            o.push(mean(&c[k..e]));
        }
        k = e;
    }
    out
}

fn derivative(x: &[f64], t: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            let (a, b) = (
                k.saturating_sub(DERIV_HALF_ROWS),
                (k + DERIV_HALF_ROWS).min(n - 1),
            );
            if b > a {
                (x[b] - x[a]) / (t[b] - t[a])
            } else {
                0.0
            }
        })
        .collect()
}

fn lagged(x: &[f64], t: &[f64], tau_s: f64) -> Vec<f64> {
    let mut y = x[0];
    x.iter()
        .enumerate()
        .map(|(k, v)| {
            let dt = if k > 0 { t[k] - t[k - 1] } else { 0.0 };
            y += (1.0 - (-dt / tau_s).exp()) * (v - y);
            y
        })
        .collect()
}

/// Distinct values of a column over the campaign, if at most MAX_LEVELS.
fn levels(runs: &[Run], name: &str) -> Option<Vec<f64>> {
    let mut seen: Vec<f64> = Vec::new();
    for v in runs
        .iter()
        .flat_map(|r| r.column(name).unwrap_or(&[]).iter())
    {
        if !seen.contains(v) {
            seen.push(*v);
            if seen.len() > MAX_LEVELS {
                return None;
            }
        }
    }
    seen.sort_by(f64::total_cmp);
    (seen.len() >= 2).then_some(seen)
}

/// The nine deciles of `v` (hinges there give a peer a feature a tenth of a column's
/// range wide, as `diagnose`'s splines of 10 knots; its 16-40 knots are not offered to
/// the peers, whose best-subset search grows as the fourth power of the library).
fn deciles(v: &[f64]) -> [f64; 9] {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    std::array::from_fn(|j| s[((s.len() - 1) as f64 * (j + 1) as f64 / 10.0) as usize])
}

/// Within-run features of one column, stacked over runs.
fn column_features(
    name: &str,
    x: &[f64],
    t: &[f64],
    temp: &[f64],
    dtemp: &[f64],
    tm: f64,
    few: bool,
) -> Vec<(String, Vec<f64>)> {
    let mut f: Vec<(String, Vec<f64>)> = Vec::new();
    let is_temp = name == "temp_c";
    if !is_temp {
        f.push((format!("{name}:value"), x.to_vec()));
    }
    if name == "t_s" {
        return f;
    }
    if !few {
        f.push((format!("{name}:rate"), derivative(x, t)));
    }
    if is_temp {
        f.push((format!("{name}:accel"), derivative(dtemp, t)));
        f.push((
            format!("{name}*temp_c:rate"),
            x.iter().zip(dtemp).map(|(a, b)| (a - tm) * b).collect(),
        ));
    } else {
        let xm = mean(x);
        f.push((
            format!("{name}*temp_c"),
            x.iter()
                .zip(temp)
                .map(|(a, b)| (a - xm) * (b - tm))
                .collect(),
        ));
        f.push((
            format!("{name}*temp_c:rate"),
            x.iter().zip(dtemp).map(|(a, b)| (a - xm) * b).collect(),
        ));
    }
    for tau in LAGS_S {
        f.push((format!("{name}:lag{tau}s"), lagged(x, t, tau)));
    }
    if name.ends_with("_deg") {
        f.push((
            format!("{name}:cos"),
            x.iter().map(|d| d.to_radians().cos()).collect(),
        ));
        f.push((
            format!("{name}:sin"),
            x.iter().map(|d| d.to_radians().sin()).collect(),
        ));
    }
    f
}

/// Products of the values of every two columns but time and temperature (the base's), each
/// less its run mean as the products with temp_c centre the column; `values[i]` is column
/// `names[i]` in one run.
fn pair_products(names: &[String], values: &[Vec<f64>]) -> Vec<(String, Vec<f64>)> {
    let centred: Vec<(&String, Vec<f64>)> = names
        .iter()
        .zip(values)
        .filter(|(n, _)| *n != "t_s" && *n != "temp_c")
        .map(|(n, x)| {
            let m = mean(x);
            (n, x.iter().map(|v| v - m).collect())
        })
        .collect();
    let mut out = Vec::new();
    for (i, (a, x)) in centred.iter().enumerate() {
        for (b, y) in &centred[i + 1..] {
            out.push((
                format!("{a}:value*{b}"),
                x.iter().zip(y).map(|(p, q)| p * q).collect(),
            ));
        }
    }
    out
}

/// Run-level features of run `ri`'s metadata: numeric values as they are, other values as
/// level indicators (all but the first level in sorted order).
fn meta_features(runs: &[Run], ri: usize, n: usize) -> Vec<(String, Vec<f64>)> {
    let mut feats = Vec::new();
    for (key, v) in &runs[ri].meta {
        match v.trim().parse::<f64>() {
            Ok(num) => feats.push((format!("# {key}"), vec![num; n])),
            Err(_) => {
                let mut all: Vec<&str> = runs.iter().filter_map(|r| r.meta_value(key)).collect();
                all.sort_unstable();
                all.dedup();
                for l in all.iter().skip(1) {
                    feats.push((
                        format!("# {key}=={l}"),
                        vec![f64::from(u8::from(v == l)); n],
                    ));
                }
            }
        }
    }
    feats
}

/// Rate-independent memory: the stop operator (the column less its play) of one column,
/// per run (`xs`) and stacked, at `STOP_SHARES` of its median within-run range.
fn stops(name: &str, xs: &[Vec<f64>]) -> Vec<(String, Vec<f64>)> {
    let mut ranges: Vec<f64> = xs
        .iter()
        .map(|x| {
            let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
            hi - lo
        })
        .collect();
    ranges.sort_by(f64::total_cmp);
    let range = ranges.get(ranges.len() / 2).copied().unwrap_or(0.0);
    STOP_SHARES
        .iter()
        .map(|share| {
            let h = share * range;
            (
                format!("{name}:stop{h:.3}"),
                xs.iter().flat_map(|x| stop(x, h)).collect(),
            )
        })
        .collect()
}

/// max(0, x - q) at the deciles q of `x` (a linear spline basis beside the value).
fn hinges(name: &str, x: &[f64]) -> Vec<(String, Vec<f64>)> {
    deciles(x)
        .into_iter()
        .map(|q| {
            (
                format!("{name}:hinge>{q:.3}"),
                x.iter().map(|v| (v - q).max(0.0)).collect(),
            )
        })
        .collect()
}

fn varies(v: &[f64]) -> bool {
    let m = mean(v);
    v.iter().any(|x| (x - m).abs() > 1e-9 * (1.0 + m.abs()))
}

/// One run's 10 s means: the drift, then per column its level indicators (all but the
/// first level, as fractions of the window) and its value.
fn binned_run(run: &Run, names: &[String], few: &[Option<Vec<f64>>]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut raw: Vec<Vec<f64>> = vec![run.drift_dph()];
    for (n, lv) in names.iter().zip(few) {
        let x = run
            .column(n)
            .map_or_else(|| vec![0.0; run.len()], <[f64]>::to_vec);
        for l in lv.iter().flatten().skip(1) {
            raw.push(x.iter().map(|v| f64::from(u8::from(v == l))).collect());
        }
        raw.push(x);
    }
    let mut b = binned(run, &raw);
    let y = b.remove(0);
    (y, b)
}

/// Builds the stacked table: y (drift), the base (1, T, T^2, dT/dt) and the library.
pub fn table(runs: &[Run]) -> Table {
    let names: Vec<String> = runs[0]
        .columns
        .iter()
        .filter(|c| *c != "rate_dph" && *c != "earth_dph")
        .cloned()
        .collect();
    let few: Vec<Option<Vec<f64>>> = names
        .iter()
        .map(|n| if n == "t_s" { None } else { levels(runs, n) })
        .collect();
    let per_run: Vec<(Vec<f64>, Vec<Vec<f64>>)> =
        runs.iter().map(|r| binned_run(r, &names, &few)).collect();
    let ti = names.iter().position(|n| n == "t_s").unwrap_or(0);
    let temp_i = names.iter().position(|n| n == "temp_c").unwrap_or(0);
    // column index in the binned set: levels come before each column's value
    let mut col_index = Vec::new();
    let mut k = 0;
    for lv in &few {
        let nl = lv.as_ref().map_or(0, |l| l.len() - 1);
        col_index.push((k, nl));
        k += nl + 1;
    }
    let value =
        |r: &(Vec<f64>, Vec<Vec<f64>>), i: usize| r.1[col_index[i].0 + col_index[i].1].clone();
    let tm = mean(
        &per_run
            .iter()
            .flat_map(|r| value(r, temp_i))
            .collect::<Vec<_>>(),
    );
    let mut run_rows = Vec::new();
    let (mut y, mut base) = (Vec::new(), vec![Vec::new(); 4]);
    let mut lib: Vec<(String, Vec<f64>)> = Vec::new();
    for (ri, r) in per_run.iter().enumerate() {
        let start = y.len();
        y.extend(&r.0);
        let t = value(r, ti);
        let temp = value(r, temp_i);
        let dtemp = derivative(&temp, &t);
        let n = t.len();
        let mut feats: Vec<(String, Vec<f64>)> = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let x = value(r, i);
            feats.extend(column_features(
                name,
                &x,
                &t,
                &temp,
                &dtemp,
                tm,
                few[i].is_some(),
            ));
            if let Some(lv) = &few[i] {
                for (j, l) in lv.iter().skip(1).enumerate() {
                    feats.push((format!("{name}=={l}"), r.1[col_index[i].0 + j].clone()));
                }
            }
            feats.push((format!("{name}:run_mean"), vec![mean(&x); n]));
        }
        let values: Vec<Vec<f64>> = (0..names.len()).map(|i| value(r, i)).collect();
        feats.extend(pair_products(&names, &values));
        feats.extend(meta_features(runs, ri, n));
        for (b, v) in base.iter_mut().zip([
            vec![1.0; n],
            temp.iter().map(|x| x - tm).collect(),
            temp.iter().map(|x| (x - tm).powi(2)).collect(),
            dtemp,
        ]) {
            b.extend(v);
        }
        if ri == 0 {
            lib = feats;
        } else {
            for ((l, v), (fl, fv)) in lib.iter_mut().zip(feats) {
                assert_eq!(*l, fl, "the same columns and metadata keys in every run");
                v.extend(fv);
            }
        }
        run_rows.push(start..y.len());
    }
    // hinges at the campaign's deciles of every many-valued column
    for (i, name) in names.iter().enumerate().filter(|(i, _)| few[*i].is_none()) {
        let x: Vec<f64> = per_run.iter().flat_map(|r| value(r, i)).collect();
        lib.extend(hinges(name, &x));
    }
    for (i, name) in names
        .iter()
        .enumerate()
        .filter(|(i, n)| few[*i].is_none() && n.as_str() != "t_s")
    {
        let xs: Vec<Vec<f64>> = per_run.iter().map(|r| value(r, i)).collect();
        lib.extend(stops(name, &xs));
    }
    lib.retain(|(_, v)| varies(v));
    Table {
        run_rows,
        y,
        base,
        lib,
    }
}

/// Least-squares coefficients of `x` on `cols` over `rows` (normal equations, Cholesky).
pub fn ols(cols: &[&[f64]], x: &[f64], rows: &[usize]) -> Vec<f64> {
    let p = cols.len();
    let mut a = vec![vec![0.0; p]; p];
    let mut b = vec![0.0; p];
    for &r in rows {
        for i in 0..p {
            b[i] += cols[i][r] * x[r];
            for j in 0..=i {
                a[i][j] += cols[i][r] * cols[j][r];
            }
        }
    }
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-10 * row[i] + 1e-300;
    }
    // Cholesky in place (lower)
    for j in 0..p {
        let d = (a[j][j] - (0..j).map(|k| a[j][k] * a[j][k]).sum::<f64>())
            .max(1e-300)
            .sqrt();
        a[j][j] = d;
        for i in j + 1..p {
            a[i][j] = (a[i][j] - (0..j).map(|k| a[i][k] * a[j][k]).sum::<f64>()) / d;
        }
    }
    let mut z = vec![0.0; p];
    for i in 0..p {
        z[i] = (b[i] - (0..i).map(|k| a[i][k] * z[k]).sum::<f64>()) / a[i][i];
    }
    for i in (0..p).rev() {
        z[i] = (z[i] - (i + 1..p).map(|k| a[k][i] * z[k]).sum::<f64>()) / a[i][i];
    }
    z
}

/// `x` minus its projection on `cols` fitted over `rows`, evaluated on every row.
pub fn residualise(cols: &[&[f64]], x: &[f64], rows: &[usize]) -> Vec<f64> {
    let w = ols(cols, x, rows);
    (0..x.len())
        .map(|r| x[r] - cols.iter().zip(&w).map(|(c, w)| c[r] * w).sum::<f64>())
        .collect()
}

/// Lasso path by coordinate descent (covariance updates: the Gram matrix once, O(p) per
/// coordinate) on standardised `x` over training `rows`, warm started; calls
/// `visit(k, beta)` at each penalty of `lambdas`.
/// Residualises y and the library on the base (fitted on `rows`), standardised by their sd on `rows`.
pub fn prepared(t: &Table, rows: &[usize]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let base: Vec<&[f64]> = t.base.iter().map(Vec::as_slice).collect();
    let y = residualise(&base, &t.y, rows);
    let x = t
        .lib
        .iter()
        .map(|(_, v)| {
            let r = residualise(&base, v, rows);
            let sd = (rows.iter().map(|&i| r[i] * r[i]).sum::<f64>() / rows.len() as f64).sqrt();
            r.iter()
                .map(|v| if sd > 1e-12 { v / sd } else { 0.0 })
                .collect()
        })
        .collect();
    (y, x)
}

/// Per-run scores of one library column against the residual, scaled by the column's
/// norm: within-run columns on their within-run variation (run offsets drop out), columns
/// constant in every run on their run means.
fn run_scores(t: &Table, resid: &[f64], z: &[f64]) -> (bool, Vec<f64>) {
    let between = t.run_rows.iter().all(|rr| {
        z[rr.clone()]
            .iter()
            .all(|v| (v - z[rr.start]).abs() < 1e-12)
    });
    let mut u = Vec::with_capacity(t.run_rows.len());
    let mut ss = 0.0;
    for rr in &t.run_rows {
        let (zr, rr_) = (&z[rr.clone()], &resid[rr.clone()]);
        let n = zr.len() as f64;
        let (zm, rm) = (mean(zr), mean(rr_));
        if between {
            u.push(n * zm * rm);
            ss += n * zm * zm;
        } else {
            u.push(zr.iter().zip(rr_).map(|(a, b)| (a - zm) * (b - rm)).sum());
            ss += zr.iter().map(|a| (a - zm).powi(2)).sum::<f64>();
        }
    }
    let norm = ss.sqrt().max(1e-300);
    (between, u.into_iter().map(|x| x / norm).collect())
}

/// Sign-flip max test over whole runs, family-wise over the library: within-run and
/// run-level columns form two families (each its own max, Bonferroni x2); for each of
/// `tested`, p = 2 x share of flips whose max over its family reaches the observed score.
fn sign_flip(t: &Table, resid: &[f64], z: &[Vec<f64>], tested: &[usize], seed: u64) -> Vec<f64> {
    let scores: Vec<(bool, Vec<f64>)> = z.iter().map(|c| run_scores(t, resid, c)).collect();
    let obs: Vec<f64> = tested
        .iter()
        .map(|&j| scores[j].1.iter().sum::<f64>().abs())
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut exceed = vec![0usize; tested.len()];
    for _ in 0..FLIPS {
        let eps: Vec<f64> = (0..t.run_rows.len())
            .map(|_| if rng.random_bool(0.5) { 1.0 } else { -1.0 })
            .collect();
        let mut max = [0.0f64; 2];
        for (between, u) in &scores {
            let m = &mut max[usize::from(*between)];
            *m = m.max(dot(u, &eps).abs());
        }
        for ((e, o), &j) in exceed.iter_mut().zip(&obs).zip(tested) {
            *e += usize::from(max[usize::from(scores[j].0)] >= *o - 1e-15);
        }
    }
    exceed
        .iter()
        .map(|e| (2.0 * (1 + e) as f64 / (1 + FLIPS) as f64).min(1.0))
        .collect()
}

/// Second moments over `rows` of the columns `x` and of `y`, each divided by the row count.
pub struct Moments {
    /// x_i . x_j / n.
    pub gram: Vec<Vec<f64>>,
    /// x_i . y / n.
    pub xy: Vec<f64>,
    /// y . y / n.
    pub yy: f64,
}

/// [`Moments`] of `x` and `y` over `rows`.
pub fn moments(x: &[Vec<f64>], y: &[f64], rows: &[usize]) -> Moments {
    let n = rows.len() as f64;
    let p = x.len();
    let xs: Vec<Vec<f64>> = x
        .iter()
        .map(|c| rows.iter().map(|&r| c[r]).collect())
        .collect();
    let ys: Vec<f64> = rows.iter().map(|&r| y[r]).collect();
    let mut gram = vec![vec![0.0; p]; p];
    for i in 0..p {
        for j in 0..=i {
            let g = dot(&xs[i], &xs[j]) / n;
            gram[i][j] = g;
            gram[j][i] = g;
        }
    }
    Moments {
        gram,
        xy: xs.iter().map(|col| dot(col, &ys) / n).collect(),
        yy: dot(&ys, &ys) / n,
    }
}

/// Folds over whole runs (run i in fold i mod F, F = min(runs, 5)): (training rows,
/// held-out rows) of each fold.
pub fn run_folds(t: &Table) -> Vec<(Vec<usize>, Vec<usize>)> {
    let folds = t.run_rows.len().min(5);
    let rows = |keep: &dyn Fn(usize) -> bool| -> Vec<usize> {
        t.run_rows
            .iter()
            .enumerate()
            .filter(|(i, _)| keep(*i))
            .flat_map(|(_, r)| r.clone())
            .collect()
    };
    (0..folds)
        .map(|f| (rows(&|i| i % folds != f), rows(&|i| i % folds == f)))
        .collect()
}

/// Grouped cross-validation's choice among models ordered simplest first: `fold_sse[f][k]`
/// is fold f's held-out sum of squares of model k over `held_out[f]` rows. Returns the
/// simplest model whose CV error is within one standard error (over folds) of the best
/// one's, and every model's CV error (mean square over all held-out rows).
pub fn one_se_choice(fold_sse: &[Vec<f64>], held_out: &[usize]) -> (usize, Vec<f64>) {
    let models = fold_sse.first().map_or(0, Vec::len);
    let folds = fold_sse.len();
    let total: usize = held_out.iter().sum();
    let cv: Vec<f64> = (0..models)
        .map(|k| fold_sse.iter().fold(0.0, |s, f| s + f[k]) / total as f64)
        .collect();
    let best = (0..models)
        .min_by(|a, b| cv[*a].total_cmp(&cv[*b]))
        .unwrap_or(0);
    let mse: Vec<f64> = fold_sse
        .iter()
        .zip(held_out)
        .map(|(f, n)| f[best] / *n as f64)
        .collect();
    let m = mean(&mse);
    let se = (mse.iter().map(|f| (f - m).powi(2)).sum::<f64>()
        / (folds * (folds - 1)).max(1) as f64)
        .sqrt();
    let chosen = (0..=best).find(|k| cv[*k] <= cv[best] + se).unwrap_or(best);
    (chosen, cv)
}

/// Held-out rms gain of model `chosen` over the base (model 0), %.
pub fn cv_gain_pct(cv: &[f64], chosen: usize) -> f64 {
    100.0 * (1.0 - (cv[chosen] / cv[0]).sqrt())
}

/// Names terms of `selected` forward: the strongest given the base and the terms already
/// named, tested against the max over the whole library; stops at the first that fails.
/// Sorted by p.
pub fn name_forward(t: &Table, selected: &[usize]) -> Vec<Named> {
    let all: Vec<usize> = (0..t.y.len()).collect();
    let mut named = Vec::new();
    let mut model: Vec<usize> = Vec::new();
    let mut pool = selected.to_vec();
    while !pool.is_empty() {
        let mut cols: Vec<&[f64]> = t.base.iter().map(Vec::as_slice).collect();
        cols.extend(model.iter().map(|&k| t.lib[k].1.as_slice()));
        let r = residualise(&cols, &t.y, &all);
        let z: Vec<Vec<f64>> = t
            .lib
            .iter()
            .map(|(_, v)| residualise(&cols, v, &all))
            .collect();
        let p = sign_flip(t, &r, &z, &pool, 0x5EED ^ model.len() as u64);
        let best = (0..pool.len())
            .min_by(|a, b| p[*a].total_cmp(&p[*b]))
            .unwrap_or(0);
        if p[best] >= ALPHA {
            break;
        }
        let j = pool.remove(best);
        named.push(Named {
            label: t.lib[j].0.clone(),
            p_value: p[best],
        });
        model.push(j);
    }
    named.sort_by(|a, b| a.p_value.total_cmp(&b.p_value));
    named
}
