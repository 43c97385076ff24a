//! The cold-start envelope a trained model carries (fog-core `model::cold_start`): the
//! least temperature rise since power-on its training cold starts showed, at a few times
//! within their warm-up, so the device can tell a warm restart from them.
//!
//! From the runs alone: each run's rise at every 10 s row time is its row temperature
//! minus its first row's (as the device's `ColdStartMonitor` measures it). The envelope
//! spans from `FIRST_POINT_S` to the time the runs' mean rise reaches `SPAN_FRACTION` of
//! its rise at their last common row (the warm-up; past it a restart has warmed as far as a
//! cold start would), with `MAX_COLD_START_POINTS` points spaced evenly in log time (the
//! warm-up is close to exponential). The bound at a point is the runs' mean rise there less
//! `BOUND_SD` of their standard deviations: a new cold start of the training population
//! falls below it at one window with a probability of about 3e-7 (Gaussian), and the
//! device checks about a hundred windows in the span. Runs that show no warm-up give no
//! envelope, as they give no warm-up clock (`own_model::warmup_time_constant_s`).

use anyhow::{anyhow, Result};
use fog_core::model::cold_start::{ColdStartEnvelope, MAX_COLD_START_POINTS};
use fog_core::model::format::{FeatureKind, FeatureSpec};
use std::collections::BTreeMap;

use crate::io::runs::Run;
use crate::stats::{mean, std_dev};
use crate::train::data::features::dataset_from_runs;

/// First point of the envelope, s since power-on (the third 10 s window).
pub const FIRST_POINT_S: f64 = 30.0;
/// The span ends where the mean rise reaches this fraction of the runs' whole rise.
pub const SPAN_FRACTION: f64 = 0.95;
/// Standard deviations of the runs' rises below their mean that a point's bound lies.
pub const BOUND_SD: f64 = 5.0;
/// Standard errors of the runs' own rises the whole rise must reach for a warm-up.
pub const WARMUP_SIGNIFICANCE_SE: f64 = 3.0;

/// The runs' rises since their first row at each row time every run has: (t_s, rises),
/// in time order.
pub fn rises_by_time(runs: &[Run]) -> Result<Vec<(f64, Vec<f64>)>> {
    let ds = dataset_from_runs(runs, &[FeatureSpec::plain(FeatureKind::TempC)])
        .map_err(|e| anyhow!("warm-up: {e}"))?;
    let groups = ds.n_groups();
    let mut first = vec![f64::NAN; groups];
    let mut by_t: BTreeMap<u64, (f64, Vec<f64>)> = BTreeMap::new();
    for (i, row) in ds.rows().enumerate() {
        let g = ds.groups[i] as usize;
        if first[g].is_nan() {
            first[g] = row[0];
        }
        let e = by_t
            .entry(ds.t_s[i].to_bits())
            .or_insert((ds.t_s[i], Vec::new()));
        e.1.push(row[0] - first[g]);
    }
    // t_s >= 0, so the bit order is the time order.
    Ok(by_t
        .into_values()
        .filter(|(_, r)| r.len() == groups)
        .collect())
}

/// The runs' whole rise (mean rise at their last common row) when it is
/// `WARMUP_SIGNIFICANCE_SE` standard errors above zero; None: no warm-up.
pub fn significant_rise_c(rises: &[(f64, Vec<f64>)]) -> Option<f64> {
    let (_, last) = rises.last()?;
    let n = last.len() as f64;
    let total = mean(last);
    (n >= 2.0 && total > WARMUP_SIGNIFICANCE_SE * std_dev(last) / n.sqrt()).then_some(total)
}

/// The envelope for a model with inputs `specs` trained on `runs`: only when an input
/// takes the power-on to be a cold start (`FeatureKind::assumes_cold_start`); a model on
/// state inputs alone (T, dT/dt, d2T/dt2) is as valid after a restart as its inputs are
/// in range, and gets none.
pub fn envelope_for(runs: &[Run], specs: &[FeatureSpec]) -> Result<Option<ColdStartEnvelope>> {
    if specs.iter().any(|s| s.kind.assumes_cold_start()) {
        cold_start_envelope(runs)
    } else {
        Ok(None)
    }
}

/// The envelope of `runs` (None: no warm-up, or a warm-up shorter than the first point).
pub fn cold_start_envelope(runs: &[Run]) -> Result<Option<ColdStartEnvelope>> {
    let rises = rises_by_time(runs)?;
    let Some(total) = significant_rise_c(&rises) else {
        return Ok(None);
    };
    let Some(&(end_s, _)) = rises.iter().find(|(_, r)| mean(r) >= SPAN_FRACTION * total) else {
        return Ok(None);
    };
    if end_s <= FIRST_POINT_S {
        return Ok(None);
    }
    let mut envelope = ColdStartEnvelope {
        t_s: heapless::Vec::new(),
        min_rise_c: heapless::Vec::new(),
    };
    let ratio = (end_s / FIRST_POINT_S).powf(1.0 / (MAX_COLD_START_POINTS - 1) as f64);
    for k in 0..MAX_COLD_START_POINTS {
        let wanted_s = FIRST_POINT_S * ratio.powi(k as i32);
        // The first row at or after the wanted time (the last point is `end_s` itself).
        let Some((t_s, r)) = rises.iter().find(|(t, _)| *t >= wanted_s - 1e-6) else {
            break;
        };
        if envelope.t_s.last().is_some_and(|&last| *t_s as f32 <= last) {
            continue;
        }
        let bound = mean(r) - BOUND_SD * std_dev(r);
        let pushed = envelope.t_s.push(*t_s as f32).is_ok()
            && envelope.min_rise_c.push(bound as f32).is_ok();
        if !pushed {
            break;
        }
    }
    Ok((envelope.t_s.len() >= 2).then_some(envelope))
}

