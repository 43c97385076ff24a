//! The final fit's output layer refitted to what the device's seeks see of it.
//!
//! Selection and the least-squares weights minimise the 10 s residual energy. A seek
//! averages each position over its dwell and differences opposite positions, so the part
//! of the model error that changes between one seek's two dwells becomes azimuth bias;
//! and a misfit that every cold start from one temperature shares (the final fit's shape,
//! not noise) becomes the same bias in every seek from there, which more starts do not
//! average away. The held-out scores that choose the shape do not see it: it belongs to
//! the final fit's particular centres, which the fold models do not share
//! (docs/record/northfinder.md, "Without dT/dt").
//!
//! So the final model's linear parameters (centre weights, bias, polynomial and linear
//! terms; centres and widths stay) are refitted by least squares to the 10 s rows plus,
//! for every training run, one row per opposite pair of positions of every seek in the
//! device's own timing (`SeekSchedule`): the difference of the run's row means over the
//! two positions' windows, with weight W. A parameter's column is the model evaluated with
//! that parameter 1 and the others 0, so the columns are exactly what the device computes.
//!
//! W is chosen over whole runs: `FOLDS` folds of runs, each refitted without its runs at
//! every W of `WEIGHT_GRID`; the held-out pair errors are grouped by pair index and by runs
//! of similar start temperature (no ambient column needed), and the score is the sum over
//! the groups of their squared mean error (less the groups' sampling variance, an estimate
//! of the squared bias a seek from that start temperature carries). The smallest W whose
//! score exceeds the lowest by at most one standard error of the paired difference wins
//! (the same held-out pairs score every W); W = 0 is the model as trained, kept unchanged.
//!
//! One file a job: `schedule` (the seeks' opposite pairs in the device's timing), `params`
//! (the model's linear parameters and their unit models), `normal` (each fold's normal
//! equations), `rows` (a run's 10 s and pair rows, accumulated per fold) and `score` (the
//! held-out seek bias of every weight); this file holds the result and the refit itself.

mod normal;
mod params;
mod rows;
mod schedule;
mod score;

use super::error::{Result, TrainError};
use super::seek_score::SeekGeometry;
use crate::train::data::dataset::Dataset;
use fog_core::model::format::RbfModel;
use normal::{singular, total};
use params::{get, parameters, set, unit_models};
use rows::accumulate;
pub use rows::FOLDS;
pub use schedule::{OppositePair, SeekSchedule};
pub use score::WEIGHT_GRID;
use score::{score_weights, start_temperature_bins};
use serde::Serialize;

/// The refitted model and how its weight was chosen.
#[derive(Clone, Debug, Serialize)]
pub struct SeekRefit {
    /// The model: the trained one when the chosen weight is 0.
    #[serde(skip)]
    pub model: RbfModel,
    /// The chosen weight of a pair row.
    pub weight: f64,
    /// Held-out score per weight of `WEIGHT_GRID`: the rms seek bias over the groups of
    /// runs and pairs, deg (at |sin psi| = 1; 0 where the estimate is not positive).
    pub bias_rms_deg: Vec<(f64, f64)>,
    /// Parameters refitted.
    pub parameters: usize,
    /// Pair rows over all runs.
    pub pair_rows: usize,
    /// rms of the 10 s residuals on the training rows as trained and refitted, deg/h: what
    /// the refit gives up of the absolute fit (a seek needs only differences).
    pub rms_10s_dph: (f64, f64),
}

