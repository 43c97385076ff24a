//! The input range a model declares (`input_min` / `input_max`): where a new run of the
//! training population is expected to stay, not merely the envelope of the training rows.
//!
//! Why: the device flags every window whose inputs leave the declared range
//! (`WindowStatus::InputOutOfRange`) and the north finder skips flagged windows, so a
//! declared range that a healthy unit leaves makes seeks fail for nothing. The raw envelope
//! of n runs is left by a new run's extreme with probability 1/(n + 1) on each side
//! (exchangeability), and that happens in the first minutes after power-on, where dT/dt
//! peaks (the peak moves with the unit's dissipation) and T starts (with the soak).
//!
//! How: for each input, the extremes (max and min) of every training run; runs at the same
//! ambient (`ambient_c`, to 1 degC; runs without it form one set) are replicates, and the
//! pooled within-set standard deviation s of their extremes (both sides pooled, dof =
//! sum over sets and sides of n_set - 1) estimates how far a new run's extreme scatters.
//! The envelope widens on each side by t(dof, p) s sqrt(1 + 1/n) (the Student-t
//! prediction bound of one new run, n the runs in the set that defines that side), with
//! p = `FALSE_ALARM_PER_START` / (2 x inputs) (Bonferroni over inputs and sides).
//! Without replicates (dof = 0) there is no estimate and the raw envelope stays (said in
//! the report). Far-off inputs (another ambient, a faster warm-up than any unit of the
//! population) are still flagged.
//!
//! An input that is a function of the time since power-on alone (`FeatureKind::
//! settled_value`: the power-on decays) reaches, on its late side, the value it settles
//! to: a unit on for longer than the training runs is further along the same curve, and
//! flagging it made every seek after the runs' length fail (a model trained on 30 min runs
//! flagged a warm unit from 46 min on).

use crate::stats::student_t::upper_quantile;
use crate::train::data::dataset::Dataset;
use fog_core::model::format::RbfModel;
use serde::Serialize;

/// Chance that a healthy new run leaves the declared range somewhere (any input, either
/// side): the product's false-alarm budget, 1 in 1,000.
pub const FALSE_ALARM_PER_START: f64 = 1e-3;

/// How one input's declared range was set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputRange {
    pub input: String,
    /// Envelope of the training rows, raw units.
    pub envelope_min: f64,
    pub envelope_max: f64,
    /// Pooled run-to-run std of the per-run extremes, raw units, and its degrees of freedom.
    pub extreme_std: f64,
    pub dof: usize,
    /// Student-t factor used (0 without replicates).
    pub t_factor: f64,
    /// Declared range, raw units.
    pub declared_min: f64,
    pub declared_max: f64,
}

