//! Competing explanations (issue 18 item 5): when a candidate of another column is within
//! one standard error of a named cause on held-out data, look for the units (runs, or
//! time blocks) where the two disagree and let those decide.
//!
//! Overall the two explain the data equally well, but that can hide a few units where
//! they predict different things (a warm restart keeps the electronics' power-on decay but
//! has little d2T/dt2). Nothing here knows any pair: the disagreement of a unit is the rms
//! over its rows of the difference between the two models' held-out predictions (base +
//! causes named so far + one or the other), which is computed without that unit's data,
//! so choosing the units on it does not peek at the errors they are then judged on. The
//! separating units are the most disagreeing ones that hold [`SEPARATING_SHARE`] of the
//! total squared disagreement (at least as many as the sign-flip test needs to reach
//! [`ALPHA`]). On them the per-unit held-out squared errors are compared with a
//! two-sided paired sign-flip test, Bonferroni over the step's competitors: a
//! significant winner is named (the rival replaces the named cause if it wins) and the
//! loser is reported as separated; otherwise both stay, "not distinguishable on this
//! data", with the units where they differ most, which is where more data would decide.

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::validation::cv::CvResult;
use crate::diagnose::validation::folds::Folds;
use crate::diagnose::validation::signflip::{paired_pvalue, smallest_p, FLIP_SEED};

use super::scored::{Scored, ALPHA};

/// Share of the total squared disagreement the separating units must hold.
pub const SEPARATING_SHARE: f64 = 0.8;

/// What the separating units said about a named cause and one competitor.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// One of the two is significantly better where they differ; `rival_won` when the
    /// former competitor is the better one (it is then named instead).
    Separated { rival_won: bool },
    /// Neither is significantly better on the units where they differ.
    NotDistinguishable,
    /// Too few units for the test to reach `ALPHA`.
    NoTestPower,
}

/// The outcome of one separation test.
#[derive(Clone, Debug)]
pub struct Separation {
    pub verdict: Verdict,
    /// The separating units (indices into `Folds::unit_rows`), most disagreeing first.
    pub units: Vec<usize>,
    /// Rms disagreement of each separating unit, deg/h (same order).
    pub disagreement_dph: Vec<f64>,
    /// Largest rms disagreement among the other units, deg/h (0 when none).
    pub rest_disagreement_dph: f64,
    /// Held-out rms gain of the better of the two over the worse on the separating
    /// units, %.
    pub gain_pct: f64,
    /// Two-sided sign-flip p on the separating units, x the step's competitors.
    pub p_value: f64,
}

/// The two models' held-out results: the named one's and the rival's.
pub struct Pair<'a> {
    pub named: &'a CvResult,
    pub rival: &'a CvResult,
}

/// Tests one named cause against one competitor (`tests`: how many competitors share
/// the step's Bonferroni correction).
pub fn separate(folds: &Folds, pair: &Pair, tests: usize) -> Separation {
    let per_unit: Vec<f64> = folds
        .unit_rows
        .iter()
        .map(|r| {
            let ss: f64 = pair.named.residual[r.clone()]
                .iter()
                .zip(&pair.rival.residual[r.clone()])
                .map(|(a, b)| (a - b) * (a - b))
                .sum();
            (ss / r.len().max(1) as f64).sqrt()
        })
        .collect();
    let units = separating_units(&per_unit);
    let rest_disagreement_dph = (0..per_unit.len())
        .filter(|u| !units.contains(u))
        .map(|u| per_unit[u])
        .fold(0.0, f64::max);
    // per-unit drop in held-out squared error, rival -> named (positive: named better)
    let named_better: Vec<f64> = units
        .iter()
        .map(|&u| pair.rival.unit_sse[u] - pair.named.unit_sse[u])
        .collect();
    let flipped: Vec<f64> = named_better.iter().map(|d| -d).collect();
    let one_sided = paired_pvalue(&named_better, FLIP_SEED).min(paired_pvalue(&flipped, FLIP_SEED));
    let p_value = (2.0 * one_sided * tests.max(1) as f64).min(1.0);
    let (sse_named, sse_rival) = units.iter().fold((0.0, 0.0), |(a, b), &u| {
        (a + pair.named.unit_sse[u], b + pair.rival.unit_sse[u])
    });
    let rival_won = sse_rival < sse_named;
    let (better, worse) = if rival_won {
        (sse_rival, sse_named)
    } else {
        (sse_named, sse_rival)
    };
    let gain_pct = 100.0 * (1.0 - (better / worse.max(1e-300)).sqrt());
    let reachable = 2.0 * smallest_p(units.len()) * (tests.max(1) as f64) < ALPHA;
    let verdict = if p_value < ALPHA {
        Verdict::Separated { rival_won }
    } else if !reachable {
        Verdict::NoTestPower
    } else {
        Verdict::NotDistinguishable
    };
    Separation {
        verdict,
        disagreement_dph: units.iter().map(|&u| per_unit[u]).collect(),
        units,
        rest_disagreement_dph,
        gain_pct,
        p_value,
    }
}