impl SeekRefit {
    /// One line for people.
    pub fn summary(&self) -> String {
        let at = |w: f64| {
            self.bias_rms_deg
                .iter()
                .find(|(x, _)| *x == w)
                .map_or(f64::NAN, |(_, s)| *s)
        };
        format!(
            "seek refit: pair weight {} chosen over {FOLDS} folds of runs ({} parameters, {} pair rows; held-out seek bias rms {:.4} deg, {:.4} as trained; training 10 s rms {:.4} deg/h, {:.4} as trained)",
            self.weight,
            self.parameters,
            self.pair_rows,
            at(self.weight),
            at(0.0),
            self.rms_10s_dph.1,
            self.rms_10s_dph.0
        ) + &format!(
            "\n  held-out seek bias rms by pair weight, deg: {}",
            self.bias_rms_deg
                .iter()
                .map(|(w, b)| format!("{w}: {b:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

/// Refits `model`'s linear parameters to `ds`'s rows and its runs' seek pairs in
/// `schedule`, with the pair weight chosen over folds of runs (module notes).
/// `start_c[g]`: the start temperature of group g, degC (groups of similar start
/// temperature are what a bias is averaged over).
pub fn refit_for_seeks(
    model: &RbfModel,
    ds: &Dataset,
    start_c: &[f64],
    schedule: &SeekSchedule,
    geometry: SeekGeometry,
) -> Result<SeekRefit> {
    schedule.check()?;
    let params = parameters(model);
    let units = unit_models(model, &params);
    let k = params.len();
    let n_groups = ds.n_groups();
    if start_c.len() != n_groups || k == 0 {
        return Err(TrainError::BadConfig {
            option: "seek refit",
            why: format!(
                "{} start temperatures for {n_groups} runs, {k} parameters",
                start_c.len()
            ),
        });
    }
    let (folds, pairs) = accumulate(ds, &units, schedule)?;
    if pairs.is_empty() {
        return Err(TrainError::BadConfig {
            option: "seek refit",
            why: "no run has rows over both positions of a seek (the runs must be cold starts timed from power-on, with rows through the seek's dwells)".into(),
        });
    }
    let all = total(&folds, k);
    let bins = start_temperature_bins(start_c);
    let scores = score_weights(&folds, &all, &pairs, &bins, geometry)?;
    let bias_rms_deg = WEIGHT_GRID
        .iter()
        .zip(&scores)
        .map(|(&w, s)| (w, s.bias_rms_deg(&scores[0])))
        .collect();
    // The one-standard-error rule on paired differences: the smallest weight whose score
    // exceeds the lowest by no more than the standard error of that difference over the
    // groups (the same held-out pairs score every weight, so their noise is shared and
    // only the difference's is compared), so that a weight the held-out runs cannot tell
    // from a larger one leaves the model closer to its 10 s fit.
    let lowest = scores
        .iter()
        .min_by(|a, b| a.sum_sq_mean_deg2.total_cmp(&b.sum_sq_mean_deg2))
        .cloned()
        .unwrap_or_default();
    let chosen = scores
        .iter()
        .position(|s| s.not_worse_than(&lowest))
        .unwrap_or(0);
    let weight = WEIGHT_GRID[chosen];
    let mut refit = model.clone();
    let trained: Vec<f64> = params.iter().map(|&p| f64::from(get(model, p))).collect();
    let mut rms_10s_dph = (all.rms_rows(&trained), all.rms_rows(&trained));
    if weight > 0.0 {
        let theta = all.solve(None, weight).ok_or(singular())?;
        rms_10s_dph.1 = all.rms_rows(&theta);
        for (&p, &v) in params.iter().zip(&theta) {
            set(&mut refit, p, v as f32);
        }
    }
    Ok(SeekRefit {
        model: refit,
        weight,
        bias_rms_deg,
        parameters: k,
        pair_rows: pairs.len(),
        rms_10s_dph,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::train::{predict_batch, train_model, TrainConfig};
    use fog_core::model::format::{FeatureKind, FeatureSpec};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal as Gauss};

    /// The simulator's measured timing of the paper's seek (`pipeline::seek_schedule`).
    fn schedule() -> SeekSchedule {
        SeekSchedule {
            seeks: vec![vec![OppositePair {
                first_s: (10.0, 120.0),
                second_s: (140.0, 250.0),
            }]],
            period_s: 270.0,
        }
    }

    const RISE_C: f64 = 15.0;
    const TAU_S: f64 = 400.0;

    /// 60 cold starts, 10 from each of 6 temperatures from -40 to +60 degC; inputs the
    /// temperature and the clock exp(-t / 400 s), rows every 10 s to 2,700 s (10 seeks),
    /// targets `law(start, t, T)` + 0.02 deg/h white noise.
    fn runs(law: impl Fn(f64, f64, f64) -> f64, seed: u64) -> (Dataset, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noise = Gauss::new(0.0, 0.02).unwrap();
        let mut ds = Dataset::with_specs(
            vec![
                FeatureSpec::plain(FeatureKind::TempC),
                FeatureSpec {
                    kind: FeatureKind::PowerOnDecay,
                    tau_s: TAU_S as f32,
                },
            ],
            vec!["temp_c".into(), "clock".into()],
        )
        .unwrap();
        let mut starts = Vec::new();
        for r in 0..60 {
            let start = -40.0 + 20.0 * (r % 6) as f64;
            let t: Vec<f64> = (1..=270).map(|k| 10.0 * k as f64).collect();
            let temp = |t: f64| start + RISE_C * (1.0 - (-t / TAU_S).exp());
            let rows: Vec<Vec<f64>> = t
                .iter()
                .map(|&t| vec![temp(t), (-t / TAU_S).exp()])
                .collect();
            let y: Vec<f64> = t
                .iter()
                .map(|&t| law(start, t, temp(t)) + noise.sample(&mut rng))
                .collect();
            ds.push_group(&format!("r{r}"), &rows, &y, &t).unwrap();
            starts.push(start);
        }
        (ds, starts)
    }

    /// Shupe: drift proportional to dT/dt, which a temperature-only model cannot follow.
    fn shupe(_: f64, t: f64, temp: f64) -> f64 {
        60.0 * RISE_C / TAU_S * (-t / TAU_S).exp() + 0.01 * temp
    }

    /// Another law: a turn-on transient (150 s) whose size follows the soak temperature.
    fn turn_on(start: f64, t: f64, temp: f64) -> f64 {
        2.0 * (start / 50.0) * (-t / 150.0).exp() + 0.01 * temp
    }

    /// Null: a smooth function of the temperature alone, which the model can represent.
    fn temperature_only(_: f64, _: f64, temp: f64) -> f64 {
        0.01 * temp + 0.002 * (temp / 10.0).powi(2)
    }

    fn rms_10s(model: &RbfModel, ds: &Dataset) -> f64 {
        let p = predict_batch(model, ds.rows()).unwrap();
        let ss: f64 = p
            .iter()
            .zip(&ds.targets_dph)
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        (ss / p.len() as f64).sqrt()
    }

    fn refit_of(law: impl Fn(f64, f64, f64) -> f64, seed: u64) -> (SeekRefit, f64, f64) {
        let (ds, starts) = runs(law, seed);
        let trained = train_model(&ds, &TrainConfig::default()).unwrap().model;
        let r = refit_for_seeks(
            &trained,
            &ds,
            &starts,
            &schedule(),
            SeekGeometry::default_site(),
        )
        .unwrap();
        eprintln!("weight {} of {:?}", r.weight, r.bias_rms_deg);
        (r.clone(), rms_10s(&trained, &ds), rms_10s(&r.model, &ds))
    }

    fn at(r: &SeekRefit, w: f64) -> f64 {
        r.bias_rms_deg.iter().find(|(x, _)| *x == w).unwrap().1
    }

    #[test]
    fn a_misfit_shared_by_starts_from_one_temperature_is_refitted_away_under_two_laws() {
        for (name, law) in [
            ("shupe", shupe as fn(f64, f64, f64) -> f64),
            ("turn-on", turn_on),
        ] {
            let (r, _, _) = refit_of(law, 3);
            assert!(r.weight > 0.0, "{name}: {r:?}");
            assert!(at(&r, 0.0) > 0.003, "{name}: a bias to remove, {r:?}");
            // Measured: shupe 0.035 -> 0.015 deg (W 10,000), turn-on 0.0091 -> 0.0051
            // (W 1,000); the null law's 0.0028 -> 0.0020 (W 100).
            assert!(at(&r, r.weight) < 0.75 * at(&r, 0.0), "{name}: {r:?}");
            assert_eq!(r.pair_rows, 60 * 10, "{name}");
        }
    }

    #[test]
    fn a_law_the_model_represents_has_no_seek_bias_and_keeps_its_10s_fit() {
        let (r, before, after) = refit_of(temperature_only, 3);
        // The normal equations' rms is the deployed model's (f32 maths) to 1e-4.
        assert!(
            (r.rms_10s_dph.0 - before).abs() < 1e-4 * before,
            "{r:?} {before}"
        );
        assert!(
            (r.rms_10s_dph.1 - after).abs() < 1e-4 * after,
            "{r:?} {after}"
        );
        assert!(at(&r, 0.0) < 0.1 * at(&refit_of(shupe, 3).0, 0.0), "{r:?}");
        assert!(after < 1.02 * before, "10 s rms {before} -> {after}, {r:?}");
    }

    #[test]
    fn the_schedule_repeats_its_last_seek_and_stops_at_the_end() {
        let s = schedule();
        let pairs = s.pairs_until(800.0);
        assert_eq!(pairs.len(), 3);
        assert_eq!(pairs[2].first_s, (550.0, 660.0));
        assert_eq!(s.pairs_until(249.0).len(), 0);
        assert_eq!(s.pairs_until(f64::INFINITY).len(), 1);
        let bad = SeekSchedule {
            period_s: 0.0,
            ..schedule()
        };
        assert!(bad.check().is_err());
        let reversed = SeekSchedule {
            seeks: vec![vec![OppositePair {
                first_s: (120.0, 10.0),
                second_s: (140.0, 250.0),
            }]],
            ..schedule()
        };
        assert!(reversed.check().is_err());
    }
}
