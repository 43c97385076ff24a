//! The Gaussian design matrix of OLS: one column per candidate centre, one row per
//! training point. Candidates are a subset of the training points (`candidates`: one per
//! occupied cell of a grid over the normalised inputs), so the matrix is n x K with K
//! bounded (default 1,000), never n x n: 9,000 points take 36 MB instead of 324 MB and
//! memory grows linearly with the data. Stored as f32, built in parallel, used only
//! through `dot_columns` (all candidates against one vector), which is what each
//! forward-selection step needs.

/// exp() arguments below this give values under 2e-35: stored as exact zeros, which
/// also keeps f32 denormals (slow on x86) out of the matrix.
const MIN_EXP_ARG: f32 = -80.0;

/// Rectangular Gaussian design: rows = points, columns = candidate centres.
pub struct GaussianDesign {
    n_rows: usize,
    n_cols: usize,
    /// Column-major values: column k (candidate k) at `values[k*n_rows .. (k+1)*n_rows]`.
    values: Vec<f32>,
    /// Squared Euclidean norm of each column.
    col_sq_norm: Vec<f64>,
    threads: usize,
}

impl GaussianDesign {
    /// Builds phi[i][k] = exp(-||x_i - x_{c_k}||^2 / (2 width^2)) over the first `dims`
    /// coordinates of `points` (row-major, `stride` values per point, normalised units),
    /// for every point i and every candidate point index c_k in `candidates`.
    pub fn build(
        points: &[f32],
        stride: usize,
        dims: usize,
        candidates: &[usize],
        width: f64,
        threads: usize,
    ) -> Self {
        let n = points.len() / stride;
        let m = candidates.len();
        let mut values = vec![0.0f32; n * m];
        let neg_inv_2s2 = (-0.5 / (width * width)) as f32;
        let threads = threads.max(1);
        // Coordinates as one array per dimension, so the distance loop vectorises.
        let coords: Vec<Vec<f32>> = (0..dims)
            .map(|d| points.chunks_exact(stride).map(|p| p[d]).collect())
            .collect();
        let per_job = m.div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            for (job, block) in values.chunks_mut((per_job * n).max(1)).enumerate() {
                let coords = &coords;
                scope.spawn(move || {
                    let mut d2 = vec![0.0f32; n];
                    for (c, col) in block.chunks_exact_mut(n.max(1)).enumerate() {
                        let k = candidates[job * per_job + c];
                        d2.fill(0.0);
                        for axis in coords {
                            let centre = axis[k];
                            for (acc, &x) in d2.iter_mut().zip(axis) {
                                *acc += (x - centre) * (x - centre);
                            }
                        }
                        for (out, &d) in col.iter_mut().zip(&d2) {
                            *out = gauss_exp(d * neg_inv_2s2);
                        }
                    }
                });
            }
        });
        let col_sq_norm = values
            .chunks_exact(n.max(1))
            .map(|c| c.iter().map(|&v| f64::from(v) * f64::from(v)).sum())
            .collect();
        Self {
            n_rows: n,
            n_cols: m,
            values,
            col_sq_norm,
            threads,
        }
    }

    /// Bytes a design of `rows` x `cols` takes.
    pub fn bytes_for(rows: usize, cols: usize) -> usize {
        rows.saturating_mul(cols)
            .saturating_mul(std::mem::size_of::<f32>())
    }

    /// Number of rows (points).
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }

    /// Number of candidates (columns).
    pub fn len(&self) -> usize {
        self.n_cols
    }

    /// True without candidates.
    pub fn is_empty(&self) -> bool {
        self.n_cols == 0
    }

    /// Column k (candidate centre k evaluated at every point).
    pub fn column(&self, k: usize) -> &[f32] {
        &self.values[k * self.n_rows..(k + 1) * self.n_rows]
    }

    /// ||column k||^2.
    pub fn column_sq_norm(&self, k: usize) -> f64 {
        self.col_sq_norm[k]
    }

    /// out[k] = column(k) . v for every candidate k (f64 accumulation), in parallel.
    pub fn dot_columns(&self, v: &[f64], out: &mut [f64]) {
        let n = self.n_cols;
        let v32: Vec<f32> = v.iter().map(|&x| x as f32).collect();
        let v = &v32[..];
        let per_job = n.div_ceil(self.threads).max(1);
        std::thread::scope(|scope| {
            for (job, out_chunk) in out.chunks_mut(per_job).enumerate() {
                scope.spawn(move || {
                    for (c, o) in out_chunk.iter_mut().enumerate() {
                        *o = dot_f32(self.column(job * per_job + c), v);
                    }
                });
            }
        });
    }

    /// Bytes held by the matrix (for reports).
    pub fn bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<f32>()
    }
}

