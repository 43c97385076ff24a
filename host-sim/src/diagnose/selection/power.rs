//! Test power measured on the record itself. When nothing is named, "no structure" is
//! only a statement if the same record would have shown an effect of a stated size. The
//! smallest reachable p counts sign patterns of the validation units, not the noise: on
//! records whose drift noise has long memory (bias wander, a rate random walk) units are
//! far from independent and an effect the size of the noise goes unseen although a small
//! p is reachable (`tests/diagnose_single_record.rs`: named in 4 of 80 records).
//!
//! So an effect is planted and looked for: the part of the top-ranked candidate's feature
//! that the chosen base cannot predict held out (the base fitted to the feature itself:
//! a copy of T would be absorbed by a base in T, which is confounding, not lack of
//! power), made orthogonal to the base's held-out residual within each run (so it adds a
//! new structure rather than amplifying one the residual already has) and scaled to the
//! residual's own within-run rms (1 noise sigma), is added to the drift; the base is
//! chosen again on the same validation layout and the same family-wise screen is run.
//! If the planted copy is not named, the report says "cannot decide: no test power at
//! 1 sigma" instead of "no significant cause".

use crate::diagnose::base::bases::{self, BaseFit};
use crate::diagnose::base::models::Stacked;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::library::transforms;
use crate::diagnose::report::residuals::demeaned_by_run;
use crate::diagnose::selection::screen::{self, Screening};
use crate::diagnose::validation::cv::Folds;
use serde::Serialize;

/// Size of the planted effect, in within-run rms of the base's held-out residual.
pub const PLANTED_SIGMAS: f64 = 1.0;

/// The outcome of planting a known effect into the record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PowerCheck {
    /// Label of the candidate whose (orthogonalised) feature was planted; `None` when
    /// none of the `TRIED` best-ranked candidates could be (each mostly predicted by the
    /// base: nothing else is counted then).
    pub planted: Option<String>,
    /// Its rms within runs, deg/h (`PLANTED_SIGMAS` x the residual's).
    pub planted_rms_dph: f64,
    /// Whether the family-wise screen named it.
    pub named: bool,
    /// Its held-out gain over the re-chosen base, %, and family-wise p.
    pub gain_pct: f64,
    pub p_value: f64,
}

/// When nothing was named (`silent`) and the layout can reach p < alpha at all
/// (otherwise the report already says "no test power"): plants the top-ranked plantable
/// candidate of `screening` at 1 residual sigma into `st.y` and screens again. `None`
/// when not silent, p < alpha is unreachable, or there is no candidate.
pub fn check(
    silent: bool,
    campaign: &Campaign,
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    screening: &Screening,
) -> Result<Option<PowerCheck>, DiagnoseError> {
    let reachable =
        crate::diagnose::validation::signflip::smallest_p(folds.unit_rows.len()) < screen::ALPHA;
    if !silent || !reachable || screening.scored.is_empty() {
        return Ok(None);
    }
    let Some((label, planted)) = plantable(campaign, folds, st, base, screening)? else {
        return Ok(Some(PowerCheck {
            planted: None,
            planted_rms_dph: 0.0,
            named: false,
            gain_pct: 0.0,
            p_value: 1.0,
        }));
    };
    let mut with_effect = st.clone();
    with_effect
        .y
        .iter_mut()
        .zip(&planted)
        .for_each(|(y, e)| *y += e);
    let base = bases::choose(folds, &with_effect)?.chosen;
    let again = screen::screen(
        campaign,
        folds,
        &with_effect,
        &base,
        transforms::enumerate(campaign),
        &[],
    )?;
    let found = again.scored.iter().position(|s| s.cand.label() == label);
    let (gain_pct, p_value) = found.map_or((0.0, 1.0), |i| {
        (again.scored[i].gain_pct, again.scored[i].p_value)
    });
    Ok(Some(PowerCheck {
        planted: Some(label),
        planted_rms_dph: within_rms(&folds.run_rows, &planted),
        named: found.is_some() && again.named == found,
        gain_pct,
        p_value,
    }))
}

