//! The Gaussian design matrix of OLS: one column per candidate centre (every training
//! point), one row per training point. It is the only large object of the trainer:
//! for 8,910 points it is stored as f32 (317 MB) rather than f64, built once per width
//! in parallel, and used only through `dot_columns` (all candidates against one vector),
//! which is what each forward-selection step needs.

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

pub use crate::fanout::thread_count;

impl GaussianDesign {
    /// Builds phi[i][k] = exp(-||x_i - x_k||^2 / (2 width^2)) over the first `dims`
    /// coordinates of `points` (row-major, `stride` values per point, normalised units).
    pub fn build(points: &[f32], stride: usize, dims: usize, width: f64, threads: usize) -> Self {
        let n = points.len() / stride;
        let mut values = vec![0.0f32; n * n];
        let neg_inv_2s2 = (-0.5 / (width * width)) as f32;
        let threads = threads.max(1);
        // Column k only needs rows i >= k computed (the matrix is symmetric); the
        // upper part is mirrored afterwards. Jobs interleave columns to balance work.
        // Coordinates as one array per dimension, so the distance loop vectorises.
        let coords: Vec<Vec<f32>> = (0..dims)
            .map(|d| points.chunks_exact(stride).map(|p| p[d]).collect())
            .collect();
        let shared = SharedColumns::new(&mut values, n);
        std::thread::scope(|scope| {
            for job in 0..threads {
                let (shared, coords) = (&shared, &coords);
                scope.spawn(move || {
                    let mut d2 = vec![0.0f32; n];
                    for k in (job..n).step_by(threads) {
                        let d2 = &mut d2[k..];
                        d2.fill(0.0);
                        for axis in coords {
                            let c = axis[k];
                            for (acc, &x) in d2.iter_mut().zip(&axis[k..]) {
                                *acc += (x - c) * (x - c);
                            }
                        }
                        let mut col = shared.column(k);
                        for (out, &d) in col[k..].iter_mut().zip(d2.iter()) {
                            *out = gauss_exp(d * neg_inv_2s2);
                        }
                    }
                });
            }
        });
        drop(shared);
        mirror_lower_to_upper(&mut values, n);
        let col_sq_norm = values
            .chunks_exact(n.max(1))
            .map(|c| c.iter().map(|&v| f64::from(v) * f64::from(v)).sum())
            .collect();
        Self {
            n,
            values,
            col_sq_norm,
            threads,
        }
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

/// Copies the lower triangle (row >= column) onto the upper one, in cache-sized tiles.
fn mirror_lower_to_upper(values: &mut [f32], n: usize) {
    const TILE: usize = 64;
    for k0 in (0..n).step_by(TILE) {
        for i0 in (0..=k0).step_by(TILE) {
            // Tile: columns k in k0.., rows i in i0.. with i < k; source (row k, column i).
            for k in k0..(k0 + TILE).min(n) {
                for i in i0..(i0 + TILE).min(k) {
                    values[k * n + i] = values[i * n + k];
                }
            }
        }
    }
}

/// Hands out disjoint mutable columns of the matrix to worker threads.
struct SharedColumns<'a> {
    columns: Vec<std::sync::Mutex<&'a mut [f32]>>,
}

impl<'a> SharedColumns<'a> {
    fn new(values: &'a mut [f32], n: usize) -> Self {
        Self {
            columns: values
                .chunks_mut(n.max(1))
                .map(std::sync::Mutex::new)
                .collect(),
        }
    }

    fn column(&self, k: usize) -> std::sync::MutexGuard<'_, &'a mut [f32]> {
        self.columns[k]
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// exp(x) for the Gaussian, x <= 0: exact 0 below `MIN_EXP_ARG`, otherwise a branch-free
/// Cephes-style 2^n * p(r) with |r| <= ln2/2 (relative error < 2e-7), which the compiler
/// vectorises, unlike a call to the C library's expf.
#[inline]
pub fn gauss_exp(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    const ROUND: f32 = 12_582_912.0; // 1.5 * 2^23: adding it rounds to an integer.
    let xc = x.max(MIN_EXP_ARG);
    let n = (xc * LOG2E + ROUND) - ROUND;
    let r = xc - n * LN2_HI - n * LN2_LO;
    let p = 1.987_569_1e-4f32;
    let p = p * r + 1.398_199_9e-3;
    let p = p * r + 8.333_452e-3;
    let p = p * r + 4.166_579_6e-2;
    let p = p * r + 1.666_666_5e-1;
    let p = p * r + 0.5;
    let p = (p * r * r + r) + 1.0;
    let scale = f32::from_bits(((n as i32 + 127) as u32) << 23);
    // Branch-free select (keeps the loop vectorisable): all-ones mask when x >= MIN.
    let keep = u32::from(x >= MIN_EXP_ARG).wrapping_neg();
    f32::from_bits((p * scale).to_bits() & keep)
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
        let one = GaussianDesign::build(&pts, 2, 2, 0.5, 1);
        let three = GaussianDesign::build(&pts, 2, 2, 0.5, 3);
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
