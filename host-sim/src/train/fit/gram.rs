//! The regression problem in covariance (Gram) form, built once per Gaussian width.
//!
//! Columns of the extended design A = [forced columns | K candidate Gaussians | y]: the
//! bias, T^1..T^3 (normalised input 0), the linear inputs, one Gaussian per candidate
//! centre and, last, the target. G = A'A then holds every inner product forward
//! selection needs (column norms, cross products, A'y in the last row, y'y in the
//! corner). It is accumulated per fold (whole runs), so a fold's training Gram is
//! `total - fold` and validating a (width, degree) costs no pass over the rows: each
//! fold's 0..64-centre path is O(K^2 m) work on the Gram. The rows are streamed in
//! blocks (the n x K design is never held), the Gaussians are evaluated in f32 exactly
//! as the former f32 design did, and every product and sum is f64.

use crate::fanout::map_in_order;
use std::ops::Range;

/// A forced (always present) column of the extended design.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForcedColumn {
    Bias,
    /// Normalised input 0 to the power k (1..=3).
    Power(usize),
    /// Normalised input j.
    Input(usize),
    /// Normalised input 0 times normalised input j (a temperature-coupled linear term).
    InputByT(usize),
}

/// What the extended design is made of.
pub struct Layout<'a> {
    /// Normalised points, row-major, `stride` values each.
    pub points: &'a [f32],
    pub stride: usize,
    /// Inputs entering the Gaussian distance (the leading ones).
    pub rbf_dims: usize,
    /// Point index of each candidate centre.
    pub candidates: &'a [usize],
    /// Gaussian sigma, normalised units.
    pub width: f64,
    pub forced: &'a [ForcedColumn],
    pub targets: &'a [f64],
}

impl Layout<'_> {
    /// Columns of the extended design (forced + candidates + target).
    pub fn n_columns(&self) -> usize {
        self.forced.len() + self.candidates.len() + 1
    }
}

/// Blocks a fold's rows are summed in: fixed, so that the thread count never changes the
/// order of a floating-point sum (enough blocks to keep 2-16 threads busy).
const SUM_BLOCKS: usize = 16;

/// Per-fold Gram matrices of one extended design, plus their total.
pub struct FoldGrams {
    p: usize,
    n_forced: usize,
    /// Full symmetric p x p, row-major, one per fold.
    folds: Vec<Vec<f64>>,
    fold_rows: Vec<usize>,
    total: Vec<f64>,
    n_rows: usize,
}

/// Bytes of one Gram matrix of `columns` columns.
pub fn gram_bytes(columns: usize) -> usize {
    columns
        .saturating_mul(columns)
        .saturating_mul(std::mem::size_of::<f64>())
}

impl FoldGrams {
    /// Accumulates G_f = A_f'A_f for every fold f (`fold[i]` < `folds` for every row i).
    /// A fold's rows are cut into `SUM_BLOCKS` blocks whatever the thread count, each block
    /// accumulated on its own and the blocks added in block order: every sum is the same,
    /// in the same order, on any machine (same seed, same bytes). The blocks run
    /// `threads` at a time and folds one after the other, so at most `threads` partial
    /// Grams exist beside the fold Grams (memory: folds + 1 + threads Grams), and only the
    /// current fold's row list is held.
    pub fn build(layout: &Layout<'_>, fold: &[usize], folds: usize, threads: usize) -> Self {
        let p = layout.n_columns();
        let parts = threads.clamp(1, SUM_BLOCKS);
        let mut fold_grams: Vec<Vec<f64>> = Vec::with_capacity(folds);
        let mut fold_rows = Vec::with_capacity(folds);
        for f in 0..folds {
            let rows: Vec<usize> = (0..fold.len()).filter(|&i| fold[i] == f).collect();
            let block = rows.len().div_ceil(SUM_BLOCKS).max(1);
            let mut g = vec![0.0; p * p];
            for round in (0..SUM_BLOCKS).step_by(parts) {
                let shares = map_in_order(parts.min(SUM_BLOCKS - round), parts, |k| {
                    let start = ((round + k) * block).min(rows.len());
                    let end = (start + block).min(rows.len());
                    accumulate(layout, &rows[start..end])
                });
                for s in &shares {
                    g.iter_mut().zip(s).for_each(|(a, b)| *a += b);
                }
            }
            mirror_upper(&mut g, p);
            fold_rows.push(rows.len());
            fold_grams.push(g);
        }
        let mut total = vec![0.0; p * p];
        for g in &fold_grams {
            total.iter_mut().zip(g).for_each(|(a, b)| *a += b);
        }
        Self {
            p,
            n_forced: layout.forced.len(),
            folds: fold_grams,
            fold_rows,
            total,
            n_rows: fold.len(),
        }
    }

