//! The unit's own estimate of some of its terms with the others held at the type's mean:
//! what the misfit test (`misfit`) reads when the unit's runs cannot resolve every term.
//!
//! Why: tested all at once, every term widens the family's critical value (a type of 5
//! units and 3 terms: 5.8; a law type's 12 terms: above the 5-spread power bound for every
//! term), and nearly collinear terms each take a large standard error, though the unit's
//! runs fix their combination well (docs/record/fleet.md, "The misfit test on what the
//! runs resolve"). Held at the type's mean, the terms the runs cannot resolve leave the
//! fit and the family.
//! Each fitted term's estimate is then exactly the all-at-once estimate plus the held
//! terms' deviations through A = (X_I' X_I)^-1 X_I' X_O (`held_map`): a fixed linear
//! combination of the unit's terms, so the misfit test reads the same combination of
//! every type unit's own estimate for its type side (`calibrate::misfit_of`), whatever
//! the terms' correlations across units.
//!
//! Every solve here comes from each run's normal equations (X_r' X_r and X_r' y_r over all
//! terms, computed once), so dropping terms one by one and the jackknife over runs cost
//! small solves, not passes over the rows.

use anyhow::{anyhow, Result};
use nalgebra::{DMatrix, DVector};

use super::solve::UnitRows;

/// Each run's normal equations of the unit terms.
pub struct RunMoments {
    /// X_r' X_r and X_r' y_r per run (all terms).
    gram: Vec<DMatrix<f64>>,
    cross: Vec<DVector<f64>>,
    terms: usize,
}

/// Some terms' own estimate, the others held (see the module notes).
#[derive(Clone, Debug)]
pub struct HeldEstimate {
    /// Every term: fitted for `kept`, the held value for the others.
    pub own: Vec<f64>,
    /// Jackknife standard error over runs (infinite for the held terms).
    pub se: Vec<f64>,
    /// `held_map[k][o]`: how held term o's deviation from its held value enters fitted
    /// term k's estimate (A above; zero rows for the held terms, zero columns for the
    /// fitted).
    pub held_map: Vec<Vec<f64>>,
}

impl RunMoments {
    pub fn of(rows: &UnitRows) -> Self {
        let p = rows.columns.len();
        let mut gram = Vec::with_capacity(rows.runs);
        let mut cross = Vec::with_capacity(rows.runs);
        for r in 0..rows.runs {
            let range = rows.rows_of(r);
            let mut g = DMatrix::<f64>::zeros(p, p);
            let mut h = DVector::<f64>::zeros(p);
            for i in range {
                for a in 0..p {
                    let xa = rows.columns[a][i];
                    h[a] += xa * rows.residual[i];
                    for b in 0..=a {
                        g[(a, b)] += xa * rows.columns[b][i];
                    }
                }
            }
            for a in 0..p {
                for b in 0..a {
                    g[(b, a)] = g[(a, b)];
                }
            }
            gram.push(g);
            cross.push(h);
        }
        RunMoments {
            gram,
            cross,
            terms: p,
        }
    }

    /// The normal equations summed over the runs except `skip`.
    fn summed(&self, skip: Option<usize>) -> (DMatrix<f64>, DVector<f64>) {
        let p = self.terms;
        let mut g = DMatrix::<f64>::zeros(p, p);
        let mut h = DVector::<f64>::zeros(p);
        for (r, (gr, hr)) in self.gram.iter().zip(&self.cross).enumerate() {
            if Some(r) != skip {
                g += gr;
                h += hr;
            }
        }
        (g, h)
    }

    /// The kept terms' block of `g` with the same whisper of ridge as `solve::solve`
    /// (relative to its largest diagonal), factored; None when singular.
    fn kept_block(
        g: &DMatrix<f64>,
        kept: &[usize],
    ) -> Option<nalgebra::Cholesky<f64, nalgebra::Dyn>> {
        let m = kept.len();
        let scale = kept.iter().map(|&k| g[(k, k)]).fold(0.0f64, f64::max);
        let block = DMatrix::from_fn(m, m, |r, c| {
            g[(kept[r], kept[c])]
                + if r == c {
                    1e-10 * scale.max(f64::MIN_POSITIVE)
                } else {
                    0.0
                }
        });
        block.cholesky()
    }

    /// Terms `kept` by least squares on the runs except `skip`, the others at `held_at`.
    fn fit(&self, kept: &[usize], held_at: &[f64], skip: Option<usize>) -> Option<Vec<f64>> {
        let (g, h) = self.summed(skip);
        let mut coef = held_at.to_vec();
        if kept.is_empty() {
            return Some(coef);
        }
        let chol = Self::kept_block(&g, kept)?;
        let held: Vec<usize> = (0..self.terms).filter(|k| !kept.contains(k)).collect();
        let rhs = DVector::from_fn(kept.len(), |r, _| {
            h[kept[r]]
                - held
                    .iter()
                    .map(|&o| g[(kept[r], o)] * held_at[o])
                    .sum::<f64>()
        });
        let sol = chol.solve(&rhs);
        if sol.iter().any(|v| !v.is_finite()) {
            return None;
        }
        for (r, &k) in kept.iter().enumerate() {
            coef[k] = sol[r];
        }
        Some(coef)
    }

