//! Gaussian RBF basis on normalised inputs (the paper's model family) for the
//! fixed-effects fits of `diagnose`: k-means centres, one shared width, plus the
//! inputs themselves as linear terms so the model extrapolates gently.

/// A fixed Gaussian basis: normalisation, centres and width in normalised space.
#[derive(Clone, Debug)]
pub struct RbfBasis {
    pub mean: Vec<f64>,
    pub scale: Vec<f64>,
    pub centres: Vec<Vec<f64>>,
    pub width: f64,
}

impl RbfBasis {
    /// Builds the basis for `inputs` (one Vec per input, equal lengths): z-score
    /// normalisation, `k` k-means centres (deterministic farthest-point start), and
    /// width = `width_factor` x the mean distance from a centre to its nearest other centre.
    pub fn fit(inputs: &[&[f64]], k: usize, width_factor: f64) -> Self {
        Self::fit_centres(inputs, k).with_width_factor(width_factor)
    }

    /// The same basis with its width `width_factor` x this one's (the centres are kept:
    /// k-means does not depend on the width, so a width grid needs one k-means run).
    pub fn with_width_factor(&self, width_factor: f64) -> Self {
        Self {
            width: width_factor * self.width,
            ..self.clone()
        }
    }

    /// [`RbfBasis::fit`] with width factor 1: the width is the mean nearest-centre spacing.
    pub fn fit_centres(inputs: &[&[f64]], k: usize) -> Self {
        let d = inputs.len();
        let n = inputs.first().map_or(0, |c| c.len());
        let mut mean = vec![0.0; d];
        let mut scale = vec![1.0; d];
        for j in 0..d {
            let m = inputs[j].iter().sum::<f64>() / n.max(1) as f64;
            let v = inputs[j].iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n.max(1) as f64;
            mean[j] = m;
            scale[j] = if v.sqrt() > 1e-300 { v.sqrt() } else { 1.0 };
        }
        // One flat buffer and a slice per point (a Vec per point cost its header and a
        // heap block each: ~3x the data at d = 2).
        let flat: Vec<f64> = (0..n)
            .flat_map(|i| (0..d).map(move |j| (i, j)))
            .map(|(i, j)| (inputs[j][i] - mean[j]) / scale[j])
            .collect();
        let centres = kmeans_flat(&flat, d, k.min(n).max(1));
        let spacing = mean_nearest_distance(&centres).max(1e-3);
        Self {
            mean,
            scale,
            centres,
            width: spacing,
        }
    }

    /// Number of design columns: one per centre, then the inputs.
    pub fn width(&self) -> usize {
        self.centres.len() + self.mean.len()
    }

    /// The design's row at the raw input values `raw(j)` (j over the inputs) into `out`.
    pub fn row_with(&self, raw: impl Fn(usize) -> f64, out: &mut [f64]) {
        let k = self.centres.len();
        let d = self.mean.len();
        let inv = 1.0 / (2.0 * self.width * self.width);
        for (j, xj) in out[k..k + d].iter_mut().enumerate() {
            *xj = (raw(j) - self.mean[j]) / self.scale[j];
        }
        let (gauss, x) = out.split_at_mut(k);
        let x = &x[..d];
        for (c, g) in self.centres.iter().zip(gauss) {
            let r2: f64 = c.iter().zip(x).map(|(a, b)| (a - b) * (a - b)).sum();
            *g = (-r2 * inv).exp();
        }
    }
}

/// An RBF design given by its rows: the basis on `inputs`, then `linear` columns.
#[derive(Clone, Debug)]
pub struct RbfDesign {
    pub basis: RbfBasis,
    pub inputs: std::sync::Arc<Vec<std::sync::Arc<Vec<f64>>>>,
    pub linear: std::sync::Arc<Vec<Vec<f64>>>,
}

impl crate::diagnose::validation::design::Design for RbfDesign {
    fn width(&self) -> usize {
        self.basis.width() + self.linear.len()
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        let b = self.basis.width();
        self.basis.row_with(|j| self.inputs[j][i], &mut out[..b]);
        for (o, c) in out[b..].iter_mut().zip(self.linear.iter()) {
            *o = c[i];
        }
    }
}