    /// The Gram of all rows.
    pub fn all(&self) -> GramView<'_> {
        GramView {
            p: self.p,
            n_forced: self.n_forced,
            total: &self.total,
            minus: None,
            n_rows: self.n_rows,
        }
    }

    /// The Gram of every row outside fold `f` (the fold's training set).
    pub fn without_fold(&self, f: usize) -> GramView<'_> {
        GramView {
            p: self.p,
            n_forced: self.n_forced,
            total: &self.total,
            minus: Some(&self.folds[f]),
            n_rows: self.n_rows - self.fold_rows[f],
        }
    }

    /// The Gram of fold `f`'s rows only (its held-out set).
    pub fn fold(&self, f: usize) -> GramView<'_> {
        GramView {
            p: self.p,
            n_forced: self.n_forced,
            total: &self.folds[f],
            minus: None,
            n_rows: self.fold_rows[f],
        }
    }

    /// Bytes held by the Gram matrices.
    pub fn bytes(&self) -> usize {
        gram_bytes(self.p) * (self.folds.len() + 1)
    }
}

/// A Gram matrix, possibly as the difference of two (total minus a fold).
#[derive(Clone, Copy)]
pub struct GramView<'a> {
    p: usize,
    n_forced: usize,
    total: &'a [f64],
    minus: Option<&'a [f64]>,
    n_rows: usize,
}

impl GramView<'_> {
    /// G[i][j].
    pub fn at(&self, i: usize, j: usize) -> f64 {
        let k = i * self.p + j;
        self.total[k] - self.minus.map_or(0.0, |m| m[k])
    }

    /// Row i of G (inner products of column i with every column, target last).
    pub fn row(&self, i: usize) -> Vec<f64> {
        let r = i * self.p..(i + 1) * self.p;
        match self.minus {
            None => self.total[r].to_vec(),
            Some(m) => self.total[r.clone()]
                .iter()
                .zip(&m[r])
                .map(|(a, b)| a - b)
                .collect(),
        }
    }

    /// Index of the target column.
    pub fn target(&self) -> usize {
        self.p - 1
    }

    /// Column indices of the candidate Gaussians.
    pub fn candidates(&self) -> Range<usize> {
        self.n_forced..self.p - 1
    }

    /// Rows summed into this Gram.
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }

    /// Residual energy ||y - A_S theta||^2 of coefficients `theta` on columns `cols`:
    /// y'y - 2 theta'A_S'y + theta'A_S'A_S theta.
    pub fn residual_energy(&self, cols: &[usize], theta: &[f64]) -> f64 {
        let t = self.target();
        let mut e = self.at(t, t);
        for (a, (&ca, &ta)) in cols.iter().zip(theta).enumerate() {
            e -= 2.0 * ta * self.at(ca, t);
            e += ta * ta * self.at(ca, ca);
            for (&cb, &tb) in cols[..a].iter().zip(theta) {
                e += 2.0 * ta * tb * self.at(ca, cb);
            }
        }
        e.max(0.0)
    }
}

/// Rows per block: a block of the extended design (rows x p f64) stays within ~256 kB,
/// so the tiles of the rank-update below find it in cache.
fn block_rows(p: usize) -> usize {
    ((256 << 10) / (8 * p.max(1))).clamp(8, 256)
}

