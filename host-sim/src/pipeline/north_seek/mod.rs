//! Cold-start north-seek Monte Carlo: the paper's north-finder experiment, repeated.
//!
//! Each start powers a simulated gyro on cold (soaked at the ambient), mounted with its input
//! axis horizontal on the simulated indexing turntable, and runs `seeks_per_start` seeks back
//! to back with fog-core's `NorthFinder` fed by fog-core's `Compensator` -- the device's
//! code path, while the gyro keeps warming up and the table turns. Every start is run twice
//! with the same seed (same gyro, same noise, same table errors): once without a model
//! (uncompensated) and once with the drift model (compensated), so the two arms differ only
//! by the compensation. Starts are spread over threads by `crate::fanout`; each has
//! its own seed derived from the campaign seed and its index, so the result does not depend
//! on the thread count or scheduling.
//!
//! With `tilt_deg` > 0 the table stands on a base tilted by that much (towards a direction
//! drawn per start) and the finder gets the inclinometer's 10 s means; a third arm runs the
//! same seeds with the model but without the tilt (`tilt_uncompensated`). With
//! `heading_bias_dph` != 0 the gyro has a bias A cos(alpha) of its input axis azimuth; the
//! heading harmonic is first calibrated over 8 headings on a warm, level gyro at the known
//! azimuth (`fog_core::seeking::heading_cal`), applied in the compensated arm, and a fourth arm runs
//! without it (`heading_uncalibrated`).
//!
//! Files: `config` (what is asked), `seeks` (one power-on's seeks), `monte_carlo` (the
//! starts over threads, the bench heading calibration), `summary` (statistics, report,
//! tables); `own_model` (the device's own chamber model), `schedule` (when each seek
//! runs), `targets` (the targets line), `unit_recipe` (a unit's model from a type and a few
//! of its own runs), `recipe_compare` (the demo's recipes side by side).

mod config;
mod monte_carlo;
pub mod own_model;
pub mod recipe_compare;
pub mod schedule;
mod seeks;
mod summary;
pub mod targets;
pub mod unit_recipe;

