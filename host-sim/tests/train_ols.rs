//! OLS trainer behaviour on synthetic data with known answers: recovery of a known RBF
//! function, error-reduction ratio bookkeeping, the rho and max-count stops, joint
//! linear terms, determinism and rejection of bad input.

use crate::train_support;

use fog_core::model::format::RbfModel;
use fog_sim::train::{
    fit_width, predict_batch, rms, train_model, Dataset, Method, StopReason, TrainConfig,
    TrainError,
};
use train_support::{campaign, shupe_like, specs_t_rate};

const AMBIENTS: [f64; 4] = [-20.0, 0.0, 20.0, 40.0];

fn residual_rms(model: &RbfModel, ds: &Dataset) -> f64 {
    let pred = predict_batch(model, ds.rows()).unwrap();
    let r: Vec<f64> = ds
        .targets_dph
        .iter()
        .zip(&pred)
        .map(|(y, p)| y - p)
        .collect();
    rms(&r)
}

#[test]
fn ols_recovers_a_known_rbf_function_built_on_sample_centres() {
    // Truth: 4 Gaussians (sigma 0.5 in normalised units) centred on training samples.
    let base = campaign(&AMBIENTS, 2, 0.0, 1, |_, _| 0.0);
    let norm = fog_sim::train::Normalizer::fit(&base).unwrap();
    let centres: Vec<[f64; 2]> = [10, 700, 1500, 2100]
        .iter()
        .map(|&i| [norm.apply(0, base.row(i)[0]), norm.apply(1, base.row(i)[1])])
        .collect();
    let weights = [0.12, -0.05, 0.08, 0.03];
    let truth = |t: f64, r: f64| {
        let x = [norm.apply(0, t), norm.apply(1, r)];
        0.02 + centres
            .iter()
            .zip(weights)
            .map(|(c, w)| {
                w * (-((x[0] - c[0]).powi(2) + (x[1] - c[1]).powi(2)) / (2.0 * 0.25)).exp()
            })
            .sum::<f64>()
    };
    let ds = campaign(&AMBIENTS, 2, 0.0, 1, truth);
    let cfg = TrainConfig {
        rho: 1e-9,
        max_centers: 12,
        ..TrainConfig::default()
    };
    let fit = fit_width(&ds, &cfg, 0.5).unwrap();
    let y_rms = rms(&ds.targets_dph);
    let got = residual_rms(&fit.model, &ds);
    assert!(
        got < 2e-4 * y_rms.max(0.01),
        "residual rms {got} vs target rms {y_rms}"
    );
    // Greedy selection need not pick the exact true samples, but every true centre has a
    // selected centre within sigma/5 of it.
    for c in &centres {
        let nearest = fit
            .model
            .centers
            .iter()
            .map(|m| ((f64::from(m[0]) - c[0]).powi(2) + (f64::from(m[1]) - c[1]).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 0.1,
            "true centre {c:?}: nearest selected {nearest}"
        );
    }
}

#[test]
fn error_reduction_ratios_are_positive_and_add_up_to_the_explained_energy() {
    let ds = campaign(&AMBIENTS, 3, 0.01, 2, shupe_like);
    let cfg = TrainConfig {
        rho: 1e-6,
        max_centers: 30,
        ..TrainConfig::default()
    };
    let fit = fit_width(&ds, &cfg, 0.35).unwrap();
    let p = &fit.path;
    assert!(p.center_err.iter().all(|&e| e > 0.0 && e < 1.0));
    assert!(p.err_sum > 0.0 && p.err_sum <= 1.0);
    // 1 - sum(err) is the residual energy fraction of the fitted model (deployed f32 maths).
    let yy: f64 = ds.targets_dph.iter().map(|y| y * y).sum();
    let rss = residual_rms(&fit.model, &ds).powi(2) * ds.len() as f64;
    assert!(
        ((1.0 - p.err_sum) - rss / yy).abs() < 1e-3 * (1.0 - p.err_sum) + 1e-7,
        "{} vs {}",
        1.0 - p.err_sum,
        rss / yy
    );
    // The bias (a forced term) takes the rest: the centres' err sum is below the total.
    assert!(p.center_err.iter().sum::<f64>() < p.err_sum);
}

#[test]
fn selection_stops_at_rho_or_at_the_maximum_count() {
    let ds = campaign(&AMBIENTS, 3, 0.005, 3, shupe_like);
    let rho = 0.02;
    let fit = fit_width(
        &ds,
        &TrainConfig {
            rho,
            ..TrainConfig::default()
        },
        0.35,
    )
    .unwrap();
    let p = &fit.path;
    assert_eq!(p.stop, StopReason::Rho);
    assert!(1.0 - p.err_sum < rho);
    // One centre fewer would not have met the criterion: the stop is the first crossing.
    let last = *p.center_err.last().unwrap();
    assert!(1.0 - (p.err_sum - last) >= rho);

    let fit = fit_width(
        &ds,
        &TrainConfig {
            rho: 1e-9,
            max_centers: 5,
            ..TrainConfig::default()
        },
        0.35,
    )
    .unwrap();
    assert_eq!(fit.path.stop, StopReason::MaxCenters);
    assert_eq!(fit.model.centers.len(), 5);
}

#[test]
fn linear_only_input_is_fitted_jointly_with_the_rbf() {
    // Third input: a slow unrelated supply voltage; drift depends on it linearly.
    let base = campaign(&AMBIENTS, 3, 0.003, 4, shupe_like);
    let mut ds = Dataset::with_specs(
        vec![
            specs_t_rate()[0],
            specs_t_rate()[1],
            fog_core::model::format::FeatureSpec {
                kind: fog_core::model::format::FeatureKind::AuxValue(0),
                tau_s: 0.0,
            },
        ],
        vec![
            "temp_c:value".into(),
            "temp_c:rate".into(),
            "supply_v:value".into(),
        ],
    )
    .unwrap();
    let coef_dph_per_v = 0.04;
    for g in 0..base.n_groups() as u32 {
        let idx = base.indices_where(|x| x == g);
        let rows: Vec<Vec<f64>> = idx
            .iter()
            .map(|&i| {
                // Faster than the warm-up, so (T, dT/dt) cannot stand in for it.
                let v = 24.0 + 0.5 * (base.t_s[i] / 23.0 + f64::from(g)).sin();
                vec![base.row(i)[0], base.row(i)[1], v]
            })
            .collect();
        let y: Vec<f64> = idx
            .iter()
            .zip(&rows)
            .map(|(&i, r)| base.targets_dph[i] + coef_dph_per_v * (r[2] - 24.0))
            .collect();
        let t: Vec<f64> = idx.iter().map(|&i| base.t_s[i]).collect();
        ds.push_group(&base.group_names[g as usize], &rows, &y, &t)
            .unwrap();
    }
    let cfg = TrainConfig {
        linear_only_inputs: 1,
        max_centers: 30,
        ..TrainConfig::default()
    };
    let fit = fit_width(&ds, &cfg, 0.35).unwrap();
    assert_eq!(fit.model.n_rbf_inputs, 2);
    // linear[2] is per normalised unit: coefficient * scale.
    let got = f64::from(fit.model.linear[2]) / f64::from(fit.model.input_scale[2]);
    assert!(
        (got - coef_dph_per_v).abs() < 0.05 * coef_dph_per_v,
        "fitted {got} dph/V"
    );
    assert!(fit.model.centers.iter().all(|c| c[2] == 0.0));
    // With the linear term the fit is as good as on the same data without the effect
    // (whose rms, 0.014 dph, would otherwise remain).
    let res = residual_rms(&fit.model, &ds);
    let cfg_base = TrainConfig {
        max_centers: 30,
        ..TrainConfig::default()
    };
    let res_base = residual_rms(&fit_width(&base, &cfg_base, 0.35).unwrap().model, &base);
    assert!(
        res < 1.1 * res_base,
        "residual rms {res} vs {res_base} without the effect"
    );
}

#[test]
fn same_data_gives_the_same_model_bytes_whatever_the_thread_count() {
    let ds = campaign(&AMBIENTS, 3, 0.01, 5, shupe_like);
    let encode = |threads| {
        let cfg = TrainConfig {
            threads: Some(threads),
            width_candidates: vec![0.35, 1.0],
            ..TrainConfig::default()
        };
        let out = train_model(&ds, &cfg).unwrap();
        let mut buf = [0u8; fog_core::model::format::MAX_ENCODED_LEN];
        let n = out.model.encode(&mut buf).unwrap();
        buf[..n].to_vec()
    };
    assert_eq!(encode(1), encode(2));
}

#[test]
fn bad_input_is_rejected_with_a_clear_error() {
    let mut ds = Dataset::with_specs(specs_t_rate(), vec!["a".into(), "b".into()]).unwrap();
    let err = ds
        .push_group("run1", &[vec![1.0, f64::NAN]], &[0.0], &[10.0])
        .unwrap_err();
    assert_eq!(
        err,
        TrainError::NonFinite {
            what: "model input",
            row: 0,
            input: 1
        }
    );
    assert!(ds.is_empty(), "a bad group is rejected whole");
    let err = ds
        .push_group("run1", &[vec![1.0]], &[0.0], &[10.0])
        .unwrap_err();
    assert!(matches!(
        err,
        TrainError::InputCount {
            expected: 2,
            found: 1,
            ..
        }
    ));

    let ds = campaign(&AMBIENTS[..1], 2, 0.01, 6, shupe_like);
    let err = train_model(&ds, &TrainConfig::default()).unwrap_err();
    assert_eq!(
        err,
        TrainError::TooFewGroups {
            found: 2,
            needed: 3
        }
    );
    assert!(err.to_string().contains("at least 3 runs"));

    for (cfg, option) in [
        (
            TrainConfig {
                rho: 1.5,
                ..TrainConfig::default()
            },
            "rho",
        ),
        (
            TrainConfig {
                max_centers: 65,
                ..TrainConfig::default()
            },
            "max-centers",
        ),
        (
            TrainConfig {
                width_candidates: vec![0.0],
                ..TrainConfig::default()
            },
            "widths",
        ),
        (
            TrainConfig {
                linear_only_inputs: 2,
                ..TrainConfig::default()
            },
            "linear-inputs",
        ),
    ] {
        match fit_width(&ds, &cfg, 0.5).unwrap_err() {
            TrainError::BadConfig { option: o, .. } => assert_eq!(o, option),
            e => panic!("expected a config error for {option}, got {e}"),
        }
    }
    let flat = campaign(&[20.0], 3, 0.0, 7, |_, _| 0.0);
    let mut rows_const = Dataset::with_specs(specs_t_rate(), vec!["a".into(), "b".into()]).unwrap();
    rows_const
        .push_group(
            "r",
            &vec![vec![1.0, 2.0]; 10],
            &[0.0; 10],
            &(0..10).map(f64::from).collect::<Vec<_>>(),
        )
        .unwrap();
    assert_eq!(
        fit_width(&rows_const, &TrainConfig::default(), 0.5).unwrap_err(),
        TrainError::ConstantInput { input: 0 }
    );
    assert!(fit_width(
        &flat,
        &TrainConfig {
            method: Method::Ols,
            ..TrainConfig::default()
        },
        0.5
    )
    .is_ok());
}
