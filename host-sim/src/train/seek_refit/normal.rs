//! The refit's normal equations: per fold, the Gram matrix and right-hand side of the 10 s
//! rows and of the pair rows kept apart, summed, solved at any pair weight.

use crate::train::error::TrainError;

/// Normal equations of one fold: Gram and right-hand side of the 10 s rows and of the
/// pair rows, kept apart so any weight combines them.
#[derive(Clone)]
pub(super) struct Normal {
    /// Sum of the squared targets and the row count (for the residual rms).
    pub(super) yy: f64,
    pub(super) n: usize,
    pub(super) rows: Vec<f64>,
    pub(super) rows_rhs: Vec<f64>,
    pub(super) pairs: Vec<f64>,
    pub(super) pairs_rhs: Vec<f64>,
}

impl Normal {
    pub(super) fn new(k: usize) -> Self {
        Self {
            yy: 0.0,
            n: 0,
            rows: vec![0.0; k * k],
            rows_rhs: vec![0.0; k],
            pairs: vec![0.0; k * k],
            pairs_rhs: vec![0.0; k],
        }
    }

    pub(super) fn add(gram: &mut [f64], rhs: &mut [f64], x: &[f64], y: f64) {
        let k = x.len();
        for a in 0..k {
            rhs[a] += x[a] * y;
            for b in 0..=a {
                gram[a * k + b] += x[a] * x[b];
            }
        }
    }

    /// rms of the 10 s residuals at `theta`: sqrt((y'y - 2 theta'b + theta'G theta) / n).
    pub(super) fn rms_rows(&self, theta: &[f64]) -> f64 {
        let k = theta.len();
        let mut quad = 0.0;
        for a in 0..k {
            for b in 0..k {
                let (i, j) = if b <= a { (a, b) } else { (b, a) };
                quad += theta[a] * self.rows[i * k + j] * theta[b];
            }
        }
        let lin: f64 = theta.iter().zip(&self.rows_rhs).map(|(t, b)| t * b).sum();
        ((self.yy - 2.0 * lin + quad).max(0.0) / self.n.max(1) as f64).sqrt()
    }

    /// Solves (rows + w pairs) theta = rhs over `self` less `minus`, lower triangles.
    pub(super) fn solve(&self, minus: Option<&Normal>, w: f64) -> Option<Vec<f64>> {
        let k = self.rows_rhs.len();
        let less =
            |v: &[f64], i: usize, m: fn(&Normal) -> &[f64]| v[i] - minus.map_or(0.0, |n| m(n)[i]);
        let mut g = nalgebra::DMatrix::<f64>::zeros(k, k);
        for a in 0..k {
            for b in 0..=a {
                let i = a * k + b;
                let v = less(&self.rows, i, |n| &n.rows) + w * less(&self.pairs, i, |n| &n.pairs);
                g[(a, b)] = v;
                g[(b, a)] = v;
            }
        }
        let rhs = nalgebra::DVector::from_iterator(
            k,
            (0..k).map(|a| {
                less(&self.rows_rhs, a, |n| &n.rows_rhs)
                    + w * less(&self.pairs_rhs, a, |n| &n.pairs_rhs)
            }),
        );
        // A relative ridge of 1e-12 of the trace keeps a column that is zero on some
        // fold's rows from making the matrix singular; it moves nothing else.
        let ridge = 1e-12 * (0..k).map(|a| g[(a, a)]).sum::<f64>() / k as f64;
        for a in 0..k {
            g[(a, a)] += ridge;
        }
        let chol = g.cholesky()?;
        Some(chol.solve(&rhs).iter().copied().collect())
    }
}

/// The sum of the folds' normal equations.
pub(super) fn total(folds: &[Normal], k: usize) -> Normal {
    let mut all = Normal::new(k);
    for f in folds {
        all.yy += f.yy;
        all.n += f.n;
        for (t, s) in [
            (&mut all.rows, &f.rows),
            (&mut all.pairs, &f.pairs),
            (&mut all.rows_rhs, &f.rows_rhs),
            (&mut all.pairs_rhs, &f.pairs_rhs),
        ] {
            t.iter_mut().zip(s).for_each(|(a, b)| *a += b);
        }
    }
    all
}

pub(super) fn singular() -> TrainError {
    TrainError::BadConfig {
        option: "seek refit",
        why: "the refit's normal equations are singular".into(),
    }
}
