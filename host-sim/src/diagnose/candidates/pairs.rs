//! Products of any two extra columns (issue 38 item 2): the drift may depend on one column
//! with a sensitivity set by another (a supply-voltage coefficient that changes with the
//! cabinet's temperature), which no single-column transform and no product with the base's
//! inputs expresses. Each product is of the two values, each less its campaign mean (as the
//! products with T centre the feature), `(a - mean a) x (b - mean b)`.
//!
//! k columns give k(k-1)/2 products, and every candidate in the library widens the naming
//! test's family-wise maximum and costs a held-out fit per step, so they are screened
//! hierarchically before they enter: every pair is scored once, cheaply, against the base,
//! and only the `PAIR_BUDGET` strongest are kept. The score is each product's per-run
//! score against the chosen base's residual (its part orthogonal to the base, whitened:
//! `validation::score`, through `Prepared::unit_scores`, one pass over the rows, no
//! held-out fit), and the statistic ranked is the sum over runs of its squares. That sum
//! does not change when whole runs' residuals change sign, which is what the naming test's
//! null does (`validation::signflip`): a screen on it picks the same products under every
//! flip, so the test on the kept products keeps its level (a screen on the signed sum
//! would pick, on the data, the products that look best in the one direction the test
//! then measures, and its family-wise maximum would no longer cover the pairs dropped).
//! The cost is that a product whose per-run scores agree in sign ranks no higher than one
//! whose scores are as large but disagree; the test sorts those out.
//!
//! Products come after every older family in the library, so the cap (`MAX_CANDIDATES`)
//! cuts them first; the screened-out pairs are reported as the family's note, not as
//! candidates. The power check plants only the products kept (the screen ran on the
//! record as it is).

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::candidates::families::{FamilyNote, OperatorFamily};
use crate::diagnose::candidates::transforms::{stacked_columns, Candidate, Partner};
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::folds::Folds;

/// Products kept after the screen. As many as the selection names causes within runs at
/// most (`selection::screen::MAX_STEPS`, 4): a planted product needs one slot, a product
/// beside another cause two, and each slot more widens the test's maximum for every
/// candidate; a fixed few also fixes their share of the library (about one column's
/// worth, ~20) and of the time, whatever the number of columns.
pub const PAIR_BUDGET: usize = 4;

/// Every product of two extra columns' values, `i < j`, in column order: the value of
/// column `i` (centred on `centre_i`) times column `j` less its mean. `value(i)` is the
/// centred value candidate of extra column `i` (with its campaign mean in `centres.0`).
pub fn all_pairs(c: &Campaign, value: &dyn Fn(usize) -> Candidate) -> Vec<Candidate> {
    let values: Vec<Candidate> = (0..c.extra_names.len()).map(value).collect();
    let k = values.len();
    let mut out = Vec::with_capacity(k * k.saturating_sub(1) / 2);
    for (i, own) in values.iter().enumerate() {
        for (j, other) in values.iter().enumerate().skip(i + 1) {
            out.push(Candidate {
                partner: Some(Partner {
                    index: j,
                    column: other.column.clone(),
                    centre: other.centres.0,
                }),
                ..own.clone()
            });
        }
    }
    out
}

/// The screen's statistic of every product: the sum over units of its squared whitened
/// score against `base` (None when it adds nothing new to the base or is not finite).
pub fn pair_scores(
    c: &Campaign,
    folds: &Folds,
    base: &BaseFit,
    pairs: &[Candidate],
) -> Vec<Option<f64>> {
    pairs
        .iter()
        .map(|p| {
            let cols = stacked_columns(c, p);
            if cols.iter().flatten().any(|v| !v.is_finite()) {
                return None;
            }
            let scores = base.prepared.unit_scores(folds, &cols)?;
            let s: f64 = scores.iter().flatten().map(|v| v * v).sum();
            s.is_finite().then_some(s)
        })
        .collect()
}

