//! The IEEE Std 952 fit of `stats::allan` on synthetic rate series with known Q, N, B,
//! K, R (seeded; tau0 = 1 s, 2^17 samples). Each generator has a twin with a different
//! physical law at a matched scale (the fit must put it in another term, not this one)
//! and a null (the term absent: it must not be detected). A mixed N + B + K series is
//! the realistic gyro. Printed numbers are the ones in docs/explain/allan.md.

use fog_sim::stats::allan::{adev_of_series, Term};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const LEN: usize = 1 << 17;
const TAU0_S: f64 = 1.0;

fn normals(seed: u64) -> impl FnMut() -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    move || StandardNormal.sample(&mut rng)
}

/// White angle noise of sigma `q_arcsec`, as a rate: (x_k+1 - x_k) / tau0 (arcsec/s = deg/h).
fn quantisation(q_arcsec: f64, seed: u64) -> Vec<f64> {
    let mut g = normals(seed);
    let x: Vec<f64> = (0..=LEN).map(|_| q_arcsec * g()).collect();
    x.windows(2).map(|w| (w[1] - w[0]) / TAU0_S).collect()
}

/// White rate noise of ARW `n_dpsh`: sigma per sample N / sqrt(tau0 in h).
fn white(n_dpsh: f64, seed: u64) -> Vec<f64> {
    let s = n_dpsh / (TAU0_S / 3600.0).sqrt();
    let mut g = normals(seed);
    (0..LEN).map(|_| s * g()).collect()
}

/// Flicker rate noise of bias instability `b_dph`: one Gauss-Markov process per octave
/// of correlation time (1 s .. 2^17 s, the record), equal variances s^2; their sum has the one-sided
/// PSD s^2 / (ln 2 f) inside the band, and IEEE 952's B^2 / (pi f) gives s = B sqrt(ln 2 / pi).
fn flicker(b_dph: f64, seed: u64) -> Vec<f64> {
    let s = b_dph * (std::f64::consts::LN_2 / std::f64::consts::PI).sqrt();
    let mut g = normals(seed);
    let taus: Vec<f64> = (0..=17).map(|k| f64::from(1u32 << k)).collect();
    let a: Vec<f64> = taus.iter().map(|t| (-TAU0_S / t).exp()).collect();
    let mut state: Vec<f64> = taus.iter().map(|_| s * g()).collect();
    (0..LEN)
        .map(|_| {
            for (x, a) in state.iter_mut().zip(&a) {
                *x = a * *x + s * (1.0 - a * a).sqrt() * g();
            }
            state.iter().sum()
        })
        .collect()
}

/// Random walk of the rate, K in deg/h/sqrt(h): step sigma K sqrt(tau0 in h).
fn rate_walk(k: f64, seed: u64) -> Vec<f64> {
    let step = k * (TAU0_S / 3600.0).sqrt();
    let mut g = normals(seed);
    let mut y = 0.0;
    (0..LEN)
        .map(|_| {
            y += step * g();
            y
        })
        .collect()
}

/// Rate ramp R deg/h^2 (deterministic) on top of a faint white noise.
fn ramp(r: f64, seed: u64) -> Vec<f64> {
    let w = white(1e-5, seed);
    w.iter()
        .enumerate()
        .map(|(i, v)| r * i as f64 * TAU0_S / 3600.0 + v)
        .collect()
}

fn add(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + y).collect()
}

/// (value, 1 sigma, detected) of `term` fitted on `y`.
fn fitted(y: &[f64], term: Term) -> (f64, f64, bool) {
    let a = adev_of_series(y, TAU0_S).unwrap();
    let t = a.noise.get(term).unwrap();
    (t.value, t.sigma, t.detected)
}

/// A seeded series generator: (scale, seed) -> rate, deg/h.
type Generator = fn(f64, u64) -> Vec<f64>;