pub use config::*;
pub use monte_carlo::*;
pub use seeks::*;
pub use summary::*;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::GyroParams;
    use fog_core::model::format::RbfModel;
    use fog_core::seeking::northfinder::SeekMode;
    use fog_core::seeking::quality::QualityError;

    #[test]
    fn azimuth_error_wraps() {
        assert!((azimuth_error_deg(359.9, 0.1) + 0.2).abs() < 1e-9);
        assert!((azimuth_error_deg(0.1, 359.9) - 0.2).abs() < 1e-9);
        assert!((azimuth_error_deg(108.5, 108.4) - 0.1).abs() < 1e-9);
    }

    #[test]
    fn noise_floor_matches_the_formula() {
        // 0.0011 deg/sqrt(h), 120 s dwell, equator, psi = 90 deg:
        // N / (sqrt(2 tau) Omega) = 0.0011 / (sqrt(2/30) * 15.041067) rad.
        let f = noise_floor_deg(0.0011, SeekMode::TwoPosition, 0.0, 90.0, 120.0);
        let expect = (0.0011 / ((2.0f64 / 30.0).sqrt() * 15.041067)).to_degrees();
        assert!((f - expect).abs() < 1e-12, "{f} vs {expect}");
        // Four positions (4 tau in total) do not depend on psi and equal two positions at psi = 90 deg.
        let f4 = noise_floor_deg(0.0011, SeekMode::FourPosition, 0.0, 10.0, 120.0);
        assert!((f4 - f).abs() < 1e-12);
        // A symmetric sequence: its forward mode's floor at the time over both visits.
        for (fwd, sym) in [
            (SeekMode::TwoPosition, SeekMode::TwoPositionSymmetric),
            (SeekMode::FourPosition, SeekMode::FourPositionSymmetric),
        ] {
            let a = noise_floor_deg(0.0011, fwd, 0.0, 60.0, 100.0);
            assert_eq!(a, noise_floor_deg(0.0011, sym, 0.0, 60.0, 100.0));
        }
    }

    #[test]
    fn the_symmetric_sequence_removes_most_of_the_uncompensated_first_seek_error() {
        // One cold start, no model, seek 1 at 20 degC (same seed, same total time): the
        // forward seek errs by the warm-up drift's change between its dwells, -0.085 deg
        // on average over 1,000 starts (std 0.015); the symmetric one by its curvature only,
        // +0.011 deg (docs/record/northfinder.md, "Time-symmetric seek").
        let err = |mode: SeekMode| {
            let cfg = MonteCarloConfig {
                seeks_per_start: 1,
                mode,
                dwell_s: default_dwell_s(mode),
                ..MonteCarloConfig::paper(1)
            };
            let arm = Arm {
                model: None,
                feed_tilt: false,
                heading: None,
            };
            let out =
                run_seeks(&GyroParams::paper_default(), &cfg, arm, cfg.start_seed(0)).unwrap();
            azimuth_error_deg(out.seeks[0].azimuth_deg, cfg.true_azimuth_deg)
        };
        let (forward, symmetric) = (
            err(SeekMode::TwoPosition),
            err(SeekMode::TwoPositionSymmetric),
        );
        assert!(forward < -0.05, "{forward}");
        assert!(symmetric.abs() < 0.04, "{symmetric}");
    }

    #[test]
    fn tilt_input_removes_the_tilt_error_and_runs_repeat() {
        let cfg = MonteCarloConfig {
            seeks_per_start: 1,
            tilt_deg: 15.0,
            ..MonteCarloConfig::paper(3)
        };
        let params = GyroParams::paper_default();
        let arm = |feed_tilt| Arm {
            model: None,
            feed_tilt,
            heading: None,
        };
        let err = |o: &ArmOutcome| azimuth_error_deg(o.seeks[0].azimuth_deg, cfg.true_azimuth_deg);
        let fed = run_seeks(&params, &cfg, arm(true), 11).unwrap();
        let level = run_seeks(&params, &cfg, arm(false), 11).unwrap();
        // Uncompensated warm-up drift alone is ~0.1 deg on the first seek; 15 deg of tilt
        // without the tilt maths is degrees.
        assert!(err(&fed).abs() < 0.2, "{}", err(&fed));
        assert!(err(&level).abs() > 1.0, "{}", err(&level));
        assert_eq!(fed, run_seeks(&params, &cfg, arm(true), 11).unwrap());
    }

    #[test]
    fn heading_calibration_finds_the_simulated_harmonic() {
        let cfg = MonteCarloConfig {
            heading_bias_dph: 0.05,
            ..MonteCarloConfig::paper(5)
        };
        let h = calibrate_heading(&cfg.gyro_params(&GyroParams::paper_default()), &cfg).unwrap();
        let a = h.amplitude_dph() as f64;
        assert!(
            (a - 0.05).abs() < 4.0 * h.amplitude_sigma_dph() as f64 + 1e-3,
            "{h:?}"
        );
        assert!(
            (h.phase_deg() as f64).abs() < 4.0 * h.phase_sigma_deg() as f64 + 1.0,
            "{h:?}"
        );
    }

    /// The default model of `north-seek --ambient 20 --seed 1` (3 runs at 20 degC).
    fn model_at_20c() -> RbfModel {
        use crate::pipeline::campaign_steps::{simulate_checked, train_default, CampaignSpec};
        let plan = CampaignSpec {
            ambients_c: vec![20.0],
            runs_per_ambient: 3,
            ..CampaignSpec::paper(1)
        };
        let campaign = simulate_checked(&GyroParams::paper_default(), &plan).unwrap();
        let runs: Vec<_> = campaign.iter().map(|c| &c.run).collect();
        train_default(&runs, &crate::train::default_specs(), "sim")
            .unwrap()
            .model
    }

    /// One seek after a cold start at `ambient_c` with `model_at_20c`, tilt fed.
    fn one_seek_with_the_20c_model(
        ambient_c: f64,
        seed: impl Fn(&MonteCarloConfig) -> u64,
    ) -> ArmOutcome {
        let cfg = MonteCarloConfig {
            seeks_per_start: 1,
            ambient_c,
            ..MonteCarloConfig::paper(1)
        };
        let model = model_at_20c();
        let arm = Arm {
            model: Some(&model),
            feed_tilt: true,
            heading: None,
        };
        run_seeks(&GyroParams::paper_default(), &cfg, arm, seed(&cfg)).unwrap()
    }

    #[test]
    fn a_cold_start_warming_faster_than_the_training_runs_is_not_refused() {
        // Start 64 of `north-seek --starts 200`: its warm-up peaks at dT/dt = 0.0129 degC/s,
        // above the 3 training runs' envelope (+5 %), which flagged 4 windows of its first
        // position and refused the seek. The declared range (run-to-run spread of the
        // training runs' extremes) covers it.
        let out = one_seek_with_the_20c_model(20.0, |cfg| {
            let seed = cfg.start_seed(63);
            assert_eq!(seed, 9_851_787_880_037_274_203);
            seed
        });
        assert_eq!(out.refusals, Vec::new());
        assert_eq!(out.seeks.len(), 1);
    }

    #[test]
    fn a_model_from_another_ambient_is_refused_recorded_and_retried_not_aborted() {
        // Twin: the same 20 degC model at -40 degC, where T is 60 degC outside anything
        // trained: every attempt is refused with the finder's reason, the seek is given up
        // after MAX_ATTEMPTS_PER_SEEK attempts, and the Monte Carlo goes on.
        let out = one_seek_with_the_20c_model(-40.0, |_| 5);
        assert_eq!(out.seeks.len(), 0);
        assert_eq!(out.failed_seeks, 1);
        assert_eq!(out.refusals.len(), MAX_ATTEMPTS_PER_SEEK);
        assert!(out.refusals.iter().all(|r| r.index == 0
            && matches!(
                r.reason,
                QualityError::Finder(
                    fog_core::seeking::quality::FinderFault::TooManyInvalidWindows { position: 0 }
                )
            )));
        let st = seek_stats(&[out], PAPER_AZIMUTH_DEG);
        assert_eq!(st.reliability.refusal_rate, 1.0);
        assert_eq!(
            st.reliability
                .refusal_reasons
                .get("Finder(TooManyInvalidWindows)"),
            Some(&MAX_ATTEMPTS_PER_SEEK)
        );
    }

    #[test]
    fn start_seeds_differ_and_repeat() {
        let cfg = MonteCarloConfig::paper(7);
        let seeds: Vec<u64> = (0..100).map(|i| cfg.start_seed(i)).collect();
        let mut sorted = seeds.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 100);
        assert_eq!(seeds[5], MonteCarloConfig::paper(7).start_seed(5));
        assert_ne!(seeds[5], MonteCarloConfig::paper(8).start_seed(5));
    }

    #[test]
    fn stats_of_known_seeks() {
        let s = |index: usize, a: f64| SeekOutcome {
            index,
            restarts: 0,
            latitude_valid: true,
            azimuth_deg: a,
            sigma_deg: 0.01,
            t_start_s: 0.0,
            duration_s: 290.0,
            main_dwell_s: 120.0,
            field_record: None,
            position_spans_s: NO_SPANS,
        };
        let arm = |seeks: Vec<SeekOutcome>| ArmOutcome {
            seeks,
            ..ArmOutcome::default()
        };
        let seeks = vec![
            arm(vec![s(0, 108.5), s(1, 108.4)]),
            arm(vec![s(0, 108.3), s(1, 108.4)]),
        ];
        let st = seek_stats(&seeks, 108.4);
        assert!((st.mean_error_deg).abs() < 1e-9);
        assert!((st.max_dev_deg - 0.1).abs() < 1e-9);
        // Seek 1 errs +0.1 and -0.1: rms 0.1 about the truth, 1 sigma (n - 1) sqrt(2) x 0.1.
        assert!((st.per_seek_rms_error_deg[0] - 0.1).abs() < 1e-9);
        assert!((st.per_seek_std_deg[0] - 0.1 * 2f64.sqrt()).abs() < 1e-9);
        assert!(st.per_seek_rms_error_deg[1].abs() < 1e-9);
        assert!(st.per_seek_std_deg[1].abs() < 1e-9);
        assert!((st.mean_range_deg - 0.1).abs() < 1e-9);
    }
}
