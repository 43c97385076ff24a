//! diagnose's k-means (`diagnose::baseline::rbf_basis::kmeans`: Lloyd from a farthest-point start, 12
//! iterations) against linfa-clustering's `KMeans` (k-means++ start, seeded Xoshiro, the same
//! 12-iteration cap, `n_runs` 1 and its default 10), on the inputs diagnose places RBF centres
//! on: z-scored (T, dT/dt) points of a simulated paper campaign, and the 3-d twin
//! (T, dT/dt, time since power-on), n = 500 and 5,000, k = 8 and 24.
//!
//! Before timing, it prints per case the final inertia (sum of squared distances from each
//! point to its nearest centre, computed here the same way for both) and whether linfa's
//! centres are bit-identical for the same input and seed twice, and with 1 vs 2 rayon threads
//! (diagnose's outputs must be byte-reproducible).
//! `cargo bench -p fog-bench --bench diagnose_kmeans -- --warm-up-time 1 --measurement-time 3`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fog_sim::diagnose::baseline::rbf_basis::kmeans;
use linfa::traits::Fit;
use linfa::DatasetBase;
use linfa_clustering::KMeans;
use ndarray::Array2;
use rand_xoshiro::rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256Plus;
use std::hint::black_box;

#[path = "support/campaign.rs"]
mod campaign;
use campaign::paper_training_set;

/// diagnose's iteration cap (`basis::kmeans`), given to linfa too.
const MAX_ITERATIONS: u64 = 12;
const LINFA_SEED: u64 = 12;
/// linfa-clustering's default `n_runs`.
const LINFA_DEFAULT_RUNS: usize = 10;

/// z-scored campaign points: (T, dT/dt), or (T, dT/dt, t since power-on) when `with_time`.
fn campaign_points(with_time: bool) -> Vec<Vec<f64>> {
    let ds = paper_training_set();
    let mut cols: Vec<Vec<f64>> = (0..ds.n_inputs())
        .map(|j| ds.rows().map(|r| r[j]).collect())
        .collect();
    if with_time {
        cols.push(ds.t_s.clone());
    }
    for col in &mut cols {
        let n = col.len() as f64;
        let mean = col.iter().sum::<f64>() / n;
        let sd = (col.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt();
        col.iter_mut().for_each(|x| *x = (*x - mean) / sd);
    }
    (0..cols[0].len())
        .map(|i| cols.iter().map(|c| c[i]).collect())
        .collect()
}

/// `n` points spread evenly over the whole campaign (every run, whole warm-up).
fn spread(points: &[Vec<f64>], n: usize) -> Vec<Vec<f64>> {
    assert!(points.len() >= n, "campaign has {} points", points.len());
    (0..n)
        .map(|i| points[i * points.len() / n].clone())
        .collect()
}

fn inertia(points: &[Vec<f64>], centres: &[Vec<f64>]) -> f64 {
    points
        .iter()
        .map(|p| {
            centres
                .iter()
                .map(|c| c.iter().zip(p).map(|(a, b)| (a - b) * (a - b)).sum::<f64>())
                .fold(f64::INFINITY, f64::min)
        })
        .sum()
}

fn linfa_kmeans<T>(data: &DatasetBase<Array2<f64>, T>, k: usize, runs: usize) -> Vec<Vec<f64>> {
    let model = KMeans::params_with_rng(k, Xoshiro256Plus::seed_from_u64(LINFA_SEED))
        .max_n_iterations(MAX_ITERATIONS)
        .n_runs(runs)
        .fit(data)
        .expect("linfa k-means");
    model
        .centroids()
        .rows()
        .into_iter()
        .map(|r| r.to_vec())
        .collect()
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("rayon pool")
        .install(f)
}

fn same_bits(a: &[Vec<f64>], b: &[Vec<f64>]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            p.len() == q.len() && p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits())
        })
}

fn bench(c: &mut Criterion) {
    for (label, with_time) in [("T_dTdt", false), ("T_dTdt_t", true)] {
        let all = campaign_points(with_time);
        let mut g = c.benchmark_group(format!("kmeans_{label}"));
        for n in [500usize, 5_000] {
            let pts = spread(&all, n);
            let data = DatasetBase::from(
                Array2::from_shape_vec((n, pts[0].len()), pts.concat()).expect("shape"),
            );
            for k in [8usize, 24] {
                let ours = kmeans(&pts, k);
                assert!(same_bits(&ours, &kmeans(&pts, k)), "ours not repeatable");
                let one = linfa_kmeans(&data, k, 1);
                let ten = linfa_kmeans(&data, k, LINFA_DEFAULT_RUNS);
                let repeat = same_bits(&ten, &linfa_kmeans(&data, k, LINFA_DEFAULT_RUNS));
                let threads = same_bits(
                    &in_pool(1, || linfa_kmeans(&data, k, LINFA_DEFAULT_RUNS)),
                    &in_pool(2, || linfa_kmeans(&data, k, LINFA_DEFAULT_RUNS)),
                );
                println!(
                    "inertia {label} n {n} k {k}: ours {:.4}  linfa_1run {:.4}  linfa_10runs {:.4}  \
                     linfa same twice: {repeat}  1 vs 2 threads: {threads}",
                    inertia(&pts, &ours),
                    inertia(&pts, &one),
                    inertia(&pts, &ten),
                );
                let id = format!("n{n}_k{k}");
                g.bench_with_input(BenchmarkId::new("ours", &id), &k, |b, &k| {
                    b.iter(|| black_box(kmeans(&pts, k)))
                });
                for runs in [1, LINFA_DEFAULT_RUNS] {
                    g.bench_with_input(
                        BenchmarkId::new(format!("linfa_{runs}run"), &id),
                        &k,
                        |b, &k| b.iter(|| black_box(linfa_kmeans(&data, k, runs))),
                    );
                }
            }
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
