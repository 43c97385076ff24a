//! The Gaussian design matrix of OLS: one column per candidate centre (every training
//! point), one row per training point. It is the only large object of the trainer:
//! for 8,910 points it is stored as f32 (317 MB) rather than f64, built once per width
//! in parallel, and used only through `dot_columns` (all candidates against one vector),
//! which is what each forward-selection step needs.

use std::num::NonZeroUsize;

/// exp() arguments below this give values under 2e-35: stored as exact zeros, which
/// also keeps f32 denormals (slow on x86) out of the matrix.
const MIN_EXP_ARG: f32 = -80.0;

/// Square Gaussian design over a point set (candidates = rows = training points).
pub struct GaussianDesign {
    n: usize,
    /// Column-major values: column k (candidate k) at `values[k*n .. (k+1)*n]`.
    values: Vec<f32>,
    /// Squared Euclidean norm of each column.
    col_sq_norm: Vec<f64>,
    threads: usize,
}

/// Worker threads to use: the machine's parallelism unless `requested` is set.
pub fn thread_count(requested: Option<usize>) -> usize {
    requested
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, NonZeroUsize::get))
        .max(1)
}

impl GaussianDesign {
    /// Builds phi[i][k] = exp(-||x_i - x_k||^2 / (2 width^2)) over the first `dims`
    /// coordinates of `points` (row-major, `stride` values per point, normalised units).
    pub fn build(points: &[f32], stride: usize, dims: usize, width: f64, threads: usize) -> Self {
        let n = points.len() / stride;
        let mut values = vec![0.0f32; n * n];
        let neg_inv_2s2 = (-0.5 / (width * width)) as f32;
        let threads = threads.max(1);
        let cols_per_job = n.div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            for (job, chunk) in values.chunks_mut(cols_per_job * n.max(1)).enumerate() {
                scope.spawn(move || {
                    for (c, col) in chunk.chunks_exact_mut(n).enumerate() {
                        let k = job * cols_per_job + c;
                        let centre = &points[k * stride..k * stride + dims];
                        for (i, out) in col.iter_mut().enumerate() {
                            let p = &points[i * stride..i * stride + dims];
                            let d2: f32 = p.iter().zip(centre).map(|(a, b)| (a - b) * (a - b)).sum();
                            let arg = d2 * neg_inv_2s2;
                            *out = if arg < MIN_EXP_ARG { 0.0 } else { arg.exp() };
                        }
                    }
                });
            }
        });
        let col_sq_norm = values
            .chunks_exact(n.max(1))
            .map(|c| c.iter().map(|&v| f64::from(v) * f64::from(v)).sum())
            .collect();
        Self { n, values, col_sq_norm, threads }
    }

    /// Number of points (rows = candidates).
    pub fn len(&self) -> usize {
        self.n
    }

    /// True for an empty point set.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Column k (candidate centre k evaluated at every point).
    pub fn column(&self, k: usize) -> &[f32] {
        &self.values[k * self.n..(k + 1) * self.n]
    }

    /// ||column k||^2.
    pub fn column_sq_norm(&self, k: usize) -> f64 {
        self.col_sq_norm[k]
    }

    /// out[k] = column(k) . v for every candidate k (f64 accumulation), in parallel.
    pub fn dot_columns(&self, v: &[f64], out: &mut [f64]) {
        let n = self.n;
        let per_job = n.div_ceil(self.threads).max(1);
        std::thread::scope(|scope| {
            for (job, out_chunk) in out.chunks_mut(per_job).enumerate() {
                scope.spawn(move || {
                    for (c, o) in out_chunk.iter_mut().enumerate() {
                        *o = dot_f32_f64(self.column(job * per_job + c), v);
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

/// Dot product of an f32 column with an f64 vector, four f64 accumulators.
pub fn dot_f32_f64(a: &[f32], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (a4, a_rest) = a.split_at(a.len() - a.len() % 4);
    let (b4, b_rest) = b.split_at(a4.len());
    for (x, y) in a4.chunks_exact(4).zip(b4.chunks_exact(4)) {
        for l in 0..4 {
            acc[l] += f64::from(x[l]) * y[l];
        }
    }
    let tail: f64 = a_rest.iter().zip(b_rest).map(|(&x, &y)| f64::from(x) * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}
