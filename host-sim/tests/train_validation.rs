//! Model selection: the Gaussian width is chosen by grouped (whole runs held out)
//! validation rather than training error, and Orr's regularised GCV-stopped selection
//! is compared with plain OLS on held-out runs.

use crate::train_support;

use fog_sim::train::{cross_validate, fold_of_rows, Method, TrainConfig, WidthSearch};
use train_support::{campaign, shupe_like};

const AMBIENTS: [f64; 5] = [-30.0, -10.0, 10.0, 30.0, 50.0];

#[test]
fn folds_hold_out_whole_runs_one_per_ambient() {
    let ds = campaign(&AMBIENTS, 3, 0.01, 11, shupe_like);
    let fold = fold_of_rows(&ds, 3).unwrap();
    for g in 0..ds.n_groups() as u32 {
        let folds: Vec<usize> = ds
            .indices_where(|x| x == g)
            .iter()
            .map(|&i| fold[i])
            .collect();
        assert!(
            folds.windows(2).all(|w| w[0] == w[1]),
            "run {g} split across folds"
        );
        // Runs are ambient-major: run r of every ambient lands in fold r.
        assert_eq!(folds[0], g as usize % 3);
    }
}

#[test]
fn width_is_chosen_by_held_out_error_and_matches_the_true_scale() {
    // Truth: bumps of sigma 0.2 (normalised units) on the data's own points, plus noise.
    let base = campaign(&AMBIENTS, 3, 0.0, 12, |_, _| 0.0);
    let norm = fog_sim::train::Normalizer::fit(&base).unwrap();
    let bumps: Vec<(f64, f64, f64)> = (0..12)
        .map(|k| {
            let r = base.row(k * 331 % base.len());
            (
                norm.apply(0, r[0]),
                norm.apply(1, r[1]),
                if k % 2 == 0 { 0.05 } else { -0.04 },
            )
        })
        .collect();
    let truth = |t: f64, r: f64| {
        let (x, y) = (norm.apply(0, t), norm.apply(1, r));
        bumps
            .iter()
            .map(|(cx, cy, w)| w * (-((x - cx).powi(2) + (y - cy).powi(2)) / (2.0 * 0.04)).exp())
            .sum()
    };
    let ds = campaign(&AMBIENTS, 3, 0.01, 12, truth);
    let cfg = TrainConfig {
        width_candidates: vec![0.03, 0.2, 2.0],
        ..TrainConfig::default()
    };
    let cv = cross_validate(&ds, &cfg, 3).unwrap();
    for s in &cv.scan {
        eprintln!(
            "width {:.2}: held-out {:.5} dph, {:.1} centres",
            s.width, s.heldout_rms_dph, s.mean_centers
        );
    }
    assert_eq!(cv.best.width, 0.2);
    for s in cv.scan.iter().filter(|s| s.width != 0.2) {
        assert!(
            s.heldout_rms_dph > 1.05 * cv.best.heldout_rms_dph,
            "width {} not clearly worse",
            s.width
        );
    }
}

#[test]
fn orr_gcv_and_validated_ols_both_stop_well_below_the_maximum() {
    let ds = campaign(&AMBIENTS, 3, 0.02, 13, shupe_like);
    let base = TrainConfig {
        width_candidates: vec![0.35],
        rho: 1e-6,
        ..TrainConfig::default()
    };
    let ols = cross_validate(&ds, &base, 3).unwrap();
    let orr = cross_validate(
        &ds,
        &TrainConfig {
            method: Method::OrrGcv,
            ..base.clone()
        },
        3,
    )
    .unwrap();
    eprintln!(
        "OLS: {:.5} dph held-out, {:.1} centres; Orr: {:.5} dph, {:.1} centres",
        ols.best.heldout_rms_dph,
        ols.best.mean_centers,
        orr.best.heldout_rms_dph,
        orr.best.mean_centers
    );
    // A tiny rho no longer drives OLS to 64 centres: grouped validation picks the size.
    assert!(ols.best.mean_centers < 0.75 * 64.0);
    assert!(orr.best.mean_centers < 0.75 * 64.0);
    assert!(orr.best.heldout_rms_dph < 1.05 * ols.best.heldout_rms_dph);
    assert!(ols.best.heldout_rms_dph < 1.05 * orr.best.heldout_rms_dph);
}

