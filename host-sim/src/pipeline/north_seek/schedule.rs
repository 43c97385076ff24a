//! The device's seek timing, measured rather than re-derived: one cold start of
//! `run_seeks` (fog-core's `NorthFinder` under its `SeekSupervisor`, the simulated
//! turntable's moves and settling, the 10 s windows each position accepts), read back as
//! the spans of each seek's opposite positions. The trainer's seek refit fits the model
//! error over exactly these windows (`train::seek_refit`), so a change of dwell, table
//! speed or sequence reaches it without a constant to update.
//!
//! It is measured with the model the seeks will use: the compensator marks a window whose
//! model inputs are still warming up as not valid and the finder dwells on until it has
//! its 110 s of valid windows; with the flat-start d2T/dt2 input seek 1 starts 10 s later
//! and every seek takes 277 s instead of 267 s. Measured without the model, the refit of
//! such a model (seed 1's qualification model) was fitted to windows 10 s off in seek 1 and
//! 100 s off by seek 10, and put a -0.012 deg bias into seek 1 at -40 and +60 degC
//! (docs/record/northfinder.md, "The seek refit").

use anyhow::{bail, Result};
use fog_core::model::format::RbfModel;
use fog_core::seeking::northfinder::SeekMode;

use super::config::MonteCarloConfig;
use super::seeks::{run_seeks, Arm, PositionSpans};
use crate::sim::GyroParams;
use crate::train::seek_refit::{OppositePair, SeekSchedule};

/// Opposite positions of a mode, by step of its sequence (`SeekMode::steps`): 2 positions
/// (0, 180 deg; the +90 dwell only resolves the sign), 4 positions (0 and 180, 90 and 270
/// deg). A symmetric sequence's difference is the mean of its visits' differences, one
/// pair per visit in time order (0/180 out and back; the doubled 270 deg dwell pairs with
/// both 90 deg visits).
fn opposite_positions(mode: SeekMode) -> &'static [(usize, usize)] {
    match mode {
        SeekMode::TwoPosition => &[(0, 1)],
        SeekMode::FourPosition => &[(0, 2), (1, 3)],
        SeekMode::TwoPositionSymmetric => &[(0, 1), (3, 4)],
        SeekMode::FourPositionSymmetric => &[(0, 2), (1, 3), (3, 5), (4, 6)],
        SeekMode::TwoPositionThueMorse => &[(0, 1), (2, 1), (5, 4), (5, 6)],
    }
}

