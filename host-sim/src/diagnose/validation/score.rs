//! The score of a candidate term per validation unit: how much the term, made orthogonal
//! to the model it would join, covaries with that model's residual in each unit. Beside
//! the held-out gain (`signflip`) it is the second per-unit statistic of the naming test:
//! a held-out drop in squared error is quadratic in the term's fitted size, so in units
//! where a real term is small (a product whose factor sits near its centre) the drop is
//! mostly fitting noise, while the score is linear in the term and adds those units'
//! evidence with their weight. Summed over units the score is the Rao score of the term;
//! flipping whole units' signs gives its null, as for the gains.
//!
//! Each unit's score vector is whitened by the term's full information (the orthogonal
//! part's Gram over all units), so that a term of several columns (a spline, levels)
//! is one vector whose squared length is its score statistic, and terms of one column
//! are on one scale: the score over the square root of the orthogonal part's energy.

use crate::diagnose::linalg::solve_spd;
use crate::diagnose::validation::unit_sums::sum_all;

/// One term's whitened score vector per unit (`units x k`).
pub type UnitScores = Vec<Vec<f64>>;

/// Per-unit whitened scores of the last `k` of `q` columns given the first `q - k`, from
/// per-unit Grams (`q x q`, row-major) and X'y (`q`) of the adjusted design. The model's
/// columns are fitted over all units with the relative `ridge` (as every fit here); the
/// term's columns are made orthogonal to them over all units. None when a system is
/// singular (the term adds nothing new, or is not finite).
pub fn whitened_unit_scores(
    grams: &[Vec<f64>],
    xty: &[Vec<f64>],
    q: usize,
    k: usize,
    ridge: f64,
) -> Option<UnitScores> {
    if k == 0 || k > q {
        return None;
    }
    let p = q - k;
    let shapes_fit = !grams.is_empty()
        && grams.len() == xty.len()
        && grams.iter().all(|g| g.len() == q * q)
        && xty.iter().all(|c| c.len() == q);
    if !shapes_fit {
        return None;
    }
    let total_g = sum_all(grams);
    let total_c = sum_all(xty);
    let at = |g: &[f64], i: usize, j: usize| g[i * q + j];
    // The model's normal equations (ridged as the held-out fits are).
    let mut a: Vec<f64> = (0..p * p).map(|ij| at(&total_g, ij / p, ij % p)).collect();
    let mean_diag = (0..p).map(|i| a[i * p + i]).sum::<f64>() / p.max(1) as f64;
    for i in 0..p {
        a[i * p + i] += ridge * a[i * p + i] + 1e-12 * mean_diag + 1e-300;
    }
    let mut beta: Vec<f64> = total_c[..p].to_vec();
    // B = A^-1 G_xz, one column per term column.
    let mut b = vec![vec![0.0; p]; k];
    if p > 0 {
        solve_spd(&mut a, &mut beta, p).ok()?;
        for (j, bj) in b.iter_mut().enumerate() {
            let mut col: Vec<f64> = (0..p).map(|i| at(&total_g, i, p + j)).collect();
            solve_spd(&mut a, &mut col, p).ok()?;
            *bj = col;
        }
    }
    // Information of the orthogonal part: G_zz - G_zx B.
    let info = nalgebra::DMatrix::from_fn(k, k, |i, j| {
        at(&total_g, p + i, p + j)
            - (0..p)
                .map(|m| at(&total_g, p + i, m) * b[j][m])
                .sum::<f64>()
    });
    let chol = info.cholesky()?;
    // A term (nearly) inside the model's span has no orthogonal part to score.
    let l = chol.l();
    if (0..k).any(|j| l[(j, j)] * l[(j, j)] <= 1e-10 * at(&total_g, p + j, p + j)) {
        return None;
    }
    let per_unit: Option<UnitScores> = grams
        .iter()
        .zip(xty)
        .map(|(g, c)| {
            // The model's residual's covariance with its own columns (e) and the term's (f).
            let resid = |i: usize| c[i] - (0..p).map(|m| at(g, i, m) * beta[m]).sum::<f64>();
            let e: Vec<f64> = (0..p).map(resid).collect();
            let s = nalgebra::DVector::from_fn(k, |j, _| {
                resid(p + j) - b[j].iter().zip(&e).map(|(bm, em)| bm * em).sum::<f64>()
            });
            let w = l.solve_lower_triangular(&s)?;
            w.iter()
                .all(|v| v.is_finite())
                .then(|| w.iter().copied().collect())
        })
        .collect();
    per_unit
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per-unit Grams and X'y of columns `cols` (row-major per row) against `y`.
    fn systems(units: &[(Vec<Vec<f64>>, Vec<f64>)]) -> (Vec<Vec<f64>>, Vec<Vec<f64>>, usize) {
        let q = units[0].0[0].len();
        let mut grams = vec![];
        let mut xty = vec![];
        for (rows, y) in units {
            let mut g = vec![0.0; q * q];
            let mut c = vec![0.0; q];
            for (r, yr) in rows.iter().zip(y) {
                for i in 0..q {
                    c[i] += r[i] * yr;
                    for j in 0..q {
                        g[i * q + j] += r[i] * r[j];
                    }
                }
            }
            grams.push(g);
            xty.push(c);
        }
        (grams, xty, q)
    }

    #[test]
    fn one_column_scores_are_covariances_with_the_residual_over_the_orthogonal_norm() {
        // Columns (x, z), y = x + z / 2.
        let unit = |off: f64| -> (Vec<Vec<f64>>, Vec<f64>) {
            let rows: Vec<Vec<f64>> = (0..8)
                .map(|i| {
                    let x = (i as f64 + off).sin();
                    let z = (2.0 * i as f64 - off).cos();
                    vec![x, z]
                })
                .collect();
            let y = rows.iter().map(|r| r[0] + 0.5 * r[1]).collect();
            (rows, y)
        };
        let (g, c, q) = systems(&[unit(0.0), unit(1.0), unit(2.5)]);
        let w = whitened_unit_scores(&g, &c, q, 1, 0.0).unwrap();
        // By hand: residual of y on x, z made orthogonal to x, per unit covariances.
        let gxx: f64 = g.iter().map(|g| g[0]).sum();
        let gxz: f64 = g.iter().map(|g| g[1]).sum();
        let gzz: f64 = g.iter().map(|g| g[3]).sum();
        let cx: f64 = c.iter().map(|c| c[0]).sum();
        let beta = cx / gxx;
        let bz = gxz / gxx;
        let info = gzz - gxz * bz;
        for (u, wu) in w.iter().enumerate() {
            let e = c[u][0] - g[u][0] * beta;
            let f = c[u][1] - g[u][2] * beta;
            let s = f - bz * e;
            assert!((wu[0] - s / info.sqrt()).abs() < 1e-9, "{wu:?} {s}");
        }
        // Summed, the score is the term's coefficient times its orthogonal norm.
        let total: f64 = w.iter().map(|v| v[0]).sum();
        assert!((total - 0.5 * info.sqrt()).abs() < 1e-9, "{total}");
    }

    #[test]
    fn a_term_that_adds_nothing_new_has_no_score() {
        let rows: Vec<Vec<f64>> = (0..6).map(|i| vec![i as f64, 2.0 * i as f64]).collect();
        let y: Vec<f64> = (0..6).map(|i| i as f64).collect();
        let (g, c, q) = systems(&[(rows, y)]);
        assert!(whitened_unit_scores(&g, &c, q, 1, 0.0).is_none());
        assert!(whitened_unit_scores(&g, &c, q, 0, 0.0).is_none());
    }
}