/// The most disagreeing units holding [`SEPARATING_SHARE`] of the squared disagreement,
/// extended to the fewest the two-sided test needs to reach `ALPHA` (or all units).
pub fn separating_units(disagreement: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..disagreement.len()).collect();
    order.sort_by(|a, b| disagreement[*b].total_cmp(&disagreement[*a]).then(a.cmp(b)));
    let total: f64 = disagreement.iter().map(|d| d * d).sum();
    let mut held = 0.0;
    let mut take = 0;
    for &u in &order {
        if held >= SEPARATING_SHARE * total && take > 0 {
            break;
        }
        held += disagreement[u] * disagreement[u];
        take += 1;
    }
    let needed = (1..=order.len())
        .find(|m| 2.0 * smallest_p(*m) < ALPHA)
        .unwrap_or(order.len());
    order.truncate(take.max(needed));
    order
}

/// Held-out results of the base plus `model_cols` plus each of the two candidates'
/// columns (the named one's first).
pub fn refit_pair(
    folds: &Folds,
    base: &BaseFit,
    model_cols: &[Vec<f64>],
    named_cols: &[Vec<f64>],
    rival_cols: &[Vec<f64>],
) -> Result<(CvResult, CvResult), DiagnoseError> {
    let with = |cols: &[Vec<f64>]| {
        let mut all = model_cols.to_vec();
        all.extend(cols.iter().cloned());
        base.prepared.validate_with(folds, &all)
    };
    Ok((with(named_cols)?, with(rival_cols)?))
}

/// The scored candidate with `label` (a competitor's), if any.
pub fn find(scored: &[Scored], label: &str) -> Option<usize> {
    scored.iter().position(|s| s.cand.label() == label)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_separating_units_hold_most_of_the_disagreement_and_enough_for_the_test() {
        // 3 units disagree, 9 barely: the 3 hold > 80 %, but a two-sided test at 0.01
        // needs 8 units (2 / 2^8 < 0.01), so the 5 next most disagreeing join them.
        let mut d = vec![0.01; 12];
        d[2] = 1.0;
        d[5] = 0.9;
        d[9] = 0.8;
        d[7] = 0.02;
        let u = separating_units(&d);
        assert_eq!(&u[..4], &[2, 5, 9, 7]);
        assert_eq!(u.len(), 8);
        // when every unit disagrees alike, most of them are needed
        let flat = vec![1.0; 20];
        assert_eq!(separating_units(&flat).len(), 16);
    }

    fn cv(folds: &Folds, residual: Vec<f64>) -> CvResult {
        let unit_sse = folds
            .unit_rows
            .iter()
            .map(|r| residual[r.clone()].iter().map(|v| v * v).sum())
            .collect();
        CvResult {
            unit_sse,
            points: residual.len(),
            residual,
        }
    }

    fn noise(n: usize) -> Vec<f64> {
        (0..n).map(|i| (i as f64 * 1.618).sin() * 0.1).collect()
    }

    #[test]
    fn the_units_where_two_candidates_differ_decide_between_them() {
        let folds = Folds::new(&[10; 12]).unwrap();
        let named = noise(120);
        // the same predictions in runs 0-3 ("cold starts"), the rival off by 0.05 in
        // runs 4-11 ("warm restarts"): named on the units where they differ
        let rival: Vec<f64> = named
            .iter()
            .enumerate()
            .map(|(i, v)| if i >= 40 { v + 0.05 } else { *v })
            .collect();
        let (a, b) = (cv(&folds, named.clone()), cv(&folds, rival));
        let s = separate(
            &folds,
            &Pair {
                named: &a,
                rival: &b,
            },
            1,
        );
        assert_eq!(s.verdict, Verdict::Separated { rival_won: false }, "{s:?}");
        assert!(s.units.iter().all(|u| *u >= 4), "{:?}", s.units);
        assert!(s.gain_pct > 0.0 && s.p_value < ALPHA, "{s:?}");
        // the same test with the roles swapped names the other one
        let s = separate(
            &folds,
            &Pair {
                named: &b,
                rival: &a,
            },
            1,
        );
        assert_eq!(s.verdict, Verdict::Separated { rival_won: true });
        // predictions apart, errors alike: mirror images of the residual per unit
        let mirror: Vec<f64> = named.iter().map(|v| -v).collect();
        let c = cv(&folds, mirror);
        let s = separate(
            &folds,
            &Pair {
                named: &a,
                rival: &c,
            },
            1,
        );
        assert_eq!(s.verdict, Verdict::NotDistinguishable, "{s:?}");
        // 5 runs cannot reach 0.01 two-sided
        let few = Folds::new(&[10; 5]).unwrap();
        let (a, b) = (
            cv(&few, named[..50].to_vec()),
            cv(&few, named[..50].iter().map(|v| v + 0.05).collect()),
        );
        let s = separate(
            &few,
            &Pair {
                named: &a,
                rival: &b,
            },
            1,
        );
        assert_eq!(s.verdict, Verdict::NoTestPower, "{s:?}");
    }
}
