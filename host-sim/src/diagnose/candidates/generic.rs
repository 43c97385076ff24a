//! The generic candidate library (issue 18 item 2): built from the record's own columns and
//! metadata, never from a list of expected effects. For every extra column: its value,
//! natural cubic splines of it (4, 6, 10, 16, 25 and 40 knots at equally spaced campaign
//! quantiles, so they are densest where the column's range is best covered; a count is
//! offered only where every interval between its knots holds rows of at least
//! `MIN_UNITS_BETWEEN_KNOTS` validation units, so the held-out test can check a feature
//! there; which count, if any, is chosen on held-out data by the selection), d/dt and
//! d2/dt2 (windows validated per column), its memory (first-order lags), its hysteresis
//! (stop operators on a ladder of play widths, `hysteresis`) when it has many values,
//! levels when it has few, a sinusoid for angles (`*_deg`), and products of its value (or
//! levels) with the base's inputs (T - mean T, dT/dt). For the temperature: d2/dt2, memory
//! and hysteresis (its value and dT/dt are the base's inputs). For time since the start: a
//! power-on decay on the same time scales. Metadata keys that vary between runs enter as
//! run-constant columns (`metadata`: numbers, times as days, versions by rank, categories;
//! their products with the base's inputs are within-run candidates; their values and levels
//! are run-level candidates, `between_runs`). Last, event clocks (`events`): a decay after
//! each step of every column (the temperature too) and after each gap of the time stamps.
//! Last of all, products of the values of any two extra columns (issue 38 item 2, `pairs`):
//! all k(k-1)/2 are scored once against the base (the sum over runs of each one's squared
//! per-run score, which whole-run sign flips leave unchanged, so the naming test keeps its
//! level) and only the `pairs::PAIR_BUDGET` (4) strongest enter; the rest are named in the
//! family's note. The newest families come last so that the cap, when it bites, cuts them
//! before the older families (the report says so per family).
//!
//! Memory time scales are the record's: from twice the row spacing, doubling, to half the
//! shortest run. The size is bounded: at most `MAX_CANDIDATES` (the rest are skipped and
//! reported as such); 20 to 30 per column, and at most `pairs::PAIR_BUDGET` products of two
//! columns whatever their number.

use crate::diagnose::candidates::events;
use crate::diagnose::candidates::families::{FamilyNote, OperatorFamily};
use crate::diagnose::candidates::hysteresis;
use crate::diagnose::candidates::metadata::{MetaColumn, MetaKind, MAX_LEVELS};
use crate::diagnose::candidates::pairs;
use crate::diagnose::candidates::transforms::{BaseInput, Candidate, Source, Transform};
use crate::diagnose::input::Campaign;
use crate::stats::mean_or_zero;
use std::ops::Range;

/// Cap on the library's size (the rest are reported as skipped).
pub const MAX_CANDIDATES: usize = 400;
/// Knot counts of the natural splines, sparsest first: from Harrell's 4 and 6 (a smooth
/// law over the whole range) to 40 (a feature a fortieth of the covered range wide), each
/// about 1.6 times the last.
pub const SPLINE_KNOT_COUNTS: [usize; 6] = [4, 6, 10, 16, 25, 40];
/// The outer knots' quantiles (Harrell's placement; the inner ones equally spaced).
pub const OUTER_KNOT_QUANTILES: (f64, f64) = (0.05, 0.95);
/// Fewest validation units (runs, or time blocks of a single record) whose rows must fall
/// between every two neighbouring knots for a knot count to be offered: a narrow feature
/// seen in one or two units cannot be told from those units' own drift by a held-out test.
pub const MIN_UNITS_BETWEEN_KNOTS: usize = 3;
/// Longest memory time scale, as a fraction of the shortest run.
pub const LONGEST_TAU_FRACTION: f64 = 0.5;

/// Share of the rows the levels must cover (window means of a switching column fall
/// between its levels where it switched within the window).
pub const LEVEL_COVERAGE: f64 = 0.9;

