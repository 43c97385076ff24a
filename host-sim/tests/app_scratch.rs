//! scratch (temporary)
use fog_sim::northseek::*;
use fog_sim::sim::GyroParams;

#[test]
fn scratch() {
    for case in 0..5 {
        let mut p = GyroParams::paper_default();
        match case {
            1 => p.noise.bias_instability_dph = 0.0,
            2 => p.noise.rrw_dph_per_sqrt_h = 0.0,
            3 => {
                p.noise.bias_instability_dph = 0.0;
                p.noise.rrw_dph_per_sqrt_h = 0.0;
                p.noise.quantization_arcsec = 0.0;
            }
            4 => {
                p.noise.bias_instability_dph = 0.0;
                p.noise.rrw_dph_per_sqrt_h = 0.0;
                p.noise.quantization_arcsec = 0.0;
                p.turntable_dummy();
            }
            _ => {}
        }
        let mut cfg = MonteCarloConfig::paper(1);
        cfg.starts = 24;
        if case == 4 {
            cfg.turntable.indexing_sigma_deg = 0.0;
        }
        let model = None;
        let outs: Vec<_> = (0..cfg.starts)
            .map(|i| run_seeks(&p, &cfg, model, cfg.start_seed(i)).unwrap())
            .collect();
        let st = seek_stats(&outs, cfg.true_azimuth_deg);
        let late: Vec<f64> = outs
            .iter()
            .flat_map(|s| {
                s[3..]
                    .iter()
                    .map(|o| azimuth_error_deg(o.azimuth_deg, cfg.true_azimuth_deg))
            })
            .collect();
        let m = late.iter().sum::<f64>() / late.len() as f64;
        let sd =
            (late.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (late.len() - 1) as f64).sqrt();
        println!(
            "case {case}: per-seek rms {:?} late std {sd:.4} mean {m:.4}",
            st.per_seek_std_deg
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect::<Vec<_>>()
        );
    }
}
trait Dummy {
    fn turntable_dummy(&mut self);
}
impl Dummy for GyroParams {
    fn turntable_dummy(&mut self) {}
}