fn dist2(a: impl AsRef<[f64]>, b: impl AsRef<[f64]>) -> f64 {
    let (a, b) = (a.as_ref(), b.as_ref());
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn mean_nearest_distance(c: &[Vec<f64>]) -> f64 {
    if c.len() < 2 {
        return 1.0;
    }
    let total: f64 = c
        .iter()
        .enumerate()
        .map(|(i, a)| {
            c.iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, b)| dist2(a, b))
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .sum();
    total / c.len() as f64
}

/// Lloyd's k-means from a farthest-point start (deterministic: no seed, no RNG stream).
///
/// Kept hand-written after measuring it against linfa-clustering 0.8.1's `KMeans`
/// (`bench/benches/diagnose_kmeans.rs`, docs/record/diagnose.md "Libraries"): on z-scored campaign
/// points (n 500 / 5,000, k 8 / 24, 2-d and 3-d) linfa with one run is not better
/// (inertia 0.89-1.02x ours) and 1.4-6.3x slower at n = 500; its default 10 runs lowers the
/// inertia by 0.5-14.5% but costs 7.6-47x the time, and diagnose runs k-means for every
/// centre count x width of every RBF fit and candidate, picking centre count, width and
/// ridge on held-out data anyway. linfa was deterministic (same seed twice, 1 vs 2
/// threads), so that was not the reason.
pub fn kmeans<P: AsRef<[f64]>>(pts: &[P], k: usize) -> Vec<Vec<f64>> {
    lloyd(pts.len(), |i| pts[i].as_ref(), k)
}

/// [`kmeans`] on `flat.len() / d` points of `d` values each, stored one after another
/// (no slice per point: 16 B a point less, memory).
pub fn kmeans_flat(flat: &[f64], d: usize, k: usize) -> Vec<Vec<f64>> {
    let d = d.max(1);
    lloyd(flat.len() / d, |i| &flat[i * d..(i + 1) * d], k)
}

/// Index of the centre nearest to `p`, the first of equals (one distance per centre).
fn nearest_centre(p: &[f64], centres: &[Vec<f64>]) -> u32 {
    let mut best = (0usize, f64::INFINITY);
    for (c, centre) in centres.iter().enumerate() {
        let d = dist2(p, centre);
        if c == 0 || d.total_cmp(&best.1) == std::cmp::Ordering::Less {
            best = (c, d);
        }
    }
    best.0 as u32
}

/// Lloyd's iterations of [`kmeans`] on `n` points given by `point`.
fn lloyd<'a>(n: usize, point: impl Fn(usize) -> &'a [f64], k: usize) -> Vec<Vec<f64>> {
    if n == 0 {
        return vec![vec![]];
    }
    let d = point(0).len();
    let mut centres = vec![point(0).to_vec()];
    let mut near: Vec<f64> = (0..n).map(|i| dist2(point(i), point(0))).collect();
    while centres.len() < k {
        let (far, &dmax) = near
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap_or((0, &0.0));
        if dmax <= 1e-18 {
            break;
        }
        centres.push(point(far).to_vec());
        for (i, nearest) in near.iter_mut().enumerate() {
            *nearest = nearest.min(dist2(point(i), point(far)));
        }
    }
    // Centre indices (at most a few dozen centres): 4 B a point.
    let mut assign = vec![0u32; n];
    for _ in 0..12 {
        let mut changed = false;
        for (i, a) in assign.iter_mut().enumerate() {
            let best = nearest_centre(point(i), &centres);
            changed |= best != *a;
            *a = best;
        }
        let mut sum = vec![vec![0.0; d]; centres.len()];
        let mut cnt = vec![0usize; centres.len()];
        for (i, &a) in assign.iter().enumerate() {
            let (p, a) = (point(i), a as usize);
            cnt[a] += 1;
            for j in 0..d {
                sum[a][j] += p[j];
            }
        }
        for (c, (s, n)) in centres.iter_mut().zip(sum.iter().zip(&cnt)) {
            if *n > 0 {
                *c = s.iter().map(|v| v / *n as f64).collect();
            }
        }
        if !changed {
            break;
        }
    }
    centres
}