/// The column's levels (sorted) when at most `MAX_LEVELS` values, each on at least 1 %
/// of the rows, cover `LEVEL_COVERAGE` of them; else `None`.
pub fn few_levels(v: impl Iterator<Item = f64>) -> Option<Vec<f64>> {
    let mut sorted: Vec<f64> = v.collect();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let mut runs: Vec<(f64, usize)> = Vec::new();
    for x in &sorted {
        match runs.last_mut() {
            Some((v, c)) if *v == *x => *c += 1,
            _ => runs.push((*x, 1)),
        }
    }
    let mut frequent: Vec<(f64, usize)> = runs.into_iter().filter(|(_, c)| *c * 100 >= n).collect();
    frequent.sort_by_key(|f| std::cmp::Reverse(f.1));
    frequent.truncate(MAX_LEVELS);
    let covered: usize = frequent.iter().map(|(_, c)| c).sum();
    let mut levels: Vec<f64> = frequent.into_iter().map(|(v, _)| v).collect();
    levels.sort_by(f64::total_cmp);
    (levels.len() >= 2 && covered as f64 >= LEVEL_COVERAGE * n as f64).then_some(levels)
}

/// The levels to indicate: all but the most common one (the reference).
fn indicated_levels(levels: &[f64], values: impl Iterator<Item = f64> + Clone) -> Vec<f64> {
    let count = |l: f64| values.clone().filter(|v| *v == l).count();
    let reference = levels
        .iter()
        .copied()
        .max_by_key(|l| count(*l))
        .unwrap_or(f64::NAN);
    levels.iter().copied().filter(|l| *l != reference).collect()
}

/// Memory time scales the record supports, s.
pub fn memory_taus_s(c: &Campaign) -> Vec<f64> {
    let spacing = c
        .runs
        .iter()
        .filter_map(|s| {
            let n = s.t_s.len();
            (n > 1).then(|| (s.t_s[n - 1] - s.t_s[0]) / (n - 1) as f64)
        })
        .fold(f64::INFINITY, f64::min);
    let shortest = c
        .runs
        .iter()
        .map(|s| s.t_s.last().unwrap_or(&0.0) - s.t_s.first().unwrap_or(&0.0))
        .fold(f64::INFINITY, f64::min);
    let mut out = Vec::new();
    if !spacing.is_finite() || spacing <= 0.0 {
        return out;
    }
    let mut tau = 2.0 * spacing;
    while tau <= LONGEST_TAU_FRACTION * shortest {
        out.push(tau);
        tau *= 2.0;
    }
    out
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    let pos = q * (sorted.len().saturating_sub(1)) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (pos - lo as f64) * (sorted[hi] - sorted[lo])
}

/// `count` knots at equally spaced quantiles of the pooled values (`OUTER_KNOT_QUANTILES`
/// at the ends), when they are distinct.
fn knots_at(sorted: &[f64], count: usize) -> Option<Vec<f64>> {
    let (lo, hi) = OUTER_KNOT_QUANTILES;
    let step = (hi - lo) / (count.max(2) - 1) as f64;
    let k: Vec<f64> = (0..count)
        .map(|j| quantile(sorted, lo + step * j as f64))
        .collect();
    k.windows(2).all(|w| w[1] > w[0]).then_some(k)
}

/// How many of the intervals between neighbouring `knots` hold rows of fewer than
/// `MIN_UNITS_BETWEEN_KNOTS` of the validation units (`unit_rows` of the stacked column
/// `x`; all of them when there are fewer units).
fn thin_intervals(x: &[f64], unit_rows: &[Range<usize>], knots: &[f64]) -> usize {
    let need = MIN_UNITS_BETWEEN_KNOTS.min(unit_rows.len());
    let intervals = knots.len().saturating_sub(1);
    let mut seen = vec![0usize; intervals];
    for rows in unit_rows {
        let mut here = vec![false; intervals];
        for v in x.get(rows.clone()).unwrap_or(&[]) {
            // interval j holds knots[j] <= v < knots[j + 1] (the last one includes its end)
            let j = knots.partition_point(|k| k <= v);
            if (1..=intervals).contains(&j) {
                here[j - 1] = true;
            } else if j > intervals && *v == knots[intervals] {
                here[intervals - 1] = true;
            }
        }
        seen.iter_mut()
            .zip(here)
            .for_each(|(s, h)| *s += usize::from(h));
    }
    seen.iter().filter(|s| **s < need).count()
}