/// exp(x) for the Gaussian, x <= 0: fog-core's `exp_neg_f32` (the device's exp, branch
/// free, so the compiler vectorises it, unlike a call to the C library's expf); exact 0
/// below `MIN_EXP_ARG`, which keeps f32 denormals (slow on x86) out of the matrix.
#[inline]
pub fn gauss_exp(x: f32) -> f32 {
    let keep = u32::from(x >= MIN_EXP_ARG).wrapping_neg();
    f32::from_bits(fog_core::model::rbf::exp_neg_f32(-x).to_bits() & keep)
}

/// Dot product of two f32 vectors: 16 f32 lanes within blocks of 512 values (so the
/// compiler can vectorise it), blocks summed in f64. Relative error ~1e-6 at worst;
/// it only ranks candidates, the fitted weights come from exact f64 Gram-Schmidt.
pub fn dot_f32(a: &[f32], b: &[f32]) -> f64 {
    const LANES: usize = 16;
    const BLOCK: usize = 512;
    let mut total = 0.0f64;
    for (ba, bb) in a.chunks(BLOCK).zip(b.chunks(BLOCK)) {
        let mut acc = [0.0f32; LANES];
        let (ea, eb) = (ba.chunks_exact(LANES), bb.chunks_exact(LANES));
        let tail: f32 = ea
            .remainder()
            .iter()
            .zip(eb.remainder())
            .map(|(x, y)| x * y)
            .sum();
        for (x, y) in ea.zip(eb) {
            let x: &[f32; LANES] = x.try_into().unwrap_or(&[0.0; LANES]);
            let y: &[f32; LANES] = y.try_into().unwrap_or(&[0.0; LANES]);
            for l in 0..LANES {
                acc[l] += x[l] * y[l];
            }
        }
        total += acc.iter().map(|&v| f64::from(v)).sum::<f64>() + f64::from(tail);
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_exp_matches_f64_exp_to_f32_precision() {
        let mut worst = 0.0f64;
        for i in 0..=80_000 {
            let x = -(i as f32) * 1e-3;
            let rel = (f64::from(gauss_exp(x)) - f64::from(x).exp()).abs() / f64::from(x).exp();
            worst = worst.max(rel);
        }
        assert!(worst < 3e-7, "worst relative error {worst:e}");
        assert_eq!(gauss_exp(-80.5), 0.0);
        assert_eq!(gauss_exp(0.0), 1.0);
    }

    #[test]
    fn design_is_symmetric_gaussian_and_thread_count_free() {
        let pts: Vec<f32> = (0..37)
            .flat_map(|i| [i as f32 * 0.1, (i as f32 * 0.7).sin()])
            .collect();
        let all: Vec<usize> = (0..37).collect();
        let one = GaussianDesign::build(&pts, 2, 2, &all, 0.5, 1);
        let three = GaussianDesign::build(&pts, 2, 2, &all, 0.5, 3);
        for k in 0..37 {
            assert_eq!(one.column(k), three.column(k));
            for i in 0..37 {
                let d2 =
                    (pts[2 * i] - pts[2 * k]).powi(2) + (pts[2 * i + 1] - pts[2 * k + 1]).powi(2);
                let want = (-f64::from(d2) / 0.5).exp();
                assert!((f64::from(one.column(k)[i]) - want).abs() < 1e-6);
                assert_eq!(one.column(k)[i], one.column(i)[k]);
            }
        }
        let v: Vec<f64> = (0..37).map(|i| f64::from(i) - 18.0).collect();
        let mut out = vec![0.0; 37];
        three.dot_columns(&v, &mut out);
        for (k, o) in out.iter().enumerate() {
            let want: f64 = one
                .column(k)
                .iter()
                .zip(&v)
                .map(|(&a, b)| f64::from(a) * b)
                .sum();
            assert!((o - want).abs() < 1e-5 * want.abs().max(1.0));
        }
    }
}