/// Upper triangle (and some of the lower; all entries computed are correct) of A'A
/// over the given rows.
fn accumulate(layout: &Layout<'_>, rows: &[usize]) -> Vec<f64> {
    let p = layout.n_columns();
    let mut g = vec![0.0; p * p];
    let b = block_rows(p);
    let mut block = vec![0.0f64; b * p];
    let evaluator = GaussianRow::new(layout);
    let mut d2 = vec![0.0f32; layout.candidates.len()];
    for chunk in rows.chunks(b) {
        for (r, &i) in chunk.iter().enumerate() {
            evaluator.fill(i, &mut d2, &mut block[r * p..(r + 1) * p]);
        }
        rank_update_upper(&block[..chunk.len() * p], chunk.len(), p, &mut g);
    }
    g
}

/// Evaluates one row of the extended design.
struct GaussianRow<'a> {
    layout: &'a Layout<'a>,
    /// Candidate coordinates, one array per RBF axis (so the distance loop vectorises).
    axes: Vec<Vec<f32>>,
    neg_inv_2s2: f32,
}

impl<'a> GaussianRow<'a> {
    fn new(layout: &'a Layout<'a>) -> Self {
        let axes = (0..layout.rbf_dims)
            .map(|a| {
                layout
                    .candidates
                    .iter()
                    .map(|&k| layout.points[k * layout.stride + a])
                    .collect()
            })
            .collect();
        Self {
            layout,
            axes,
            neg_inv_2s2: (-0.5 / (layout.width * layout.width)) as f32,
        }
    }

    /// Row i: forced values, Gaussians (f32 distance and exp, as the deployed maths),
    /// target.
    fn fill(&self, i: usize, d2: &mut [f32], out: &mut [f64]) {
        let l = self.layout;
        let x = &l.points[i * l.stride..(i + 1) * l.stride];
        let nf = l.forced.len();
        for (o, c) in out.iter_mut().zip(l.forced) {
            *o = match *c {
                ForcedColumn::Bias => 1.0,
                ForcedColumn::Power(k) => f64::from(x[0]).powi(k as i32),
                ForcedColumn::Input(j) => f64::from(x[j]),
                ForcedColumn::InputByT(j) => f64::from(x[0]) * f64::from(x[j]),
            };
        }
        d2.fill(0.0);
        for (axis, &xa) in self.axes.iter().zip(x) {
            for (acc, &c) in d2.iter_mut().zip(axis) {
                *acc += (xa - c) * (xa - c);
            }
        }
        let k = d2.len();
        for (o, &d) in out[nf..nf + k].iter_mut().zip(d2.iter()) {
            *o = f64::from(crate::train::fit::design::gauss_exp(d * self.neg_inv_2s2));
        }
        out[nf + k] = l.targets[i];
    }
}

/// g[j][k] += sum_r a[r][j] a[r][k] for k >= the 4-row tile holding j. On x86-64 CPUs
/// with AVX2 the same code is compiled for 256-bit vectors with wider tiles (chosen at
/// run time). Every entry is still one multiply then one add per row, in row order (no
/// fused multiply-add), so the result is bit-identical on every CPU.
fn rank_update_upper(a: &[f64], rows: usize, p: usize, g: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        unsafe { rank_update_upper_avx2(a, rows, p, g) };
        return;
    }
    rank_update_tiles::<4>(a, rows, p, g);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn rank_update_upper_avx2(a: &[f64], rows: usize, p: usize, g: &mut [f64]) {
    rank_update_tiles::<8>(a, rows, p, g);
}