/// Candidates tried in rank order for planting.
pub const TRIED: usize = 20;
/// Least share of a feature's within-run variance the base must leave unexplained held
/// out for the feature to be planted: a feature the base predicts (a copy of T under a
/// base in T) cannot be told from the base on any record, which is confounding, not a
/// lack of test power.
const MIN_UNEXPLAINED: f64 = 0.5;

/// The first of the `TRIED` best-ranked candidates whose feature the base leaves at
/// least `MIN_UNEXPLAINED` unexplained, with the effect to plant.
fn plantable(
    campaign: &Campaign,
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    screening: &Screening,
) -> Result<Option<(String, Vec<f64>)>, DiagnoseError> {
    let runs = &folds.run_rows;
    for scored in screening.scored.iter().take(TRIED) {
        let cols = scored.columns(campaign);
        let Some(feature) = cols.first() else {
            continue;
        };
        let mut feature_as_target = st.clone();
        feature_as_target.y.clone_from(feature);
        let Ok(fit) = bases::fit(folds, &feature_as_target, &base.spec) else {
            continue;
        };
        let unexplained = fit.cv.residual;
        let share = (within_rms(runs, &unexplained) / within_rms(runs, feature)).powi(2);
        if share < MIN_UNEXPLAINED || !share.is_finite() {
            continue;
        }
        if let Some(planted) = planted_effect(runs, &unexplained, &base.cv.residual) {
            return Ok(Some((scored.cand.label(), planted)));
        }
    }
    Ok(None)
}

/// `feature` minus its run means and its projection on the run-demeaned `residual`,
/// scaled to `PLANTED_SIGMAS` x the residual's within-run rms.
fn planted_effect(
    runs: &[std::ops::Range<usize>],
    feature: &[f64],
    residual: &[f64],
) -> Option<Vec<f64>> {
    let f = demeaned_by_run(runs, feature);
    let r = demeaned_by_run(runs, residual);
    let rr: f64 = r.iter().map(|v| v * v).sum();
    let fr: f64 = f.iter().zip(&r).map(|(a, b)| a * b).sum();
    let along = if rr > 0.0 { fr / rr } else { 0.0 };
    let orth: Vec<f64> = f.iter().zip(&r).map(|(a, b)| a - along * b).collect();
    let (size, target) = (within_rms(runs, &orth), within_rms(runs, residual));
    // Less than 1e-6 of the feature left after the projection: nothing new to plant.
    let usable = size > 1e-6 * within_rms(runs, &f) && target > 0.0;
    (usable && size.is_finite() && target.is_finite()).then(|| {
        orth.iter()
            .map(|v| v * PLANTED_SIGMAS * target / size)
            .collect()
    })
}

/// Rms around each run's own mean.
fn within_rms(runs: &[std::ops::Range<usize>], v: &[f64]) -> f64 {
    let d = demeaned_by_run(runs, v);
    (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_planted_effect_is_orthogonal_to_the_residual_and_one_sigma_in_size() {
        let runs = vec![0..50, 50..120];
        let residual: Vec<f64> = (0..120)
            .map(|i| (f64::from(i) * 0.37).sin() + 0.2)
            .collect();
        let feature: Vec<f64> = (0..120)
            .map(|i| f64::from(i) * 0.01 + (f64::from(i) * 0.37).sin())
            .collect();
        let e = planted_effect(&runs, &feature, &residual).unwrap();
        let r = demeaned_by_run(&runs, &residual);
        let dot: f64 = e.iter().zip(&r).map(|(a, b)| a * b).sum();
        assert!(dot.abs() < 1e-9, "not orthogonal: {dot}");
        let ratio = within_rms(&runs, &e) / within_rms(&runs, &residual);
        assert!((ratio - PLANTED_SIGMAS).abs() < 1e-12, "size ratio {ratio}");
        assert!(
            planted_effect(&runs, &residual, &residual).is_none(),
            "a feature equal to the residual has nothing left to plant"
        );
    }
}
