#[path = "common/planted.rs"]
mod planted;
use fog_sim::diagnose::*;
use planted::*;

#[test]
fn scratch() {
    let eff = match std::env::var("EFF").as_deref() { Ok("accel") => Effect::TempAccel, Ok("null") => Effect::Null, Ok("value") => Effect::ColumnValue, _ => Effect::PowerOnTransient };
    let seed: u64 = std::env::var("SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(11);
    let sig: f64 = std::env::var("SIG").ok().and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let (runs, _) = campaign(eff, seed, Shape { sigmas: sig, ..Shape::default() });
    let c = input::prepare(&runs).unwrap();
    let st = models::Stacked::new(&c);
    let folds = cv::Folds::new(&st.run_lengths).unwrap();
    let base = models::fit_baseline(&folds, &st).unwrap();
    println!("base rms {:.4} k {} wf {} ridge {}", base.cv.rms(), base.centres, base.width_factor, base.ridge);
    let cands = transforms::enumerate(&c);
    let mut rows = vec![];
    for cand in cands {
        let per_run: Vec<Vec<Vec<f64>>> = c.runs.iter().map(|s| cand.compute(s)).collect();
        let m = per_run[0].len();
        let cols: Vec<Vec<f64>> = (0..m).map(|j| per_run.iter().flat_map(|r| r[j].iter().copied()).collect()).collect();
        let cv = base.prepared.validate_with(&folds, &cols).unwrap();
        let g = screen::unit_gains(&base.cv, &cv);
        let tot: f64 = g.iter().sum();
        let l1: f64 = g.iter().map(|x| x.abs()).sum();
        rows.push((cand.label(), tot, l1, g));
    }
    rows.sort_by(|a, b| b.2.total_cmp(&a.2));
    for r in rows.iter().take(12) {
        println!("{:<28} sum {:+.5} l1 {:.5} {:?}", r.0, r.1, r.2, r.3.iter().map(|x| (x * 1e4).round() / 1e4).collect::<Vec<_>>());
    }
    // linear baseline experiment
    let lin = vec![st.temp_c.clone(), st.temp_c.iter().map(|t| t * t).collect(), st.temp_rate_cps.clone()];
    let lp = cv::Prepared::new(&folds, &lin, &st.y, 1e-9);
    let lcv = lp.validate(&folds).unwrap();
    println!("linear baseline rms {:.4}", lcv.rms());
    for tau in [120.0, 240.0, 480.0] {
        let dec: Vec<f64> = st.t_s.iter().map(|t| (-t / tau).exp()).collect();
        let cvd = lp.validate_with(&folds, &[dec.clone()]).unwrap();
        let g = screen::unit_gains(&lcv, &cvd);
        println!("lin+decay{tau} rms {:.4} {:?}", cvd.rms(), g.iter().map(|x| (x * 1e4).round() / 1e4).collect::<Vec<_>>());
        let cvr = base.prepared.validate_with(&folds, &[dec]).unwrap();
        let g = screen::unit_gains(&base.cv, &cvr);
        println!("rbf+decay{tau} rms {:.4} {:?}", cvr.rms(), g.iter().map(|x| (x * 1e4).round() / 1e4).collect::<Vec<_>>());
    }
    let d = diagnose(&runs).unwrap();
    println!("{}", report::render_text(&d.report));
}

#[test]
fn scratch_effect_size() {
    for eff in [Effect::PowerOnTransient, Effect::TempAccel, Effect::ColumnValue] {
        let (a, _) = campaign(Effect::Null, 11, Shape::default());
        let (b, _) = campaign(eff, 11, Shape::default());
        let d: Vec<f64> = a.iter().zip(&b).flat_map(|(x, y)| x.rate_dph().iter().zip(y.rate_dph()).map(|(p, q)| q - p).collect::<Vec<_>>()).collect();
        let peak = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let rms = (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt();
        println!("{eff:?}: peak {peak:.4} rms {rms:.4} first {:?}", &d[..5]);
    }
}