/// The rank update in register tiles of 4 x TK, so the compiler keeps the accumulators
/// in registers and vectorises over k.
#[inline(always)]
fn rank_update_tiles<const TK: usize>(a: &[f64], rows: usize, p: usize, g: &mut [f64]) {
    const TJ: usize = 4;
    for j0 in (0..p).step_by(TJ) {
        let jn = (p - j0).min(TJ);
        for k0 in (j0..p).step_by(TK) {
            let kn = (p - k0).min(TK);
            if jn == TJ && kn == TK {
                let mut acc = [[0.0f64; TK]; TJ];
                for row in a.chunks_exact(p).take(rows) {
                    let aj: &[f64; TJ] = row[j0..j0 + TJ].try_into().unwrap_or(&[0.0; TJ]);
                    let ak: &[f64; TK] = row[k0..k0 + TK].try_into().unwrap_or(&[0.0; TK]);
                    for (accj, &x) in acc.iter_mut().zip(aj) {
                        for (s, &y) in accj.iter_mut().zip(ak) {
                            *s += x * y;
                        }
                    }
                }
                for (jj, accj) in acc.iter().enumerate() {
                    let out = &mut g[(j0 + jj) * p + k0..(j0 + jj) * p + k0 + TK];
                    out.iter_mut().zip(accj).for_each(|(o, s)| *o += s);
                }
            } else {
                for j in j0..j0 + jn {
                    for k in k0..k0 + kn {
                        let s: f64 = a
                            .chunks_exact(p)
                            .take(rows)
                            .map(|row| row[j] * row[k])
                            .sum();
                        g[j * p + k] += s;
                    }
                }
            }
        }
    }
}

/// Copies the upper triangle onto the lower one.
fn mirror_upper(g: &mut [f64], p: usize) {
    for j in 0..p {
        for k in 0..j {
            g[j * p + k] = g[k * p + j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_grams_equal_explicit_inner_products() {
        let pts: Vec<f32> = (0..53)
            .flat_map(|i| [i as f32 * 0.05 - 1.3, (i as f32 * 0.7).sin()])
            .collect();
        let y: Vec<f64> = (0..53).map(|i| (f64::from(i) * 0.3).cos()).collect();
        let cands: Vec<usize> = (0..53).step_by(3).collect();
        let forced = [
            ForcedColumn::Bias,
            ForcedColumn::Power(2),
            ForcedColumn::Input(1),
        ];
        let layout = Layout {
            points: &pts,
            stride: 2,
            rbf_dims: 2,
            candidates: &cands,
            width: 0.4,
            forced: &forced,
            targets: &y,
        };
        let fold: Vec<usize> = (0..53).map(|i| i / 10 % 3).collect();
        let p = layout.n_columns();
        let ev = GaussianRow::new(&layout);
        let mut d2 = vec![0.0; cands.len()];
        let rows: Vec<Vec<f64>> = (0..53)
            .map(|i| {
                let mut r = vec![0.0; p];
                ev.fill(i, &mut d2, &mut r);
                r
            })
            .collect();
        let one_thread = FoldGrams::build(&layout, &fold, 3, 1);
        for threads in [1, 2, 3, 5] {
            let grams = FoldGrams::build(&layout, &fold, 3, threads);
            // the same sums in the same order, bit for bit, on any thread count
            assert_eq!(grams.total, one_thread.total, "{threads} threads");
            assert_eq!(grams.folds, one_thread.folds, "{threads} threads");
            for f in 0..3 {
                let (held, train) = (grams.fold(f), grams.without_fold(f));
                assert_eq!(held.n_rows() + train.n_rows(), 53);
                for j in 0..p {
                    for k in 0..p {
                        let want = |keep: &dyn Fn(usize) -> bool| -> f64 {
                            (0..53)
                                .filter(|&i| keep(fold[i]))
                                .map(|i| rows[i][j] * rows[i][k])
                                .sum()
                        };
                        let h = want(&|g| g == f);
                        let t = want(&|g| g != f);
                        assert!((held.at(j, k) - h).abs() < 1e-12 * h.abs().max(1.0));
                        assert!((train.at(j, k) - t).abs() < 1e-12 * t.abs().max(1.0));
                        assert_eq!(train.row(j)[k], train.at(j, k));
                    }
                }
            }
        }
    }
}
