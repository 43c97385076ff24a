//! Forward-selection bookkeeping shared by OLS and Orr's regularised variant.
//!
//! The selected regressors are kept as an orthonormal basis w_1..w_m (Gram-Schmidt with
//! one re-orthogonalisation pass, i.e. numerically stable CGS2) and an upper-triangular
//! R with q_{k_j} = sum_i R[i][j] w_i. The N candidates are never orthogonalised
//! explicitly: for each candidate k only two numbers are kept,
//!   p_k = u_k'y  and  s_k = u_k'u_k,
//! where u_k is q_k with its projection on the basis removed. Adding w updates them with
//! a = Phi'w (one pass over the design):  p_k -= a_k (w'y),  s_k -= a_k^2.
//! This is algebraically Chen-Cowan-Grant's Gram-Schmidt OLS with O(N) memory on top of
//! the design matrix and one design pass per selected centre.

use super::design::GaussianDesign;

/// Orthogonal forward-selection state over one design matrix.
pub struct Selection<'a> {
    design: &'a GaussianDesign,
    y: Vec<f64>,
    yy: f64,
    /// Orthonormal basis vectors (forced terms first, then centres).
    basis: Vec<Vec<f64>>,
    /// Column j of R (length j+1): coefficients of term j on w_0..w_j.
    r_cols: Vec<Vec<f64>>,
    /// w_j'y for each basis vector.
    z: Vec<f64>,
    n_forced: usize,
    /// Candidate index of each selected centre, in selection order.
    selected: Vec<usize>,
    p: Vec<f64>,
    s: Vec<f64>,
    taken: Vec<bool>,
    /// A candidate is eligible only while s_k > tol * ||q_k||^2.
    collinearity_tol: f64,
    scratch: Vec<f64>,
}

/// Outcome of trying to add a regressor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Added {
    Yes,
    /// Numerically inside the span of the current basis; not added.
    Collinear,
}

impl<'a> Selection<'a> {
    /// Starts with an empty basis. `y` has one value per design row.
    pub fn new(design: &'a GaussianDesign, y: &[f64], collinearity_tol: f64) -> Self {
        let n = design.len();
        let mut p = vec![0.0; n];
        design.dot_columns(y, &mut p);
        let s = (0..n).map(|k| design.column_sq_norm(k)).collect();
        Self {
            design,
            y: y.to_vec(),
            yy: dot(y, y),
            basis: Vec::new(),
            r_cols: Vec::new(),
            z: Vec::new(),
            n_forced: 0,
            selected: Vec::new(),
            p,
            s,
            taken: vec![false; n],
            collinearity_tol,
            scratch: vec![0.0; n],
        }
    }

    /// Adds a regressor that is always part of the model (bias, linear terms).
    /// Must be called before any centre is selected.
    pub fn add_forced(&mut self, column: &[f64]) -> Added {
        debug_assert!(self.selected.is_empty(), "forced terms come first");
        let added = self.add_column(column);
        if added == Added::Yes {
            self.n_forced += 1;
        }
        added
    }

    /// Adds candidate centre k.
    pub fn add_candidate(&mut self, k: usize) -> Added {
        let column: Vec<f64> = self
            .design
            .column(k)
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        self.taken[k] = true;
        let added = self.add_column(&column);
        if added == Added::Yes {
            self.selected.push(k);
        }
        added
    }

    fn add_column(&mut self, v: &[f64]) -> Added {
        let mut u = v.to_vec();
        let mut coeff = vec![0.0; self.basis.len()];
        for _pass in 0..2 {
            for (c, w) in coeff.iter_mut().zip(&self.basis) {
                let proj = dot(w, &u);
                *c += proj;
                axpy(-proj, w, &mut u);
            }
        }
        let norm2 = dot(&u, &u);
        let has_new_energy = norm2 > self.collinearity_tol * dot(v, v);
        if !has_new_energy {
            return Added::Collinear;
        }
        let norm = norm2.sqrt();
        u.iter_mut().for_each(|x| *x /= norm);
        let zj = dot(&u, &self.y);
        let mut a = std::mem::take(&mut self.scratch);
        self.design.dot_columns(&u, &mut a);
        for ((p, s), &ak) in self.p.iter_mut().zip(self.s.iter_mut()).zip(&a) {
            *p -= ak * zj;
            *s -= ak * ak;
        }
        self.scratch = a;
        coeff.push(norm);
        self.r_cols.push(coeff);
        self.z.push(zj);
        self.basis.push(u);
        Added::Yes
    }

    /// (p_k, s_k) of candidate k if it is still eligible (not taken, not collinear).
    pub fn candidate(&self, k: usize) -> Option<(f64, f64)> {
        let s = self.s[k];
        let eligible = !self.taken[k] && s > self.collinearity_tol * self.design.column_sq_norm(k);
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
        self.y.len()
    }

    /// Residual energy of the unregularised least-squares fit on the current basis.
    pub fn residual_energy(&self) -> f64 {
        (self.yy - self.z.iter().map(|z| z * z).sum::<f64>()).max(0.0)
    }

    /// Number of forced terms.
    pub fn n_forced(&self) -> usize {
        self.n_forced
    }

    /// Selected centres (candidate indices), in order.
    pub fn selected(&self) -> &[usize] {
        &self.selected
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

/// Plain dot product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}