/// The `PAIR_BUDGET` products with the largest statistic (ties and order: library order),
/// kept in library order, and a note saying how many of how many were kept.
pub fn screened(
    c: &Campaign,
    folds: &Folds,
    base: &BaseFit,
    pairs: Vec<Candidate>,
) -> (Vec<Candidate>, Option<FamilyNote>) {
    let scores = pair_scores(c, folds, base, &pairs);
    let mut ranked: Vec<(usize, f64)> = scores
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.map(|s| (i, s)))
        .collect();
    ranked.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    ranked.truncate(PAIR_BUDGET);
    let mut keep: Vec<usize> = ranked.into_iter().map(|(i, _)| i).collect();
    keep.sort_unstable();
    let total = pairs.len();
    let note = (total > keep.len()).then(|| FamilyNote {
        family: OperatorFamily::PairProduct,
        note: format!(
            "library: {} of {total} products of two columns kept, the strongest by the sum over \
             runs of their squared score against the base (screened before the test)",
            keep.len()
        ),
    });
    let kept = pairs
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep.contains(i))
        .map(|(_, p)| p)
        .collect();
    (kept, note)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::baseline::layout::layout_and_base;
    use crate::diagnose::candidates::library_of;
    use crate::diagnose::input::Series;
    use crate::diagnose::report::families::{rows, Inputs};
    use crate::diagnose::selection::screen::Screening;
    use crate::diagnose::validation::buffer::BufferRule;

    /// Eight runs of 10 s rows warming up; extras `a`, `b`, their noisy copies `a2`, `b2`
    /// and two unrelated wanders `u`, `v`; the drift is `(a - mean) x (b - mean)` plus
    /// white noise of a tenth of its rms.
    fn campaign() -> Campaign {
        let mut state = 0.4321f64;
        let mut next = move || {
            state = (state * 997.0 + 0.137).fract();
            state - 0.5
        };
        let n = 240;
        let runs = (0..8)
            .map(|r| {
                let t_s: Vec<f64> = (0..n).map(|i| 10.0 * f64::from(i)).collect();
                let temp_c: Vec<f64> = t_s
                    .iter()
                    .map(|t| 10.0 * f64::from(r % 4) + 8.0 * (1.0 - (-t / 600.0).exp()))
                    .collect();
                let mut wander = |period_s: f64, phase: f64| -> Vec<f64> {
                    t_s.iter()
                        .map(|t| (t / period_s + phase + f64::from(r)).sin() + 0.3 * next())
                        .collect::<Vec<f64>>()
                };
                let a = wander(300.0, 0.0);
                let b = wander(470.0, 1.0);
                let u = wander(650.0, 2.0);
                let v = wander(830.0, 3.0);
                let copy = |x: &[f64], next: &mut dyn FnMut() -> f64| -> Vec<f64> {
                    x.iter().map(|v| v + 0.1 * next()).collect()
                };
                let (a2, b2) = (copy(&a, &mut next), copy(&b, &mut next));
                let drift_dph = a
                    .iter()
                    .zip(&b)
                    .map(|(x, y)| 0.01 * x * y + 0.001 * next())
                    .collect();
                Series {
                    name: format!("run{r}"),
                    ambient_c: None,
                    latitude_deg: None,
                    drift_dph,
                    t_s,
                    temp_c,
                    extras: vec![a, b, u, v, a2, b2],
                }
            })
            .collect();
        Campaign {
            runs,
            extra_names: ["a", "b", "u", "v", "a2", "b2"].map(String::from).to_vec(),
            exclusions: vec![],
            derivative_widths: vec![],
        }
    }

    #[test]
    fn a_planted_product_is_kept_an_unrelated_one_is_screened_out_and_counted() {
        let c = campaign();
        let (folds, st, choice) = layout_and_base(&c, BufferRule::default()).unwrap();
        let (built, _) = library_of(&c, &[], &st, &folds, &choice.chosen);
        let kept: Vec<String> = built
            .candidates
            .iter()
            .filter(|c| OperatorFamily::of(c) == OperatorFamily::PairProduct)
            .map(Candidate::label)
            .collect();
        // 15 pairs; the four of {a, a2} x {b, b2} carry the planted product
        assert_eq!(kept.len(), PAIR_BUDGET, "{kept:?}");
        assert!(kept.contains(&"a:value*b".to_owned()), "{kept:?}");
        assert!(!kept.contains(&"u:value*v".to_owned()), "{kept:?}");
        let screening = Screening {
            scored: vec![],
            skipped: vec![],
            steps: vec![],
        };
        let family = rows(&Inputs {
            built: &built,
            screening: &screening,
            smallest_attainable_p: 0.0,
            silent: false,
            power_check: None,
        })
        .into_iter()
        .find(|r| r.family == "pairwise products")
        .expect("the family has a row");
        assert_eq!(family.candidates, PAIR_BUDGET);
        assert!(
            family.why_cut.iter().any(|w| w.contains("4 of 15")),
            "{:?}",
            family.why_cut
        );
        // the planted product scores far above the unrelated one (whose sinusoids, over
        // eight runs, share a few per cent of the planted one by chance)
        let planted = built
            .candidates
            .iter()
            .find(|c| c.label() == "a:value*b")
            .unwrap()
            .clone();
        let mean_of = |i: usize| {
            let pooled: Vec<f64> = c.runs.iter().flat_map(|s| s.extras[i].clone()).collect();
            crate::stats::mean_or_zero(&pooled)
        };
        let unrelated = Candidate {
            column: "u".into(),
            source: crate::diagnose::candidates::transforms::Source::Extra(2),
            centres: (mean_of(2), planted.centres.1),
            partner: Some(Partner {
                index: 3,
                column: "v".into(),
                centre: mean_of(3),
            }),
            ..planted.clone()
        };
        assert_eq!(unrelated.label(), "u:value*v");
        let s = pair_scores(&c, &folds, &choice.chosen, &[planted, unrelated]);
        let (p, u) = (s[0].unwrap(), s[1].unwrap());
        assert!(p > 10.0 * u, "planted {p}, unrelated {u}");
    }
}
