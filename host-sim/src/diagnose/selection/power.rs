//! Test power measured on the record itself. When nothing is named, "no structure" is
//! only a statement if the same record would have shown an effect of a stated size. The
//! smallest reachable p counts sign patterns of the validation units, not the noise: on
//! records whose drift noise has long memory (bias wander, a rate random walk) units are
//! far from independent and an effect the size of the noise goes unseen although a small
//! p is reachable (`tests/diagnose_single_record.rs`: named in 4 of 80 records).
//!
//! So effects are planted and looked for, one of every shape the library can name (value,
//! derivatives, memory, decay, sinusoid, levels, spline, products with the base's
//! inputs): for each shape, the best-ranked candidate of that shape whose feature the
//! chosen base cannot predict held out (the base fitted to the feature itself: a copy of
//! T would be absorbed by a base in T, which is confounding, not lack of power). Its
//! columns, each scaled to unit within-run rms and summed, minus what the base predicts,
//! made orthogonal to the base's held-out residual within each run (so it adds a new
//! structure rather than amplifying one the residual already has) and scaled to the
//! residual's own within-run rms (1 noise sigma), are added to the drift; the base is
//! chosen again on the same validation layout and the same family-wise selection (first
//! step) is run. If any planted shape is not named, the report says "cannot decide: no
//! test power at 1 sigma" for that shape instead of "no significant cause".

use crate::diagnose::baseline::choice::{self, BaseFit};
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::candidates::families::OperatorFamily;
use crate::diagnose::candidates::transforms::{stacked_columns, Candidate};
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::selection::scored::ALPHA;
use crate::diagnose::selection::screen::{self, Screening};
use crate::diagnose::validation::folds::{demeaned_by_run, Folds};
use serde::Serialize;

/// Size of the planted effect, in within-run rms of the base's held-out residual.
pub const PLANTED_SIGMAS: f64 = 1.0;

/// One planted shape.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShapeCheck {
    pub planted: String,
    /// Its operator family (`candidates::families`).
    pub family: &'static str,
    /// Whether the selection's first step named it (its column, in the same product).
    pub named: bool,
    pub gain_pct: f64,
    pub p_value: f64,
}

/// The outcome of planting known effects into the record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PowerCheck {
    /// Label of the first planted shape that was not named (else of the first planted);
    /// `None` when no candidate could be planted (each mostly predicted by the base).
    pub planted: Option<String>,
    /// Its rms within runs, deg/h (`PLANTED_SIGMAS` x the residual's).
    pub planted_rms_dph: f64,
    /// Whether every planted shape was named.
    pub named: bool,
    /// `planted`'s held-out gain over the re-chosen base, %, and family-wise p.
    pub gain_pct: f64,
    pub p_value: f64,
    /// Every shape planted, in the order tried.
    pub shapes: Vec<ShapeCheck>,
}

/// What the selection is re-run with on the record with a planted effect: the library
/// and the number of sequences sharing alpha.
#[derive(Clone, Copy)]
pub struct Rerun<'a> {
    pub library: &'a [Candidate],
    pub groups: f64,
}

/// When nothing was named (`silent`) and the layout can reach p < alpha at all
/// (otherwise the report already says "no test power"): plants one candidate of every
/// shape of `screening` at 1 residual sigma into `st.y` and selects again. `None` when
/// not silent, p < alpha is unreachable, or there is no candidate.
pub fn check(
    silent: bool,
    campaign: &Campaign,
    folds: &Folds,
    st: &mut Stacked,
    base: &BaseFit,
    screening: &Screening,
    rerun: Rerun<'_>,
) -> Result<Option<PowerCheck>, DiagnoseError> {
    let reachable =
        crate::diagnose::validation::signflip::smallest_p(folds.unit_rows.len()) < ALPHA;
    if !silent || !reachable || screening.scored.is_empty() {
        return Ok(None);
    }
    let mut checked = Vec::new();
    let mut planted_rms = 0.0;
    // One shape at a time, and only the drift is swapped in and out of `st` (memory: one
    // planted effect and one drift column per row, never a copy of the stacked series).
    for shape in shapes(screening) {
        let Some((cand, planted)) = plantable(campaign, folds, st, base, screening, shape)? else {
            continue;
        };
        let with_effect: Vec<f64> = st.y.iter().zip(&planted).map(|(y, e)| y + e).collect();
        let drift = std::mem::replace(&mut st.y, with_effect);
        let chosen = choice::choose(folds, st);
        st.y = drift;
        let replanted_base = chosen?.chosen;
        let again = screen::screen(
            campaign,
            folds,
            &replanted_base,
            rerun.library.to_vec(),
            rerun.groups,
            1,
        )?;
        let found = again.scored.iter().find(|s| s.cand.label() == cand.label());
        let named = again.steps.first().is_some_and(|s| {
            s.scored.cand.column == cand.column
                && s.scored.cand.times == cand.times
                && s.scored.cand.partner == cand.partner
        });
        planted_rms = within_rms(&folds.run_rows, &planted);
        checked.push(ShapeCheck {
            planted: cand.label(),
            family: OperatorFamily::of(&cand).name(),
            named,
            gain_pct: found.map_or(0.0, |s| s.gain_pct),
            p_value: found.map_or(1.0, |s| s.p_value),
        });
    }
    let headline = checked
        .iter()
        .find(|s| !s.named)
        .or(checked.first())
        .cloned();
    Ok(Some(PowerCheck {
        planted: headline.as_ref().map(|s| s.planted.clone()),
        planted_rms_dph: planted_rms,
        named: !checked.is_empty() && checked.iter().all(|s| s.named),
        gain_pct: headline.as_ref().map_or(0.0, |s| s.gain_pct),
        p_value: headline.as_ref().map_or(1.0, |s| s.p_value),
        shapes: checked,
    }))
}