/// The seek schedule of `cfg`'s seeks compensated by `model`: its first start's seeks,
/// level.
pub fn seek_schedule(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    model: Option<&RbfModel>,
) -> Result<SeekSchedule> {
    let level = MonteCarloConfig {
        tilt_deg: 0.0,
        heading_bias_dph: 0.0,
        ..cfg.clone()
    };
    let arm = Arm {
        model,
        feed_tilt: false,
        heading: None,
    };
    let out = run_seeks(params, &level, arm, level.start_seed(0))?;
    let pairs_of = |s: &PositionSpans| -> Option<Vec<OppositePair>> {
        opposite_positions(cfg.mode)
            .iter()
            .map(|&(a, b)| {
                Some(OppositePair {
                    first_s: s[a]?,
                    second_s: s[b]?,
                })
            })
            .collect()
    };
    let seeks: Vec<Vec<OppositePair>> = out
        .seeks
        .iter()
        .map(|s| pairs_of(&s.position_spans_s))
        .collect::<Option<_>>()
        .ok_or_else(|| {
            anyhow::anyhow!("seek schedule: a finished seek has a main position without windows")
        })?;
    let starts: Vec<f64> = out.seeks.iter().map(|s| s.t_start_s).collect();
    let period_s = match starts.as_slice() {
        [first, .., last] => (last - first) / (starts.len() - 1) as f64,
        [_] => out.seeks[0].duration_s.max(1.0),
        [] => bail!("seek schedule: the seek sequence finished no seek"),
    };
    let schedule = SeekSchedule { seeks, period_s };
    schedule
        .check()
        .map_err(|e| anyhow::anyhow!("seek schedule: {e}"))?;
    Ok(schedule)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::model::format::{FeatureKind, FeatureSpec};

    /// A model of T, dT/dt and the flat-start d2T/dt2 that predicts no drift (wide
    /// trained ranges).
    fn rate_model() -> RbfModel {
        let mut m = RbfModel::empty();
        m.n_rbf_inputs = 0;
        for (k, scale, lo, hi) in [
            (FeatureKind::TempC, 10.0f32, -100.0f32, 150.0f32),
            (FeatureKind::TempRateCps, 0.01, -1.0, 1.0),
            (FeatureKind::TempAccelFlatStartCps2, 0.001, -1.0, 1.0),
        ] {
            m.inputs.push(FeatureSpec::plain(k)).unwrap();
            m.input_offset.push(0.0).unwrap();
            m.input_scale.push(scale).unwrap();
            m.input_min.push(lo).unwrap();
            m.input_max.push(hi).unwrap();
            m.linear.push(0.0).unwrap();
        }
        m
    }

    #[test]
    fn a_model_whose_d2t_dt2_warms_up_delays_seek_1_and_lengthens_every_seek() {
        let params = GyroParams::paper_default();
        let cfg = MonteCarloConfig {
            seeks_per_start: 2,
            ..MonteCarloConfig::paper(1)
        };
        let plain = seek_schedule(&params, &cfg, None).unwrap();
        let rated = seek_schedule(&params, &cfg, Some(&rate_model())).unwrap();
        let first = |s: &SeekSchedule, k: usize| s.seeks[k][0].first_s.0;
        // Measured: the first window 10 s later and each seek 10 s longer (one window
        // more per seek the finder does not take; the cause is not traced here).
        assert!(
            first(&rated, 0) >= first(&plain, 0) + 10.0,
            "{plain:?} {rated:?}"
        );
        assert!(
            first(&rated, 1) >= first(&plain, 1) + 10.0,
            "{plain:?} {rated:?}"
        );
        assert!(rated.period_s > plain.period_s + 5.0, "{plain:?} {rated:?}");
        for p in rated.seeks.iter().flatten() {
            assert!((p.first_s.1 - p.first_s.0 - 110.0).abs() < 1e-6, "{p:?}");
        }
    }

    #[test]
    fn the_symmetric_seek_pairs_each_visit_and_centres_both_positions_on_one_time() {
        let params = GyroParams::paper_default();
        let mode = SeekMode::TwoPositionSymmetric;
        let cfg = MonteCarloConfig {
            seeks_per_start: 2,
            mode,
            dwell_s: super::super::default_dwell_s(mode),
            ..MonteCarloConfig::paper(1)
        };
        let s = seek_schedule(&params, &cfg, None).unwrap();
        let mid = |(a, b): (f64, f64)| 0.5 * (a + b);
        for seek in &s.seeks {
            let [out, back] = seek.as_slice() else {
                panic!("{seek:?}")
            };
            for p in [out, back] {
                assert!((p.first_s.1 - p.first_s.0 - 50.0).abs() < 1e-6, "{p:?}");
                assert!((p.second_s.1 - p.second_s.0 - 50.0).abs() < 1e-6, "{p:?}");
                assert!(p.second_s.0 > p.first_s.1, "{p:?}");
            }
            // 0 deg is out.first and back.second, 180 deg out.second and back.first: the
            // same mean time, so a drift linear in time cancels in their difference.
            let t0 = 0.5 * (mid(out.first_s) + mid(back.second_s));
            let t180 = 0.5 * (mid(out.second_s) + mid(back.first_s));
            assert!((t0 - t180).abs() < 1e-6, "{t0} {t180}");
        }
    }

    #[test]
    fn the_paper_seek_dwells_110_s_at_each_main_position_and_repeats_every_seek() {
        let params = GyroParams::paper_default();
        let cfg = MonteCarloConfig {
            seeks_per_start: 3,
            ..MonteCarloConfig::paper(1)
        };
        let s = seek_schedule(&params, &cfg, None).unwrap();
        assert_eq!(s.seeks.len(), 3);
        for (k, seek) in s.seeks.iter().enumerate() {
            assert_eq!(seek.len(), 1);
            let p = seek[0];
            // 11 windows of 10 s at each main position, the second after the first.
            assert!((p.first_s.1 - p.first_s.0 - 110.0).abs() < 1e-6, "{p:?}");
            assert!((p.second_s.1 - p.second_s.0 - 110.0).abs() < 1e-6, "{p:?}");
            assert!(p.second_s.0 > p.first_s.1, "{p:?}");
            if k > 0 {
                let shift = p.first_s.0 - s.seeks[k - 1][0].first_s.0;
                assert!(
                    (shift - s.period_s).abs() < 10.0 + 1e-6,
                    "{shift} {}",
                    s.period_s
                );
            }
        }
    }
}
