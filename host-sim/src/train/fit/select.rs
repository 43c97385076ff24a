//! Forward-selection bookkeeping shared by OLS and Orr's regularised variant, in
//! covariance (Gram) form.
//!
//! The selected regressors span an orthonormal basis w_1..w_m with an upper-triangular R,
//! q_{k_j} = sum_i R[i][j] w_i (Chen-Cowan-Grant's Gram-Schmidt). Neither the basis nor
//! the candidates are held as vectors over the rows: for every basis vector w_i only
//! a_i[k] = q_k'w_i is kept, for every column k of the extended design (candidates,
//! forced terms and the target, so a_i[target] = w_i'y). Adding column c is one row of
//! the Gram matrix: a_new = (G[c] - sum_i a_i[c] a_i) / ||u_c|| (an incremental pivoted
//! Cholesky factorisation). For each candidate, p_k = u_k'y and s_k = u_k'u_k (u_k: q_k
//! with its projection on the basis removed) are updated as p_k -= a_k z, s_k -= a_k^2.
//! A step costs O(K m), no pass over the data rows.

use crate::train::fit::gram::GramView;

/// Orthogonal forward-selection state over one Gram matrix.
pub struct Selection<'a> {
    gram: GramView<'a>,
    /// Column index of candidate 0.
    first: usize,
    yy: f64,
    /// a_i over all columns, one per basis term (forced terms first, then centres).
    a: Vec<Vec<f64>>,
    /// Column j of R (length j+1): coefficients of term j on w_0..w_j.
    r_cols: Vec<Vec<f64>>,
    /// w_j'y for each basis vector.
    z: Vec<f64>,
    /// Column index of each basis term.
    columns: Vec<usize>,
    n_forced: usize,
    /// Candidate number of each selected centre, in selection order.
    selected: Vec<usize>,
    p: Vec<f64>,
    s: Vec<f64>,
    /// ||q_k||^2 of each candidate.
    norm2: Vec<f64>,
    taken: Vec<bool>,
    /// A candidate is eligible only while s_k > tol * ||q_k||^2.
    collinearity_tol: f64,
}

/// Outcome of trying to add a regressor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Added {
    Yes,
    /// Numerically inside the span of the current basis; not added.
    Collinear,
}

impl<'a> Selection<'a> {
    /// Starts with an empty basis over the candidates of `gram`.
    pub fn new(gram: GramView<'a>, collinearity_tol: f64) -> Self {
        let cands = gram.candidates();
        let t = gram.target();
        let p = cands.clone().map(|k| gram.at(k, t)).collect();
        let s: Vec<f64> = cands.clone().map(|k| gram.at(k, k)).collect();
        Self {
            gram,
            first: cands.start,
            yy: gram.at(t, t),
            a: Vec::new(),
            r_cols: Vec::new(),
            z: Vec::new(),
            columns: Vec::new(),
            n_forced: 0,
            selected: Vec::new(),
            p,
            norm2: s.clone(),
            taken: vec![false; s.len()],
            s,
            collinearity_tol,
        }
    }

    /// Adds forced column `column` (bias, polynomial or linear term, a column index of
    /// the Gram). Must be called before any centre is selected.
    pub fn add_forced(&mut self, column: usize) -> Added {
        debug_assert!(self.selected.is_empty(), "forced terms come first");
        let added = self.add_column(column);
        if added == Added::Yes {
            self.n_forced += 1;
        }
        added
    }

    /// Adds candidate centre k.
    pub fn add_candidate(&mut self, k: usize) -> Added {
        self.taken[k] = true;
        let added = self.add_column(self.first + k);
        if added == Added::Yes {
            self.selected.push(k);
        }
        added
    }

    fn add_column(&mut self, c: usize) -> Added {
        let coeff: Vec<f64> = self.a.iter().map(|ai| ai[c]).collect();
        let qq = self.gram.at(c, c);
        let norm2 = qq - coeff.iter().map(|r| r * r).sum::<f64>();
        let has_new_energy = norm2 > self.collinearity_tol * qq;
        if !has_new_energy {
            return Added::Collinear;
        }
        let norm = norm2.sqrt();
        let mut a_new = self.gram.row(c);
        for (r, ai) in coeff.iter().zip(&self.a) {
            a_new.iter_mut().zip(ai).for_each(|(x, v)| *x -= r * v);
        }
        a_new.iter_mut().for_each(|x| *x /= norm);
        let zj = a_new[self.gram.target()];
        let cands = &a_new[self.first..self.first + self.p.len()];
        for ((p, s), &ak) in self.p.iter_mut().zip(self.s.iter_mut()).zip(cands) {
            *p -= ak * zj;
            *s -= ak * ak;
        }
        let mut col = coeff;
        col.push(norm);
        self.r_cols.push(col);
        self.z.push(zj);
        self.columns.push(c);
        self.a.push(a_new);
        Added::Yes
    }