/// Candidates tried per shape, in rank order, for planting.
pub const TRIED: usize = 5;
/// Least share of a feature's within-run variance the base must leave unexplained held
/// out for the feature to be planted: a feature the base predicts (a copy of T under a
/// base in T) cannot be told from the base on any record, which is confounding, not a
/// lack of test power.
const MIN_UNEXPLAINED: f64 = 0.5;

/// A candidate's shape: its transform and the base input (or, for a pairwise product,
/// any other column) it multiplies.
fn shape_of(c: &Candidate) -> Shape {
    let times = c.times.map(|b| b.name());
    (
        c.transform.name(),
        times.or(c.partner.as_ref().map(|_| "another column")),
    )
}

/// A candidate's shape, as the power check plants it.
type Shape = (&'static str, Option<&'static str>);

/// The shapes among the ranked candidates, in rank order of their best candidate.
fn shapes(screening: &Screening) -> Vec<Shape> {
    let mut shapes: Vec<Shape> = Vec::new();
    for s in &screening.scored {
        if !shapes.contains(&shape_of(&s.cand)) {
            shapes.push(shape_of(&s.cand));
        }
    }
    shapes
}

/// For one shape among the ranked candidates, the first of its `TRIED` best whose
/// feature the base leaves at least `MIN_UNEXPLAINED` unexplained, with the effect to
/// plant. The feature is fitted as the target in place of `st.y`, which is restored.
fn plantable(
    campaign: &Campaign,
    folds: &Folds,
    st: &mut Stacked,
    base: &BaseFit,
    screening: &Screening,
    shape: Shape,
) -> Result<Option<(Candidate, Vec<f64>)>, DiagnoseError> {
    let runs = &folds.run_rows;
    for scored in screening
        .scored
        .iter()
        .filter(|s| shape_of(&s.cand) == shape)
        .take(TRIED)
    {
        let cols = stacked_columns(campaign, &scored.cand);
        let drift = std::mem::replace(&mut st.y, unit_sum(runs, &cols));
        drop(cols);
        let fit = choice::fit(folds, st, &base.spec);
        let feature = std::mem::replace(&mut st.y, drift);
        let Ok(fit) = fit else {
            continue;
        };
        let unexplained = fit.cv.residual;
        let share = (within_rms(runs, &unexplained) / within_rms(runs, &feature)).powi(2);
        if share < MIN_UNEXPLAINED || !share.is_finite() {
            continue;
        }
        if let Some(planted) = planted_effect(runs, &unexplained, &base.cv.residual) {
            return Ok(Some((scored.cand.clone(), planted)));
        }
    }
    Ok(None)
}

/// The columns, each scaled to unit within-run rms, summed.
fn unit_sum(runs: &[std::ops::Range<usize>], cols: &[Vec<f64>]) -> Vec<f64> {
    let n = cols.first().map_or(0, Vec::len);
    let mut out = vec![0.0; n];
    for c in cols {
        let s = within_rms(runs, c);
        if s > 0.0 && s.is_finite() {
            out.iter_mut().zip(c).for_each(|(o, v)| *o += v / s);
        }
    }
    out
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