/// Per-run (min, max) of input `j`, by group id (None for a group without rows).
fn run_extremes(ds: &Dataset, j: usize) -> Vec<Option<(f64, f64)>> {
    let mut out: Vec<Option<(f64, f64)>> = vec![None; ds.n_groups()];
    for (row, &g) in ds.rows().zip(&ds.groups) {
        let v = row[j];
        let e = &mut out[g as usize];
        *e = Some(e.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
    }
    out
}

/// Replicate set of every group: groups with the same ambient (1 degC) share one.
fn replicate_sets(ds: &Dataset) -> Vec<Vec<usize>> {
    let key = |g: usize| {
        ds.group_ambient_c
            .get(g)
            .copied()
            .flatten()
            .map(|a| a.round() as i64)
    };
    let mut keys: Vec<Option<i64>> = (0..ds.n_groups()).map(key).collect();
    keys.sort_unstable();
    keys.dedup();
    keys.iter()
        .map(|k| (0..ds.n_groups()).filter(|&g| key(g) == *k).collect())
        .collect()
}

/// The declared range of every input of `ds`.
pub fn declared_ranges(ds: &Dataset) -> Vec<InputRange> {
    let sets = replicate_sets(ds);
    let d = ds.n_inputs();
    let p = FALSE_ALARM_PER_START / (2.0 * d as f64);
    (0..d)
        .map(|j| {
            let ext = run_extremes(ds, j);
            let (mut ss, mut dof) = (0.0, 0usize);
            // Runs of the set holding each side's extreme.
            let (mut lo, mut hi) = ((f64::INFINITY, 1usize), (f64::NEG_INFINITY, 1usize));
            for set in &sets {
                let e: Vec<(f64, f64)> = set.iter().filter_map(|&g| ext[g]).collect();
                let n = e.len();
                for side in [|x: &(f64, f64)| x.0, |x: &(f64, f64)| x.1] {
                    let v: Vec<f64> = e.iter().map(side).collect();
                    let m = v.iter().sum::<f64>() / n.max(1) as f64;
                    ss += v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
                    dof += n.saturating_sub(1);
                }
                for &(a, b) in &e {
                    if a < lo.0 {
                        lo = (a, n);
                    }
                    if b > hi.0 {
                        hi = (b, n);
                    }
                }
            }
            let s = if dof > 0 {
                (ss / dof as f64).sqrt()
            } else {
                0.0
            };
            let t = if dof > 0 {
                upper_quantile(p, dof as f64)
            } else {
                0.0
            };
            let widen = |n: usize| t * s * (1.0 + 1.0 / n as f64).sqrt();
            let (mut declared_min, mut declared_max) = (lo.0 - widen(lo.1), hi.0 + widen(hi.1));
            if let Some(v) = ds.specs.get(j).and_then(|f| f.kind.settled_value()) {
                declared_min = declared_min.min(f64::from(v));
                declared_max = declared_max.max(f64::from(v));
            }
            InputRange {
                input: ds.input_names[j].clone(),
                envelope_min: lo.0,
                envelope_max: hi.0,
                extreme_std: s,
                dof,
                t_factor: t,
                declared_min,
                declared_max,
            }
        })
        .collect()
}

/// Writes the declared ranges into the model (f32, rounded outwards).
pub fn apply(model: &mut RbfModel, ranges: &[InputRange]) {
    for (j, r) in ranges.iter().enumerate() {
        if let (Some(lo), Some(hi)) = (model.input_min.get_mut(j), model.input_max.get_mut(j)) {
            *lo = lo.min(r.declared_min as f32);
            *hi = hi.max(r.declared_max as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::model::format::{FeatureKind, FeatureSpec};

    /// Runs of one input whose maxima scatter by `spread`, at the given ambients.
    fn dataset(maxima: &[f64], ambients: &[Option<f64>]) -> Dataset {
        let mut ds = Dataset::with_specs(
            vec![FeatureSpec::plain(FeatureKind::TempRateCps)],
            vec!["rate".into()],
        )
        .unwrap();
        for (r, (&m, &a)) in maxima.iter().zip(ambients).enumerate() {
            let rows: Vec<Vec<f64>> = (0..20).map(|k| vec![m * k as f64 / 19.0]).collect();
            let id = ds
                .push_group(&format!("r{r}"), &rows, &[0.0; 20], &[0.0; 20])
                .unwrap();
            ds.set_group_ambient(id, a);
        }
        ds
    }

    #[test]
    fn replicates_widen_by_the_t_bound_and_lone_runs_do_not() {
        let maxima = [1.0, 1.1, 0.9];
        let ds = dataset(&maxima, &[Some(20.0); 3]);
        let r = &declared_ranges(&ds)[0];
        // Maxima 1.0 / 1.1 / 0.9 (ss 0.02), minima all 0: s^2 = 0.02 / 4, dof 4.
        assert_eq!(r.dof, 4);
        assert!((r.extreme_std - (0.02f64 / 4.0).sqrt()).abs() < 1e-12);
        let t = upper_quantile(FALSE_ALARM_PER_START / 2.0, 4.0);
        let expect = 1.1 + t * r.extreme_std * (4.0f64 / 3.0).sqrt();
        assert!((r.declared_max - expect).abs() < 1e-9, "{r:?}");
        assert!(r.declared_min < 0.0);
        // Three runs at three ambients: no replicates, the envelope stays.
        let ds = dataset(&maxima, &[Some(-40.0), Some(20.0), Some(60.0)]);
        let r = &declared_ranges(&ds)[0];
        assert_eq!((r.dof, r.declared_max, r.declared_min), (0, 1.1, 0.0));
    }

    #[test]
    fn a_power_on_clock_reaches_its_settled_value_and_the_gyros_inputs_do_not() {
        // Three 30 min runs at one ambient: exp(-t/400 s), (t/400 s) exp(-t/400 s) and a
        // temperature rising to its settled value. The clocks' late side reaches 0 (a unit
        // on for an hour is further along them); their early side and the temperature keep
        // the envelope (identical runs: no widening).
        let specs = vec![
            FeatureSpec {
                kind: FeatureKind::PowerOnDecay,
                tau_s: 400.0,
            },
            FeatureSpec {
                kind: FeatureKind::PowerOnDecayStretch,
                tau_s: 400.0,
            },
            FeatureSpec::plain(FeatureKind::TempC),
        ];
        let names = vec!["decay".into(), "stretch".into(), "t".into()];
        let mut ds = Dataset::with_specs(specs, names).unwrap();
        let t: Vec<f64> = (1..=180).map(|k| 10.0 * f64::from(k)).collect();
        let rows: Vec<Vec<f64>> = t
            .iter()
            .map(|&t| {
                let u = t / 400.0;
                vec![(-u).exp(), u * (-u).exp(), 20.0 + 8.0 * (1.0 - (-u).exp())]
            })
            .collect();
        for r in 0..3 {
            let id = ds
                .push_group(&format!("r{r}"), &rows, &[0.0; 180], &t)
                .unwrap();
            ds.set_group_ambient(id, Some(20.0));
        }
        let ranges = declared_ranges(&ds);
        let (first, last) = (&rows[0], &rows[179]);
        assert_eq!(
            (ranges[0].declared_min, ranges[0].declared_max),
            (0.0, first[0])
        );
        assert_eq!(ranges[0].envelope_min, last[0]);
        assert_eq!(ranges[1].declared_min, 0.0);
        assert_eq!(
            ranges[1].declared_max,
            (-1.0f64).exp(),
            "the peak at t = tau"
        );
        assert_eq!(
            (ranges[2].declared_min, ranges[2].declared_max),
            (first[2], last[2])
        );
    }

    #[test]
    fn null_twin_identical_replicates_keep_the_envelope() {
        let ds = dataset(&[1.0, 1.0, 1.0], &[None; 3]);
        let r = &declared_ranges(&ds)[0];
        assert_eq!(r.extreme_std, 0.0);
        assert_eq!((r.declared_min, r.declared_max), (0.0, 1.0));
    }
}