/// The built library: its candidates, in a fixed order, and what was left out.
#[derive(Clone, Debug)]
pub struct Built {
    pub candidates: Vec<Candidate>,
    /// The families of the candidates the cap left out, in library order.
    pub cut_by_cap: Vec<OperatorFamily>,
    /// Columns a family offers nothing for, and why.
    pub notes: Vec<FamilyNote>,
}

/// The whole library: within-run candidates of every column and of the run-constant
/// metadata (products only), then the event clocks, in a fixed order; what the cap left
/// out and why a column has no event clock.
/// The pairwise products go through `keep_pairs` (the screen, `pairs::screened`) and
/// come last. `unit_rows` are the validation units' rows of the stacked campaign (which
/// spline knot counts the record covers).
pub fn enumerate(
    c: &Campaign,
    meta: &[MetaColumn],
    base_rate_half_s: f64,
    unit_rows: &[Range<usize>],
    keep_pairs: &KeepPairs,
) -> Built {
    let temps: Vec<f64> = c
        .runs
        .iter()
        .flat_map(|s| s.temp_c.iter().copied())
        .collect();
    let temp_mean = mean_or_zero(&temps);
    let blank = |column: &str, source, transform| Candidate {
        column: column.to_owned(),
        source,
        transform,
        tau_s: None,
        half_s: match transform {
            Transform::Rate => Some(c.half_width_s(column, 1)),
            Transform::Accel => Some(c.half_width_s(column, 2)),
            _ => None,
        },
        knots: vec![],
        levels: vec![],
        times: None,
        partner: None,
        centres: (0.0, temp_mean),
        base_rate_half_s,
        run_values: vec![],
        event: None,
        width: None,
    };
    let taus = memory_taus_s(c);
    let mut out = Vec::new();
    for &tau in &taus {
        out.push(Candidate {
            tau_s: Some(tau),
            ..blank("t_s", Source::Time, Transform::Decay)
        });
    }
    out.push(blank("temp_c", Source::Temp, Transform::Accel));
    for &tau in &taus {
        out.push(Candidate {
            tau_s: Some(tau),
            ..blank("temp_c", Source::Temp, Transform::Lag)
        });
    }
    let mut notes = Vec::new();
    out.extend(hysteresis_of(c, "temp_c", Source::Temp, &blank, &mut notes));
    for (i, name) in c.extra_names.iter().enumerate() {
        out.extend(column_candidates(
            c, i, name, &taus, unit_rows, &blank, &mut notes,
        ));
    }
    out.extend(metadata_products(meta, &blank));
    out.extend(event_clocks(c, &taus, &blank, &mut notes));
    let (pairs, pair_note) = keep_pairs(pairs::all_pairs(c, &|i| centred_value(c, i, &blank)));
    out.extend(pairs);
    notes.extend(pair_note);
    let cut_by_cap = out
        .iter()
        .skip(MAX_CANDIDATES)
        .map(OperatorFamily::of)
        .collect();
    out.truncate(MAX_CANDIDATES);
    Built {
        candidates: out,
        cut_by_cap,
        notes,
    }
}

/// A decay on every memory time scale after the events of the temperature, of every extra
/// column and of the time stamps' gaps; a column without usable events gets a note.
fn event_clocks(
    c: &Campaign,
    taus: &[f64],
    blank: &Blank,
    notes: &mut Vec<FamilyNote>,
) -> Vec<Candidate> {
    let mut rules: Vec<(String, Source, Result<events::EventRule, String>)> = vec![
        ("t_s".into(), Source::Time, events::gap_rule(c)),
        (
            "temp_c".into(),
            Source::Temp,
            events::step_rule(c, |s| &s.temp_c),
        ),
    ];
    for (i, name) in c.extra_names.iter().enumerate() {
        rules.push((
            name.clone(),
            Source::Extra(i),
            events::step_rule(c, |s| &s.extras[i]),
        ));
    }
    let mut out = Vec::new();
    for (name, src, rule) in rules {
        match rule {
            Ok(rule) => out.extend(taus.iter().map(|&tau| Candidate {
                tau_s: Some(tau),
                event: Some(rule),
                ..blank(&name, src, Transform::Event)
            })),
            Err(why) => notes.push(FamilyNote {
                family: OperatorFamily::EventClock,
                note: format!("{name}: {why}"),
            }),
        }
    }
    out
}

