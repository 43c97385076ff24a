//! scratch (temporary)
use fog_sim::northseek::*;
use fog_sim::report_pipeline::*;
use fog_sim::sim::GyroParams;

#[test]
fn scratch() {
    let params = GyroParams::paper_default();
    let plan = CampaignPlan { ambients_c: vec![20.0], runs_per_ambient: 3, ..CampaignPlan::paper(1) };
    let campaign = simulate_campaign(&params, &plan, 2, &|| ()).unwrap();
    let runs: Vec<_> = campaign.iter().map(|c| &c.run).collect();
    let trained = train_default(&runs, "sim").unwrap();
    println!("{:?}", trained.report.cross_validation.scan);
    let mut p = GyroParams::paper_default();
    p.noise.arw_dpsh = 0.0;
    p.noise.bias_instability_dph = 0.0;
    p.noise.rrw_dph_per_sqrt_h = 0.0;
    p.noise.quantization_arcsec = 0.0;
    p.drift.turn_on_bias_sigma_dph = 0.0;
    p.variation.power_sigma_frac = 0.0;
    p.variation.start_temp_sigma_c = 0.0;
    let mut cfg = MonteCarloConfig::paper(1);
    cfg.turntable.indexing_sigma_deg = 0.0;
    let s = run_seeks(&p, &cfg, Some(&trained.model), 1).unwrap();
    for o in &s { println!("drift only, compensated: {:.5} {:.1} {:.1}", azimuth_error_deg(o.azimuth_deg, cfg.true_azimuth_deg), o.t_start_s, o.duration_s); }
    p.sensor.noise_c = 0.0;
    let s = run_seeks(&p, &cfg, Some(&trained.model), 1).unwrap();
    for o in &s { println!("drift only, no T noise, compensated: {:.5} {:.1} {:.1}", azimuth_error_deg(o.azimuth_deg, cfg.true_azimuth_deg), o.t_start_s, o.duration_s); }
}