    /// (p_k, s_k) of candidate k if it is still eligible (not taken, not collinear).
    pub fn candidate(&self, k: usize) -> Option<(f64, f64)> {
        let s = self.s[k];
        let eligible = !self.taken[k] && s > self.collinearity_tol * self.norm2[k];
        eligible.then_some((self.p[k], s))
    }

    /// The eligible candidate maximising `score(p_k, s_k)` (lowest index on ties).
    pub fn best_candidate(&self, score: impl Fn(f64, f64) -> f64) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for k in 0..self.p.len() {
            if let Some((p, s)) = self.candidate(k) {
                let v = score(p, s);
                if v.is_finite() && best.is_none_or(|(_, b)| v > b) {
                    best = Some((k, v));
                }
            }
        }
        best
    }

    /// y'y.
    pub fn y_energy(&self) -> f64 {
        self.yy
    }

    /// Number of rows.
    pub fn n_rows(&self) -> usize {
        self.gram.n_rows()
    }

    /// Residual energy of the unregularised least-squares fit on the current basis.
    pub fn residual_energy(&self) -> f64 {
        (self.yy - self.z.iter().map(|z| z * z).sum::<f64>()).max(0.0)
    }

    /// Number of forced terms.
    pub fn n_forced(&self) -> usize {
        self.n_forced
    }

    /// Selected centres (candidate numbers), in order.
    pub fn selected(&self) -> &[usize] {
        &self.selected
    }

    /// Gram column index of every basis term, in order (forced terms first).
    pub fn columns(&self) -> &[usize] {
        &self.columns
    }

    /// w_j'y of every basis term.
    pub fn projections(&self) -> &[f64] {
        &self.z
    }

    /// ||u_j||^2 of every basis term (its energy before normalisation).
    pub fn term_energies(&self) -> Vec<f64> {
        self.r_cols.iter().map(|c| c[c.len() - 1].powi(2)).collect()
    }

    /// Coefficients of the first `terms` basis terms in the original regressors:
    /// solves R theta = shrink .* z by back-substitution.
    pub fn solve(&self, terms: usize, shrink: &[f64]) -> Vec<f64> {
        let mut theta = vec![0.0; terms];
        for j in (0..terms).rev() {
            let mut acc = shrink[j] * self.z[j];
            for (i, th) in theta.iter().enumerate().take(terms).skip(j + 1) {
                acc -= self.r_cols[i][j] * th;
            }
            theta[j] = acc / self.r_cols[j][j];
        }
        theta
    }
}

#[cfg(test)]
mod tests {
    //! The Gram-form selection against the former explicit one (Gram-Schmidt with
    //! re-orthogonalisation on the n-row columns of the f32 design, every candidate
    //! re-projected at each step): same centres in the same order, same coefficients.

    use super::*;
    use crate::train::fit::design::GaussianDesign;
    use crate::train::fit::gram::{FoldGrams, ForcedColumn, Layout};
    use crate::train::fit::ols::select_ols;

