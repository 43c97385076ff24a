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
    pub fn fit(inputs: &[Vec<f64>], k: usize, width_factor: f64) -> Self {
        let d = inputs.len();
        let n = inputs.first().map_or(0, Vec::len);
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
        let pts: Vec<&[f64]> = flat.chunks_exact(d.max(1)).collect();
        let centres = kmeans(&pts, k.min(n).max(1));
        let spacing = mean_nearest_distance(&centres).max(1e-3);
        Self {
            mean,
            scale,
            centres,
            width: width_factor * spacing,
        }
    }

    /// Number of design columns: one per centre, then the inputs.
    pub fn width(&self) -> usize {
        self.centres.len() + self.mean.len()
    }

    /// Row `i` of the design into `out` (`width()` long): one Gaussian per centre, then
    /// the normalised inputs.
    pub fn row_into(&self, inputs: &[Vec<f64>], i: usize, out: &mut [f64]) {
        self.row_with(|j| inputs[j][i], out);
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

    /// The design columns: one Gaussian per centre, then the normalised inputs (use
    /// [`RbfDesign`] where the rows can be streamed: n x columns is the memory's largest
    /// item).
    pub fn columns(&self, inputs: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let n = inputs.first().map_or(0, Vec::len);
        let mut cols: Vec<Vec<f64>> = (0..self.width()).map(|_| Vec::with_capacity(n)).collect();
        let mut row = vec![0.0; self.width()];
        for i in 0..n {
            self.row_into(inputs, i, &mut row);
            cols.iter_mut().zip(&row).for_each(|(c, v)| c.push(*v));
        }
        cols
    }
}

/// An RBF design given by its rows: the basis on `inputs`, then `linear` columns.
#[derive(Clone, Debug)]
pub struct RbfDesign {
    pub basis: RbfBasis,
    pub inputs: std::sync::Arc<Vec<Vec<f64>>>,
    pub linear: std::sync::Arc<Vec<Vec<f64>>>,
}

impl crate::diagnose::validation::design::Design for RbfDesign {
    fn width(&self) -> usize {
        self.basis.width() + self.linear.len()
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        let b = self.basis.width();
        self.basis.row_into(&self.inputs, i, &mut out[..b]);
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
/// (`benches/diagnose_kmeans.rs`, docs/diagnose.md "Libraries"): on z-scored campaign
/// points (n 500 / 5,000, k 8 / 24, 2-d and 3-d) linfa with one run is not better
/// (inertia 0.89-1.02x ours) and 1.4-6.3x slower at n = 500; its default 10 runs lowers the
/// inertia by 0.5-14.5% but costs 7.6-47x the time, and diagnose runs k-means for every
/// centre count x width of every RBF fit and candidate, picking centre count, width and
/// ridge on held-out data anyway. linfa was deterministic (same seed twice, 1 vs 2
/// threads), so that was not the reason.
pub fn kmeans<P: AsRef<[f64]>>(pts: &[P], k: usize) -> Vec<Vec<f64>> {
    if pts.is_empty() {
        return vec![vec![]];
    }
    let d = pts[0].as_ref().len();
    let mut centres = vec![pts[0].as_ref().to_vec()];
    let mut near: Vec<f64> = pts.iter().map(|p| dist2(p, &pts[0])).collect();
    while centres.len() < k {
        let (far, &dmax) = near
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap_or((0, &0.0));
        if dmax <= 1e-18 {
            break;
        }
        centres.push(pts[far].as_ref().to_vec());
        for (i, p) in pts.iter().enumerate() {
            near[i] = near[i].min(dist2(p, &pts[far]));
        }
    }
    let mut assign = vec![0usize; pts.len()];
    for _ in 0..12 {
        let mut changed = false;
        for (i, p) in pts.iter().enumerate() {
            let best = (0..centres.len())
                .min_by(|&a, &b| dist2(p, &centres[a]).total_cmp(&dist2(p, &centres[b])))
                .unwrap_or(0);
            changed |= best != assign[i];
            assign[i] = best;
        }
        let mut sum = vec![vec![0.0; d]; centres.len()];
        let mut cnt = vec![0usize; centres.len()];
        for (p, &a) in pts.iter().zip(&assign) {
            let p = p.as_ref();
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