/// Builds a candidate of `column` under `transform` with every other field at its default.
type Blank<'a> = dyn Fn(&str, Source, Transform) -> Candidate + 'a;

/// The screen of the pairwise products: the products kept and a note on the rest.
pub type KeepPairs<'a> = dyn Fn(Vec<Candidate>) -> (Vec<Candidate>, Option<FamilyNote>) + 'a;

/// The value of extra column `i` with its campaign mean as the centre of its products.
fn centred_value(c: &Campaign, i: usize, blank: &Blank) -> Candidate {
    let name = &c.extra_names[i];
    let pooled: Vec<f64> = c
        .runs
        .iter()
        .flat_map(|s| s.extras[i].iter().copied())
        .collect();
    let own = blank(name, Source::Extra(i), Transform::Value);
    Candidate {
        centres: (mean_or_zero(&pooled), own.centres.1),
        ..own
    }
}

/// Every within-run candidate of extra column `i` (`name`); a note for the spline knot
/// counts the record does not cover.
fn column_candidates(
    c: &Campaign,
    i: usize,
    name: &str,
    taus: &[f64],
    unit_rows: &[Range<usize>],
    blank: &Blank,
    notes: &mut Vec<FamilyNote>,
) -> Vec<Candidate> {
    let mut out = Vec::new();
    let src = Source::Extra(i);
    let pooled: Vec<f64> = c
        .runs
        .iter()
        .flat_map(|s| s.extras[i].iter().copied())
        .collect();
    for tr in [Transform::Value, Transform::Rate, Transform::Accel] {
        out.push(blank(name, src, tr));
    }
    if name.ends_with("_deg") {
        out.push(blank(name, src, Transform::Harmonic));
    }
    let levels = few_levels(pooled.iter().copied());
    let own = match &levels {
        Some(l) => Candidate {
            knots: indicated_levels(l, pooled.iter().copied()),
            levels: l.clone(),
            ..blank(name, src, Transform::Levels)
        },
        None => centred_value(c, i, blank),
    };
    if levels.is_some() {
        out.push(own.clone());
    } else {
        let mut sorted = pooled.clone();
        sorted.sort_by(f64::total_cmp);
        for count in SPLINE_KNOT_COUNTS {
            let Some(knots) = knots_at(&sorted, count) else {
                continue;
            };
            let thin = thin_intervals(&pooled, unit_rows, &knots);
            if thin > 0 {
                notes.push(FamilyNote {
                    family: OperatorFamily::Smooth,
                    note: format!(
                        "{name}: {count} knots not offered ({thin} of {} intervals between \
                         them seen in fewer than {} validation units)",
                        count - 1,
                        MIN_UNITS_BETWEEN_KNOTS.min(unit_rows.len())
                    ),
                });
                break;
            }
            out.push(Candidate {
                knots,
                ..blank(name, src, Transform::Spline)
            });
        }
    }
    for &tau in taus {
        out.push(Candidate {
            tau_s: Some(tau),
            ..blank(name, src, Transform::Lag)
        });
    }
    if levels.is_none() {
        out.extend(hysteresis_of(c, name, src, blank, notes));
    }
    for b in [BaseInput::Temp, BaseInput::TempRate] {
        out.push(Candidate {
            times: Some(b),
            ..own.clone()
        });
    }
    out
}

/// The stop operator of a many-valued column on every play width its record supports
/// (`hysteresis`); a note when it supports none.
fn hysteresis_of(
    c: &Campaign,
    name: &str,
    src: Source,
    blank: &Blank,
    notes: &mut Vec<FamilyNote>,
) -> Vec<Candidate> {
    match hysteresis::widths(c, |s| src.of(s).unwrap_or(&[])) {
        Ok(w) => w
            .into_iter()
            .map(|h| Candidate {
                width: Some(h),
                ..blank(name, src, Transform::Hysteresis)
            })
            .collect(),
        Err(why) => {
            notes.push(FamilyNote {
                family: OperatorFamily::Hysteresis,
                note: format!("{name}: {why}"),
            });
            vec![]
        }
    }
}

