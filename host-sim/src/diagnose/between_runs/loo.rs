//! The run-level fits: run offsets explained by run features, scored leaving one run out,
//! and the permutation check (features shuffled across runs). Split from the stage's
//! sequence (`between_runs`) because both the free-offset level model and the tests
//! below use them on their own.

use crate::diagnose::linalg::solve_spd;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Run-level permutations for the check p-value.
pub const PERMUTATIONS: usize = 4_000;
/// Seed of the permutations (results are deterministic).
pub const PERM_SEED: u64 = 0xBE7_3EE2;

/// Least squares o = a + b . f over `rows` (small ridge for stability).
pub fn fit(o: &[f64], f: &[Vec<f64>], rows: &[usize]) -> Option<Vec<f64>> {
    fit_over(o, f, rows.iter().copied())
}

/// [`fit`] over the rows an iterator gives (leave-one-out: no list of rows a run).
fn fit_over(o: &[f64], f: &[Vec<f64>], rows: impl Iterator<Item = usize>) -> Option<Vec<f64>> {
    let q = 1 + f.first().map_or(0, Vec::len);
    let mut a = vec![0.0; q * q];
    let mut b = vec![0.0; q];
    let mut x = vec![1.0; q];
    // The row [1, f[r]...] copied into one buffer (this runs for every permutation of
    // every candidate); the lower triangle summed and mirrored (the same products).
    for r in rows {
        for (xi, fi) in x[1..].iter_mut().zip(&f[r]) {
            *xi = *fi;
        }
        for i in 0..q {
            b[i] += x[i] * o[r];
            let xi = x[i];
            a[i * q..=i * q + i]
                .iter_mut()
                .zip(&x[..=i])
                .for_each(|(s, xj)| *s += xi * xj);
        }
    }
    for i in 0..q {
        for j in 0..i {
            a[j * q + i] = a[i * q + j];
        }
        a[i * q + i] += 1e-9 * (1.0 + a[i * q + i]);
    }
    solve_spd(&mut a, &mut b, q).ok()?;
    Some(b)
}

pub fn predict(coef: &[f64], f: &[f64]) -> f64 {
    coef[0] + coef[1..].iter().zip(f).map(|(c, x)| c * x).sum::<f64>()
}

/// Leave-one-run-out errors of the offsets under o = a + b . f (f empty: the mean).
pub fn loo_errors(o: &[f64], f: &[Vec<f64>]) -> Option<Vec<f64>> {
    let n = o.len();
    (0..n)
        .map(|r| {
            let rows: Vec<usize> = (0..n).filter(|&i| i != r).collect();
            let coef = fit(o, f, &rows)?;
            Some(o[r] - predict(&coef, &f[r]))
        })
        .collect()
}

/// Per-run held-out gains (run's points x drop in squared offset error, leave one run
/// out), the leave-one-out rms without and with the candidate.
pub fn loo_gains(o: &[f64], lens: &[usize], f: &[Vec<f64>]) -> Option<(Vec<f64>, f64, f64)> {
    let n = o.len();
    let mut gains = Vec::with_capacity(n);
    let (mut ss0, mut ss1) = (0.0, 0.0);
    for r in 0..n {
        let others = || (0..n).filter(move |&i| i != r);
        let m = others().map(|i| o[i]).sum::<f64>() / (n - 1) as f64;
        let coef = fit_over(o, f, others())?;
        let e0 = o[r] - m;
        let e1 = o[r] - predict(&coef, &f[r]);
        ss0 += e0 * e0;
        ss1 += e1 * e1;
        gains.push(lens[r] as f64 * (e0 * e0 - e1 * e1));
    }
    Some((gains, (ss0 / n as f64).sqrt(), (ss1 / n as f64).sqrt()))
}

/// Run-level permutation p of the total gain (features shuffled across runs).
pub fn permutation_p(o: &[f64], lens: &[usize], f: &[Vec<f64>]) -> f64 {
    let Some((g, _, _)) = loo_gains(o, lens, f) else {
        return 1.0;
    };
    let obs: f64 = g.iter().sum();
    let mut rng = ChaCha8Rng::seed_from_u64(PERM_SEED);
    let mut perm: Vec<Vec<f64>> = f.to_vec();
    let mut hits = 1usize;
    for _ in 0..PERMUTATIONS {
        perm.shuffle(&mut rng);
        if let Some((gp, _, _)) = loo_gains(o, lens, &perm) {
            if gp.iter().sum::<f64>() >= obs - 1e-12 * obs.abs() {
                hits += 1;
            }
        }
    }
    hits as f64 / (PERMUTATIONS + 1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::between_runs::heading::heading_effect;

    #[test]
    fn a_heading_harmonic_in_the_offsets_is_recovered() {
        let n = 12;
        let lens = vec![100; n];
        let f: Vec<Vec<f64>> = (0..n)
            .map(|r| {
                let h = (r as f64 * 97.0).to_radians();
                vec![h.cos(), h.sin()]
            })
            .collect();
        let jitter = |r: usize| 0.002 * ((r as f64 * 12.9898).sin() * 43_758.5).fract();
        let o: Vec<f64> = (0..n)
            .map(|r| 0.5 + 0.03 * f[r][0] - 0.01 * f[r][1] + jitter(r))
            .collect();
        let (g, rms0, rms1) = loo_gains(&o, &lens, &f).unwrap();
        assert!(rms1 < 0.2 * rms0, "{rms0} -> {rms1}");
        assert!(g.iter().sum::<f64>() > 0.0);
        assert!(permutation_p(&o, &lens, &f) < 0.01);
        let all: Vec<usize> = (0..n).collect();
        let e = heading_effect("heading_deg", &fit(&o, &f, &all).unwrap(), 40.0);
        assert!((e.amplitude_dph - 0.0316).abs() < 0.002, "{e:?}");
        assert!((e.phase_deg - 341.6).abs() < 3.0, "{e:?}");
        let unrelated: Vec<Vec<f64>> = (0..n).map(|r| vec![((r * 5) % 7) as f64]).collect();
        let flat: Vec<f64> = (0..n).map(jitter).collect();
        assert!(permutation_p(&flat, &lens, &unrelated) > 0.01);
    }
}
