//! Competing explanations in the report (issue 18 item 5): each competitor of a named
//! cause with what the units where the two disagree said (`selection::separate`), in
//! fields and in one sentence: separated (which one lost, where, by how much, p), or not
//! distinguishable on this data (and which units would decide), or no test power.

use crate::diagnose::selection::scored::ALPHA;
use crate::diagnose::selection::screen::Rival;
use crate::diagnose::selection::separate::Verdict;
use crate::diagnose::validation::folds::Folds;
use serde::Serialize;

/// A candidate the held-out data could not tell from a named cause over all units
/// (within one standard error of it), and the test on the units where they differ.
#[derive(Clone, Debug, Serialize)]
pub struct Competitor {
    pub candidate: String,
    /// The named cause it competes with.
    pub named: String,
    /// Its held-out gain at the step the named cause was chosen, %.
    pub conditional_gain_pct: f64,
    /// Its held-out squared-error excess over the named cause, standard errors (< 1;
    /// negative when it had the lower error overall but lost where they differ).
    pub gap_se: f64,
    /// `separated` (the candidate is rejected), `not distinguishable` or `no test power`.
    pub verdict: &'static str,
    /// The units (runs, or time blocks) where the two disagree most, most first.
    pub separating_units: Vec<String>,
    /// Rms difference of the two models' held-out predictions on those units, deg/h.
    pub disagreement_dph: Vec<f64>,
    /// Held-out rms gain of the better of the two over the other on those units, %.
    pub separation_gain_pct: f64,
    /// Two-sided paired sign-flip p on those units (x the step's competitors).
    pub separation_p: f64,
    pub in_words: String,
}

/// The report's line for competitor `r` of the cause `named`; `unit_names` name the
/// validation units.
pub fn competitor(named: &str, r: &Rival, unit_names: &[String]) -> Competitor {
    let sep = &r.separation;
    let names: Vec<String> = sep
        .units
        .iter()
        .map(|&u| {
            unit_names
                .get(u)
                .cloned()
                .unwrap_or_else(|| format!("unit {u}"))
        })
        .collect();
    let n = names.len();
    let max_apart = sep.disagreement_dph.first().copied().unwrap_or(0.0);
    let shown = shortlist(&names);
    let (verdict, in_words) = match sep.verdict {
        Verdict::Separated { .. } => (
            "separated",
            format!(
                "separated: {} rejected on the {n} units where they differ ({shown}): {named} has {:+.1} % lower held-out rms there, p {:.4}{}",
                r.label,
                sep.gain_pct,
                sep.p_value,
                if r.gap_se < 0.0 {
                    " (the rejected one had the lower error over all units)"
                } else {
                    ""
                }
            ),
        ),
        Verdict::NotDistinguishable => (
            "not distinguishable",
            format!(
                "not distinguishable on this data: on the {n} units where they differ most ({shown}; predictions apart by up to {max_apart:.4} deg/h, at most {:.4} elsewhere) neither is better (p {:.2}); more units like these, where {named} and {} move apart, would separate them",
                sep.rest_disagreement_dph, sep.p_value, r.label
            ),
        ),
        Verdict::NoTestPower => (
            "no test power",
            format!(
                "no test power: {n} units cannot reach p < {ALPHA} in a two-sided sign-flip test; more runs where {named} and {} move apart would separate them",
                r.label
            ),
        ),
    };
    Competitor {
        candidate: r.label.clone(),
        named: named.to_owned(),
        conditional_gain_pct: r.gain_pct,
        gap_se: r.gap_se,
        verdict,
        separating_units: names,
        disagreement_dph: sep.disagreement_dph.clone(),
        separation_gain_pct: sep.gain_pct,
        separation_p: sep.p_value,
        in_words,
    }
}

/// The first few names, then how many more.
fn shortlist(names: &[String]) -> String {
    const SHOWN: usize = 4;
    let mut s = names
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        s.push_str(&format!(" and {} more", names.len() - SHOWN));
    }
    s
}

/// A name for every validation unit: the run's name when units are whole runs, else
/// the run's name and the block's time span in rows.
pub fn unit_names(folds: &Folds, run_names: &[String]) -> Vec<String> {
    folds
        .unit_rows
        .iter()
        .map(|u| {
            let run = folds
                .run_rows
                .iter()
                .position(|r| r.contains(&u.start))
                .unwrap_or(0);
            let name = run_names.get(run).map_or("run", String::as_str);
            match folds.run_rows.get(run) {
                Some(r) if *r == *u => name.to_owned(),
                Some(r) => format!("{name} rows {}-{}", u.start - r.start, u.end - r.start),
                None => name.to_owned(),
            }
        })
        .collect()
}
