//! diagnose's dense solve: the hand-written Cholesky it used until issue 12 (kept here as
//! the reference) against nalgebra's, which `diagnose::linalg::solve_spd` now uses, on the
//! sizes diagnose solves: 6 (a polynomial base, a candidate and a few run dummies), 24 and
//! 40 (RBF centres, inputs, candidate columns, run dummies of a time-block layout).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

/// The former hand-written in-place Cholesky solve (row-major `a`, `b` becomes `x`).
fn solve_spd(a: &mut [f64], b: &mut [f64], n: usize) -> Result<(), ()> {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 || !d.is_finite() {
            return Err(());
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k * n + i] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    Ok(())
}

/// A symmetric positive-definite Gram matrix X'X of a deterministic n-column design.
fn gram(n: usize) -> (Vec<f64>, Vec<f64>) {
    let rows = 10 * n;
    let x: Vec<f64> = (0..rows * n)
        .map(|k| {
            ((k * 7919 % 1009) as f64 / 1009.0 - 0.5) + if k % (n + 1) == 0 { 1.0 } else { 0.0 }
        })
        .collect();
    let mut a = vec![0.0; n * n];
    let mut b = vec![0.0; n];
    for r in 0..rows {
        let row = &x[r * n..(r + 1) * n];
        for i in 0..n {
            b[i] += row[i] * (r as f64 * 0.01).sin();
            for j in 0..n {
                a[i * n + j] += row[i] * row[j];
            }
        }
    }
    (a, b)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("spd_solve");
    for n in [6usize, 24, 40] {
        let (a, b) = gram(n);
        g.bench_with_input(BenchmarkId::new("hand_written", n), &n, |bch, &n| {
            bch.iter(|| {
                let (mut a, mut b) = (a.clone(), b.clone());
                solve_spd(&mut a, &mut b, n).unwrap();
                black_box(b)
            })
        });
        g.bench_with_input(BenchmarkId::new("nalgebra", n), &n, |bch, &n| {
            bch.iter(|| {
                let m = nalgebra::DMatrix::from_row_slice(n, n, &a);
                let v = nalgebra::DVector::from_column_slice(&b);
                black_box(m.cholesky().unwrap().solve(&v))
            })
        });
        // Same answer (to rounding) before comparing speed.
        let (mut a2, mut b2) = (a.clone(), b.clone());
        solve_spd(&mut a2, &mut b2, n).unwrap();
        let m = nalgebra::DMatrix::from_row_slice(n, n, &a);
        let x = m
            .cholesky()
            .unwrap()
            .solve(&nalgebra::DVector::from_column_slice(&b));
        let diff = b2
            .iter()
            .zip(x.iter())
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(
            diff < 1e-9 * x.amax().max(1.0),
            "n {n}: solutions differ by {diff}"
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