/// One line for people: the envelope's bounds at its first and last points.
pub fn summary(envelope: Option<&ColdStartEnvelope>) -> String {
    let ends = envelope.and_then(|e| {
        Some((
            (*e.t_s.first()?, *e.min_rise_c.first()?),
            (*e.t_s.last()?, *e.min_rise_c.last()?),
        ))
    });
    match ends {
        Some(((t0, r0), (t1, r1))) => format!(
            "cold-start check: a power-on must rise at least {r0:.2} degC by {t0:.0} s ... {r1:.2} degC by {t1:.0} s (training runs' mean - {BOUND_SD} sd); windows of one that rises less are flagged to {t1:.0} s"
        ),
        None => "cold-start check: none (no input takes the power-on for a cold start, or the runs show no warm-up)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::compensation::cold_start::ColdStartMonitor;

    /// A 45 min run at 1 Hz whose temperature follows `temp_c(t_s)`, quantised to the
    /// simulator's 0.0625 degC, with 0.02 degC of noise from a small LCG.
    fn run(seed: u64, temp_c: impl Fn(f64) -> f64) -> Run {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.07
        };
        let t: Vec<f64> = (1..=2700).map(f64::from).collect();
        let temp = t
            .iter()
            .map(|&t| ((temp_c(t) + noise()) / 0.0625).round() * 0.0625)
            .collect();
        Run::new(
            "",
            vec![("ambient_c".into(), "20".into())],
            vec![
                ("t_s".into(), t.clone()),
                ("rate_dph".into(), vec![0.0; t.len()]),
                ("temp_c".into(), temp),
            ],
        )
        .unwrap()
    }

    /// One time constant (the simulator's kind of warm-up), dissipation 2 % run to run.
    fn exponential(k: u64, start_above_c: f64) -> impl Fn(f64) -> f64 {
        let rise = 6.0 * (1.0 + 0.02 * ((k % 7) as f64 - 3.0) / 2.0);
        move |t| 20.0 + start_above_c + (rise - start_above_c) * (1.0 - (-t / 430.0).exp())
    }

    /// The twin law: a fast and a slow part (board and housing), a different shape.
    fn two_constants(k: u64, start_above_c: f64) -> impl Fn(f64) -> f64 {
        let scale = 1.0 + 0.02 * ((k % 5) as f64 - 2.0) / 2.0;
        move |t| {
            let cold = scale * (2.0 * (1.0 - (-t / 60.0).exp()) + 5.0 * (1.0 - (-t / 900.0).exp()));
            20.0 + start_above_c + cold * (1.0 - start_above_c / 7.0)
        }
    }

    /// Whether the device's monitor, fed the run's 10 s means, flags any window.
    fn flagged(envelope: &ColdStartEnvelope, r: &Run) -> bool {
        let rises = rises_by_time(std::slice::from_ref(r)).unwrap();
        let mut monitor = ColdStartMonitor::new();
        rises
            .iter()
            .any(|(t, rise)| monitor.push(envelope, *t as f32, 20.0 + rise[0] as f32))
    }

    #[test]
    fn cold_starts_pass_and_warm_restarts_are_caught_under_either_warm_up_law() {
        type Law = fn(u64, f64) -> Box<dyn Fn(f64) -> f64>;
        let laws: [(&str, Law); 2] = [
            ("one time constant", |k, c| Box::new(exponential(k, c))),
            ("two time constants", |k, c| Box::new(two_constants(k, c))),
        ];
        for (name, law) in laws {
            let training: Vec<Run> = (0..24).map(|k| run(k, law(k, 0.0))).collect();
            let e = cold_start_envelope(&training).unwrap().expect(name);
            assert_eq!(e.t_s.len(), MAX_COLD_START_POINTS, "{name}");
            assert_eq!(e.t_s[0], FIRST_POINT_S as f32, "{name}");
            // Fresh cold starts of the same population: none flagged.
            for k in 100..140 {
                assert!(!flagged(&e, &run(k, law(k, 0.0))), "{name}: cold start {k}");
            }
            // Restarts 1.5 degC and more above the ambient: all flagged.
            for (k, c) in [(200, 1.5), (201, 3.0), (202, 6.0)] {
                assert!(flagged(&e, &run(k, law(k, c))), "{name}: restart +{c} degC");
            }
        }
    }

    #[test]
    fn runs_that_do_not_warm_give_no_envelope() {
        // The null twin: the unit sits at its ambient.
        let flat: Vec<Run> = (0..24).map(|k| run(k, |_| 20.0)).collect();
        assert_eq!(cold_start_envelope(&flat).unwrap(), None);
        assert!(summary(None).contains("none"));
    }
}