/// A second drift law for the width search: a static bias quadratic in T and a Shupe
/// coefficient that itself changes with T (a narrower structure than `shupe_like`).
fn quadratic_bias_and_t_dependent_shupe(temp_c: f64, rate_cps: f64) -> f64 {
    let x = (temp_c - 15.0) / 30.0;
    0.2 * x * x - 0.05 * x + 20.0 * rate_cps * (1.0 + 0.8 * (-(x * 3.0).powi(2)).exp())
}

#[test]
fn the_width_climb_finds_the_full_searchs_best_scoring_fewer_widths() {
    type DriftLaw = fn(f64, f64) -> f64;
    let laws: [(&str, DriftLaw); 2] = [
        ("shupe_like", shupe_like),
        (
            "quadratic bias, T-dependent Shupe",
            quadratic_bias_and_t_dependent_shupe,
        ),
    ];
    for (name, law) in laws {
        let ds = campaign(&AMBIENTS, 3, 0.02, 17, law);
        let full = cross_validate(
            &ds,
            &TrainConfig {
                width_search: WidthSearch::Full,
                ..TrainConfig::default()
            },
            3,
        )
        .unwrap();
        let climb = cross_validate(&ds, &TrainConfig::default(), 3).unwrap();
        let widths = |cv: &fog_sim::train::CvReport| {
            let mut w: Vec<f64> = cv.scan.iter().map(|s| s.width).collect();
            w.dedup();
            w
        };
        eprintln!(
            "{name}: full scored {:?} -> {} (deg {}), climb scored {:?} -> {} (deg {})",
            widths(&full),
            full.best.width,
            full.best.degree,
            widths(&climb),
            climb.best.width,
            climb.best.degree
        );
        assert_eq!(
            climb.best, full.best,
            "{name}: the climb missed the best shape"
        );
        assert!(
            widths(&climb).len() < widths(&full).len(),
            "{name}: the climb scored as many widths as the full search"
        );
    }
}

#[test]
fn a_seek_criterion_whose_seek_fits_in_no_run_is_refused_not_scored_as_zero() {
    use fog_sim::train::seek_score::{Criterion, SeekGeometry};
    use fog_sim::train::TrainError;
    let ds = campaign(&AMBIENTS, 3, 0.01, 13, shupe_like);
    let run_s = ds.t_s[ds.indices_where(|g| g == 0).last().copied().unwrap()] - ds.t_s[0];
    let seek = |dwell_s: f64| TrainConfig {
        criterion: Criterion::Seek(SeekGeometry::forward(dwell_s, 34.0)),
        ..TrainConfig::default()
    };
    // Two positions of a third of the run each fit; two of the whole run do not.
    assert!(cross_validate(&ds, &seek(run_s / 3.0), 3).is_ok());
    match cross_validate(&ds, &seek(run_s), 3) {
        Err(TrainError::NoSeekPairs {
            dwell_s,
            longest_run_s,
        }) => {
            assert_eq!(dwell_s, run_s);
            assert!(
                (longest_run_s - run_s).abs() < 1e-9,
                "{longest_run_s} vs {run_s}"
            );
        }
        other => panic!("expected NoSeekPairs, got {:?}", other.map(|r| r.best)),
    }
    // The 10 s rms does not need seeks.
    let rms = TrainConfig {
        criterion: Criterion::Rms10s,
        ..TrainConfig::default()
    };
    assert!(cross_validate(&ds, &rms, 3).is_ok());
}
