mod train_support;
use fog_sim::train::GaussianDesign;
use train_support::{campaign, shupe_like};
#[test]
fn prof() {
    let ambients: Vec<f64> = (0..11).map(|i| -40.0 + 10.0 * f64::from(i)).collect();
    let ds = campaign(&ambients, 3, 0.01, 7, shupe_like);
    let norm = fog_sim::train::Normalizer::fit(&ds).unwrap();
    let pts = norm.normalized_rows(&ds);
    for th in [1, 2] {
        let t0 = std::time::Instant::now();
        let d = GaussianDesign::build(&pts, 2, 2, 0.35, th);
        let t1 = t0.elapsed().as_secs_f64();
        let v = vec![1.0; d.len()];
        let mut out = vec![0.0; d.len()];
        let t0 = std::time::Instant::now();
        for _ in 0..10 { d.dot_columns(&v, &mut out); }
        eprintln!("threads {th}: build {t1:.3} s, matvec {:.4} s", t0.elapsed().as_secs_f64() / 10.0);
    }
}
