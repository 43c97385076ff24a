//! Criterion benchmark of one drift evaluation: f32 (`libm::expf`) vs integer-only fixed
//! point, for 35 centres (the paper's gyro 008) and 64 (the format's maximum), 2 inputs
//! (T, dT/dt). Run: `cargo bench -p fog-bench --bench rbf`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fog_core::model::fixed::FixedModel;
use fog_core::model::rbf::{predict_f32, predict_f64};
use fog_core::model::synthetic::{random_warmup_point, warmup_model, SplitMix64};
use std::hint::black_box;

fn inputs(n: usize) -> Vec<[f32; 2]> {
    let mut rng = SplitMix64::new(7);
    (0..n)
        .map(|_| {
            let x = random_warmup_point(&mut rng);
            [x[0] as f32, x[1] as f32]
        })
        .collect()
}

fn bench_rbf(c: &mut Criterion) {
    let xs = inputs(256);
    let mut g = c.benchmark_group("rbf_predict");
    for centers in [35usize, 64] {
        let model = warmup_model(centers, 2, 2.0, 2013);
        let fixed = FixedModel::from_model(&model).unwrap();
        let mut i = 0usize;
        g.bench_with_input(BenchmarkId::new("f32", centers), &model, |b, m| {
            b.iter(|| {
                i = (i + 1) & 255;
                predict_f32(m, black_box(&xs[i])).unwrap()
            })
        });
        g.bench_with_input(BenchmarkId::new("fixed", centers), &fixed, |b, f| {
            b.iter(|| {
                i = (i + 1) & 255;
                f.predict(black_box(&xs[i])).unwrap()
            })
        });
        g.bench_with_input(
            BenchmarkId::new("f64_reference", centers),
            &model,
            |b, m| {
                b.iter(|| {
                    i = (i + 1) & 255;
                    let x = [xs[i][0] as f64, xs[i][1] as f64];
                    predict_f64(m, black_box(&x)).unwrap()
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench_rbf);
criterion_main!(benches);
