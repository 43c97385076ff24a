//! Trainer benchmarks at the paper's full campaign size (11 ambients x 3 runs x 270
//! points = ~8,900 candidate centres): design build, one selection pass over all
//! candidates, and complete OLS / Orr fits at one width.
//! `cargo bench -p fog-bench --bench train`

use criterion::{criterion_group, criterion_main, Criterion};
use fog_sim::train::{fit_width, grid_candidates, GaussianDesign, Method, Normalizer, TrainConfig};
use std::hint::black_box;

#[path = "support/campaign.rs"]
mod campaign;
use campaign::paper_training_set;

fn bench_train(c: &mut Criterion) {
    let ds = paper_training_set();
    let n = ds.len();
    let points = Normalizer::fit(&ds)
        .expect("normaliser")
        .normalized_rows(&ds);
    let candidates = grid_candidates(&points, 2, 2, 0.6, TrainConfig::default().max_candidates);
    let k = candidates.len();
    let mut g = c.benchmark_group(format!("train_{n}_points_{k}_candidates"));
    g.sample_size(10);
    g.bench_function("design_build_f32", |b| {
        b.iter(|| black_box(GaussianDesign::build(&points, 2, 2, &candidates, 0.6, 2)))
    });
    let design = GaussianDesign::build(&points, 2, 2, &candidates, 0.6, 2);
    let v = vec![1.0; n];
    let mut out = vec![0.0; k];
    g.bench_function("selection_pass_all_candidates", |b| {
        b.iter(|| design.dot_columns(black_box(&v), &mut out))
    });
    let ols = TrainConfig {
        rho: 1e-6,
        ..TrainConfig::default()
    };
    g.bench_function("ols_fit_64_centres", |b| {
        b.iter(|| black_box(fit_width(&ds, &ols, 0.6).expect("fit")))
    });
    let orr = TrainConfig {
        method: Method::OrrGcv,
        ..TrainConfig::default()
    };
    g.bench_function("orr_gcv_fit", |b| {
        b.iter(|| black_box(fit_width(&ds, &orr, 0.6).expect("fit")))
    });
    g.finish();
}

criterion_group!(benches, bench_train);
criterion_main!(benches);
