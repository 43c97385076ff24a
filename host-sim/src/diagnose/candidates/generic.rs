//! The generic candidate library (issue 18 item 2): built from the record's own columns
//! and metadata, never from a list of expected effects. For every extra column: its value,
//! a natural cubic spline of it (4 and 6 knots at campaign quantiles; which one, if any,
//! is chosen on held-out data by the selection), d/dt and d2/dt2 (windows validated per
//! column), its memory (first-order lags), levels when it has few distinct values, a
//! sinusoid for angles (`*_deg`), and products of its value (or levels) with the base's
//! inputs (T - mean T, dT/dt). For the temperature: d2/dt2 and memory (its value and
//! dT/dt are the base's inputs). For time since the start: a power-on decay on the same
//! time scales. Metadata keys that vary between runs enter as run-constant columns
//! (`metadata`: numbers, times as days, versions by rank, categories; their products with
//! the base's inputs are within-run candidates; their values and levels are run-level
//! candidates, `between_runs`). Last, event clocks (`events`): a decay after each step of
//! every column (the temperature too) and after each gap of the time stamps. Last of all,
//! products of the values of any two extra columns (issue 38 item 2, `pairs`): all
//! k(k-1)/2 are scored once against the base (the sum over runs of each one's squared
//! per-run score, which whole-run sign flips leave unchanged, so the naming test keeps its
//! level) and only the `pairs::PAIR_BUDGET` (4) strongest enter; the rest are named in the
//! family's note. The newest families come last so that the cap, when it bites, cuts them
//! before the older families (the report says so per family).
//!
//! Memory time scales are the record's: from twice the row spacing, doubling, to half the
//! shortest run. The size is bounded: at most `MAX_CANDIDATES` (the rest are skipped and
//! reported as such); about 20 per column, and at most `pairs::PAIR_BUDGET` products of
//! two columns whatever their number.

use crate::diagnose::candidates::events;
use crate::diagnose::candidates::families::{FamilyNote, OperatorFamily};
use crate::diagnose::candidates::metadata::{MetaColumn, MetaKind, MAX_LEVELS};
use crate::diagnose::candidates::pairs;
use crate::diagnose::candidates::transforms::{BaseInput, Candidate, Source, Transform};
use crate::diagnose::input::Campaign;
use crate::stats::mean_or_zero;

/// Cap on the library's size (the rest are reported as skipped).
pub const MAX_CANDIDATES: usize = 400;
/// Knot counts of the natural splines (Harrell's quantile placements).
pub const SPLINE_KNOTS: [&[f64]; 2] = [
    &[0.05, 0.35, 0.65, 0.95],
    &[0.05, 0.23, 0.41, 0.59, 0.77, 0.95],
];
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

/// Knots at `qs` of the pooled values, when they are distinct.
fn knots_at(sorted: &[f64], qs: &[f64]) -> Option<Vec<f64>> {
    let k: Vec<f64> = qs.iter().map(|q| quantile(sorted, *q)).collect();
    k.windows(2).all(|w| w[1] > w[0]).then_some(k)
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
/// come last.
pub fn enumerate(
    c: &Campaign,
    meta: &[MetaColumn],
    base_rate_half_s: f64,
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
    for (i, name) in c.extra_names.iter().enumerate() {
        out.extend(column_candidates(c, i, name, &taus, &blank));
    }
    out.extend(metadata_products(meta, &blank));
    let mut notes = Vec::new();
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

/// Every within-run candidate of extra column `i` (`name`).
fn column_candidates(
    c: &Campaign,
    i: usize,
    name: &str,
    taus: &[f64],
    blank: &Blank,
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
        for qs in SPLINE_KNOTS {
            if let Some(knots) = knots_at(&sorted, qs) {
                out.push(Candidate {
                    knots,
                    ..blank(name, src, Transform::Spline)
                });
            }
        }
    }
    for &tau in taus {
        out.push(Candidate {
            tau_s: Some(tau),
            ..blank(name, src, Transform::Lag)
        });
    }
    for b in [BaseInput::Temp, BaseInput::TempRate] {
        out.push(Candidate {
            times: Some(b),
            ..own.clone()
        });
    }
    out
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
        assert_eq!(
            knots_at(&v, SPLINE_KNOTS[0]).unwrap(),
            vec![5.0, 35.0, 65.0, 95.0]
        );
        assert!(knots_at(&[1.0; 50], SPLINE_KNOTS[0]).is_none());
    }
}
