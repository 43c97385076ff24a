//! Worst error of the fixed-point (and f32) drift against the f64 reference over a model's
//! trained input range. With a model file (e.g. from `fogsim train`) it measures that model,
//! otherwise the synthetic 35- and 64-centre models.
//!
//! `cargo run -p fog-core --release --example fixed_error -- [MODEL]...`

use fog_core::model::accuracy::worst_errors;
use fog_core::model::format::RbfModel;
use fog_core::model::synthetic::warmup_model;

fn report(name: &str, m: &RbfModel) {
    match worst_errors(m, 250_000, 250_000, 1) {
        Ok(r) => println!(
            "{name}: {} centres, {} inputs, |drift| <= {:.3} deg/h over {} points: worst |fixed - f64| = {:.3e} deg/h, |f32 - f64| = {:.3e} deg/h",
            m.centers.len(),
            m.inputs.len(),
            r.max_abs_drift_dph,
            r.n_points,
            r.worst_fixed_dph,
            r.worst_f32_dph
        ),
        Err(e) => eprintln!("{name}: {e}"),
    }
}

fn main() {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        report("synthetic 35", &warmup_model(35, 2, 2.0, 2013));
        report("synthetic 64x4", &warmup_model(64, 4, 2.0, 64));
    }
    for p in paths {
        let bytes = match std::fs::read(&p) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("{p}: cannot read: {e}");
                std::process::exit(1);
            }
        };
        match RbfModel::decode(&bytes) {
            Ok(m) => report(&p, &m),
            Err(e) => {
                eprintln!("{p}: {e}");
                std::process::exit(1);
            }
        }
    }
}