    /// The former path: explicit columns, CGS2 basis, pick max (u_k'y)^2 / u_k'u_k among
    /// candidates with u_k'u_k > tol q_k'q_k, weights from R theta = z.
    fn explicit_ols(
        forced: &[Vec<f64>],
        cands: &[Vec<f64>],
        y: &[f64],
        m: usize,
        tol: f64,
    ) -> (Vec<usize>, Vec<f64>) {
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut r_cols: Vec<Vec<f64>> = Vec::new();
        let mut z = Vec::new();
        let orthogonalise = |basis: &[Vec<f64>], v: &[f64]| {
            let mut u = v.to_vec();
            let mut coeff = vec![0.0; basis.len()];
            for _ in 0..2 {
                for (c, w) in coeff.iter_mut().zip(basis) {
                    let proj = dot(w, &u);
                    *c += proj;
                    u.iter_mut().zip(w).for_each(|(x, wi)| *x -= proj * wi);
                }
            }
            (u, coeff)
        };
        let mut add = |basis: &mut Vec<Vec<f64>>, v: &[f64]| {
            let (mut u, mut coeff) = orthogonalise(basis, v);
            let norm = dot(&u, &u).sqrt();
            u.iter_mut().for_each(|x| *x /= norm);
            z.push(dot(&u, y));
            coeff.push(norm);
            r_cols.push(coeff);
            basis.push(u);
        };
        for f in forced {
            add(&mut basis, f);
        }
        let mut selected: Vec<usize> = Vec::new();
        while selected.len() < m {
            let best = (0..cands.len())
                .filter(|k| !selected.contains(k))
                .filter_map(|k| {
                    let (u, _) = orthogonalise(&basis, &cands[k]);
                    let (p, s) = (dot(&u, y), dot(&u, &u));
                    (s > tol * dot(&cands[k], &cands[k])).then_some((k, p * p / s))
                })
                .fold(None, |b: Option<(usize, f64)>, c| match b {
                    Some(b) if b.1 >= c.1 => Some(b),
                    _ => Some(c),
                });
            let Some((k, _)) = best else { break };
            add(&mut basis, &cands[k]);
            selected.push(k);
        }
        let terms = r_cols.len();
        let mut theta = vec![0.0; terms];
        for j in (0..terms).rev() {
            let acc = z[j]
                - ((j + 1)..terms)
                    .map(|i| r_cols[i][j] * theta[i])
                    .sum::<f64>();
            theta[j] = acc / r_cols[j][j];
        }
        (selected, theta)
    }

    #[test]
    fn gram_form_selects_the_same_centres_with_the_same_weights_as_explicit_ols() {
        let n = 160;
        let pts: Vec<f32> = (0..n)
            .flat_map(|i| {
                let t = i as f32 * 0.04;
                [t - 3.0, (t * 1.7).sin() + 0.3 * (t * 5.1).cos()]
            })
            .collect();
        // A smooth drift law plus a deterministic pseudo-noise.
        let y: Vec<f64> = pts
            .chunks_exact(2)
            .enumerate()
            .map(|(i, p)| {
                let (t, r) = (f64::from(p[0]), f64::from(p[1]));
                0.3 * t - 0.05 * t * t
                    + 0.2 * (2.0 * r).tanh()
                    + 0.01 * ((i * 7919 % 101) as f64 / 101.0 - 0.5)
            })
            .collect();
        let cands: Vec<usize> = (0..n).step_by(2).collect();
        let forced = [
            ForcedColumn::Bias,
            ForcedColumn::Power(1),
            ForcedColumn::Power(2),
        ];
        let (width, m, tol) = (0.45, 20, 1e-4);
        let layout = Layout {
            points: &pts,
            stride: 2,
            rbf_dims: 2,
            candidates: &cands,
            width,
            forced: &forced,
            targets: &y,
        };
        let grams = FoldGrams::build(&layout, &vec![0; n], 1, 2);
        let mut sel = Selection::new(grams.all(), tol);
        for c in 0..forced.len() {
            assert_eq!(sel.add_forced(c), Added::Yes);
        }
        let path = select_ols(&mut sel, 0.0, None, m);
        let theta = sel.solve(path.terms, &path.shrink);

        let design = GaussianDesign::build(&pts, 2, 2, &cands, width, 1);
        let explicit_cands: Vec<Vec<f64>> = (0..cands.len())
            .map(|k| design.column(k).iter().map(|&v| f64::from(v)).collect())
            .collect();
        let t: Vec<f64> = pts.chunks_exact(2).map(|p| f64::from(p[0])).collect();
        let explicit_forced = vec![vec![1.0; n], t.clone(), t.iter().map(|v| v * v).collect()];
        let (want_sel, want_theta) = explicit_ols(&explicit_forced, &explicit_cands, &y, m, tol);

        assert_eq!(sel.selected(), &want_sel[..]);
        assert_eq!(theta.len(), want_theta.len());
        for (got, want) in theta.iter().zip(&want_theta) {
            assert!(
                (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                "coefficient {got} vs {want}"
            );
        }
    }
}