/// Products of every run-constant metadata column (its value, or its levels) with the
/// base's inputs.
fn metadata_products(meta: &[MetaColumn], blank: &Blank) -> Vec<Candidate> {
    let temp_mean = blank("temp_c", Source::Temp, Transform::Value).centres.1;
    let mut out = Vec::new();
    for m in meta {
        let levels = if m.kind == MetaKind::Category {
            few_levels(m.run_values.iter().copied())
        } else {
            None
        };
        let own = match levels {
            Some(l) => Candidate {
                knots: indicated_levels(&l, m.run_values.iter().copied()),
                levels: l,
                run_values: m.run_values.clone(),
                ..blank(&m.key, Source::Meta, Transform::Levels)
            },
            None => Candidate {
                centres: (mean_or_zero(&m.run_values), temp_mean),
                run_values: m.run_values.clone(),
                ..blank(&m.key, Source::Meta, Transform::Value)
            },
        };
        for b in [BaseInput::Temp, BaseInput::TempRate] {
            out.push(Candidate {
                times: Some(b),
                ..own.clone()
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::candidates::transforms::level_weight;

    #[test]
    fn levels_are_found_only_for_few_values_and_the_reference_is_the_commonest() {
        let v = [1.0, 2.0, 2.0, 3.0, 2.0];
        let l = few_levels(v.iter().copied()).unwrap();
        assert_eq!(l, vec![1.0, 2.0, 3.0]);
        assert_eq!(indicated_levels(&l, v.iter().copied()), vec![1.0, 3.0]);
        assert!(few_levels((0..10).map(f64::from)).is_none());
        assert!(few_levels([4.0, 4.0].into_iter()).is_none());
        // a few window means between levels do not hide them
        let mut m: Vec<f64> = (0..200).map(|i| f64::from(i % 2)).collect();
        m.push(0.3);
        assert_eq!(few_levels(m.into_iter()).unwrap(), vec![0.0, 1.0]);
        let l = [0.0, 1.0, 2.0];
        assert_eq!(level_weight(0.25, 0.0, &l), 0.75);
        assert_eq!(level_weight(0.25, 1.0, &l), 0.25);
        assert_eq!(level_weight(0.25, 2.0, &l), 0.0);
    }

    #[test]
    fn knots_need_distinct_quantiles() {
        let v: Vec<f64> = (0..101).map(f64::from).collect();
        let k = knots_at(&v, 4).unwrap();
        for (k, want) in k.iter().zip([5.0, 35.0, 65.0, 95.0]) {
            assert!((k - want).abs() < 1e-9, "{k} against {want}");
        }
        assert_eq!(knots_at(&v, 16).unwrap().len(), 16);
        assert!(knots_at(&[1.0; 50], 4).is_none());
    }

    #[test]
    fn a_knot_count_needs_every_interval_seen_in_enough_units() {
        // three units over 0..=9, a fourth only over 0..=4: every interval of 4 knots
        // is seen by three units or more
        let mut x: Vec<f64> = Vec::new();
        let mut rows = Vec::new();
        for hi in [9, 9, 9, 4] {
            let start = x.len();
            x.extend((0..=hi).map(f64::from));
            rows.push(start..x.len());
        }
        assert_eq!(thin_intervals(&x, &rows, &[0.5, 3.5, 6.5, 9.0]), 0);
        // one unit alone covers 10..=12: the interval reaching there is thin
        let start = x.len();
        x.extend([10.0, 11.0, 12.0]);
        rows.push(start..x.len());
        assert_eq!(thin_intervals(&x, &rows, &[0.5, 3.5, 9.5, 12.0]), 1);
        // a single unit (one record's validation) needs only itself
        assert_eq!(thin_intervals(&x, &rows[4..], &[10.0, 11.0, 12.0]), 0);
    }
}