struct Case {
    term: Term,
    truth: f64,
    /// The law itself, seeded.
    law: Generator,
    /// Twin: another law at a matched scale, and the term it must be read as.
    twin: (Generator, f64, Term),
    /// Largest relative error of the recovered value (measured, with margin).
    tolerance: f64,
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            term: Term::Q,
            truth: 0.5,
            law: quantisation,
            twin: (white, 0.5 * 2f64.sqrt() / 60.0, Term::N),
            tolerance: 0.01,
        },
        Case {
            term: Term::N,
            truth: 1e-3,
            law: white,
            twin: (rate_walk, 1e-3, Term::K),
            tolerance: 0.01,
        },
        Case {
            term: Term::B,
            truth: 5e-3,
            law: flicker,
            twin: (white, 5e-3 / 60.0 * 3.0, Term::N),
            tolerance: 0.15,
        },
        Case {
            term: Term::K,
            truth: 1e-2,
            law: rate_walk,
            twin: (white, 1e-2, Term::N),
            tolerance: 0.02,
        },
        Case {
            term: Term::R,
            truth: 1e-2,
            law: ramp,
            twin: (rate_walk, 1e-2, Term::K),
            tolerance: 0.01,
        },
    ]
}

#[test]
fn each_term_is_recovered_its_twin_is_another_term_and_its_null_is_not_detected() {
    for c in cases() {
        for seed in [1u64, 2, 3] {
            let (v, s, det) = fitted(&(c.law)(c.truth, seed), c.term);
            println!(
                "{:?}: truth {:.3e}, fitted {v:.4e} +/- {s:.1e} (error {:+.1} %, {:.1} sigma)",
                c.term,
                c.truth,
                100.0 * (v / c.truth - 1.0),
                (v - c.truth) / s
            );
            assert!(
                det && (v / c.truth - 1.0).abs() <= c.tolerance,
                "{:?} seed {seed}: {v} vs {}",
                c.term,
                c.truth
            );
        }
        let (twin, scale, as_term) = c.twin;
        let y = twin(scale, 9);
        let (_, _, own) = fitted(&y, c.term);
        let (_, _, other) = fitted(&y, as_term);
        println!(
            "{:?} twin: read as {as_term:?} {other}, as {:?} {own}",
            c.term, c.term
        );
        assert!(other && !own, "{:?}: the twin's law is {as_term:?}", c.term);
    }
    // Nulls: white rate noise has no Q, B, K or R; white angle noise has no N (its Allan
    // variance is exactly 3 Q^2 / tau^2; a sampled random walk of the rate is no null for
    // N: its block means carry a white part of step^2 tau0 / 6).
    let w = white(1e-3, 21);
    for t in [Term::Q, Term::B, Term::K, Term::R] {
        assert!(!fitted(&w, t).2, "white noise: {t:?} detected");
    }
    assert!(
        !fitted(&quantisation(0.5, 22), Term::N).2,
        "white angle: N detected"
    );
}

#[test]
fn a_realistic_gyro_n_b_k_is_read_term_by_term() {
    let (n, b, k) = (1e-3, 4e-3, 5e-3);
    let y = add(&add(&white(n, 31), &flicker(b, 32)), &rate_walk(k, 33));
    let a = adev_of_series(&y, TAU0_S).unwrap();
    for (term, truth, tol) in [(Term::N, n, 0.05), (Term::B, b, 0.3), (Term::K, k, 0.5)] {
        let t = a.noise.get(term).unwrap();
        println!(
            "mixed {term:?}: truth {truth:.3e}, fitted {:.4e} +/- {:.1e} ({:+.1} %), read from tau {:?}..{:?} s",
            t.value,
            t.sigma,
            100.0 * (t.value / truth - 1.0),
            t.tau_from_s,
            t.tau_to_s
        );
        assert!(
            t.detected && (t.value / truth - 1.0).abs() <= tol,
            "{term:?}"
        );
    }
    assert!(!a.noise.get(Term::Q).unwrap().detected);
}