    /// A (see `HeldEstimate::held_map`), from all runs.
    fn held_map(&self, kept: &[usize]) -> Option<Vec<Vec<f64>>> {
        let mut map = vec![vec![0.0; self.terms]; self.terms];
        if kept.is_empty() {
            return Some(map);
        }
        let (g, _) = self.summed(None);
        let chol = Self::kept_block(&g, kept)?;
        for o in (0..self.terms).filter(|o| !kept.contains(o)) {
            let col = DVector::from_fn(kept.len(), |r, _| g[(kept[r], o)]);
            let a = chol.solve(&col);
            for (r, &k) in kept.iter().enumerate() {
                map[k][o] = a[r];
            }
        }
        map.iter().flatten().all(|v| v.is_finite()).then_some(map)
    }

    /// Terms `kept` fitted, the others held at `held_at`; jackknife over runs (needs 2).
    pub fn held_estimate(&self, kept: &[usize], held_at: &[f64]) -> Result<HeldEstimate> {
        let n = self.gram.len();
        let own = self
            .fit(kept, held_at, None)
            .ok_or_else(|| anyhow!("the unit terms cannot be solved on these runs"))?;
        let held_map = self
            .held_map(kept)
            .ok_or_else(|| anyhow!("the unit terms cannot be solved on these runs"))?;
        let mut se = vec![f64::INFINITY; self.terms];
        if n >= 2 {
            let mut leave = Vec::with_capacity(n);
            for r in 0..n {
                leave.push(self.fit(kept, held_at, Some(r)).ok_or_else(|| {
                    anyhow!("the unit terms cannot be solved without run {}", r + 1)
                })?);
            }
            for &k in kept {
                let mean = leave.iter().map(|c| c[k]).sum::<f64>() / n as f64;
                let ss: f64 = leave.iter().map(|c| (c[k] - mean).powi(2)).sum();
                se[k] = ((n as f64 - 1.0) / n as f64 * ss).sqrt();
            }
        }
        Ok(HeldEstimate { own, se, held_map })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four runs of 40 rows; columns: a ramp, a near twin of the ramp (ramp + 1e-3
    /// wiggle) and an independent wiggle; y = planted coefficients + each run's noise.
    fn rows(coef: [f64; 3], noise: f64) -> UnitRows {
        let (mut residual, mut cols, mut run, mut t) = (
            Vec::new(),
            vec![Vec::new(), Vec::new(), Vec::new()],
            Vec::new(),
            Vec::new(),
        );
        for r in 0..4 {
            for i in 0..40 {
                let x = i as f64 / 40.0 - 0.5;
                let c = [x, x + 1e-3 * (7.0 * x).sin(), (3.0 * x).cos()];
                let wobble = noise * ((r * 40 + i) as f64 * 1.7).sin();
                residual.push(c.iter().zip(coef).map(|(a, b)| a * b).sum::<f64>() + wobble);
                for k in 0..3 {
                    cols[k].push(c[k]);
                }
                run.push(r);
                t.push(10.0 * i as f64);
            }
        }
        UnitRows::from_parts(residual, cols, run, t)
    }

    #[test]
    fn every_term_fitted_reads_what_was_planted_and_maps_nothing() {
        let m = RunMoments::of(&rows([0.2, -0.1, 0.05], 0.0));
        let e = m.held_estimate(&[0, 1, 2], &[0.0; 3]).unwrap();
        // the twins differ by 1e-3: the whisper of ridge moves them by ~5e-5
        for (k, want) in [0.2, -0.1, 0.05].into_iter().enumerate() {
            assert!((e.own[k] - want).abs() < 1e-3, "{:?}", e.own);
        }
        assert_eq!(e.held_map, vec![vec![0.0; 3]; 3]);
    }

    #[test]
    fn a_held_twin_maps_into_the_term_it_resembles_and_not_the_other() {
        // noisy: with both twins fitted each has a huge se; with one held, the other's is
        // small and takes the held twin's deviation (A ~ 1), the independent wiggle not
        // (A ~ 0); the estimate is the all-at-once one plus A times the held deviation
        let m = RunMoments::of(&rows([0.2, 0.03, 0.05], 1e-3));
        let both = m.held_estimate(&[0, 1, 2], &[0.0; 3]).unwrap();
        let held = m.held_estimate(&[0, 2], &[0.0; 3]).unwrap();
        assert!(both.se[0] > 50.0 * held.se[0], "{both:?} {held:?}");
        assert!((held.held_map[0][1] - 1.0).abs() < 0.05, "{held:?}");
        assert!(held.held_map[2][1].abs() < 0.05, "{held:?}");
        assert!((held.own[0] - 0.23).abs() < 1e-2, "{held:?}");
        let via_map = both.own[0] + held.held_map[0][1] * both.own[1];
        assert!((held.own[0] - via_map).abs() < 1e-3, "{held:?} {both:?}");
        assert!(held.se[1].is_infinite() && held.own[1] == 0.0);
    }
}
