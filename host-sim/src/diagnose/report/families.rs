//! The within-run library per operator family (issue 38 item 4): how many candidates each
//! family contributed, how many the library's cap or the record cut and why, and what the
//! test's power is for that family. "No test power" is said per family, not only overall:
//! a record can have the power to name a value of a column and none to name its lag.
//!
//! The power comes from the planted-shape check (`selection::power`, run when nothing is
//! named): the shapes planted of a family and how many of them the selection named at 1
//! residual sigma. Nothing new is computed here, so the per-family report costs nothing.

use crate::diagnose::candidates::families::{self, OperatorFamily};
use crate::diagnose::candidates::generic::Built;
use crate::diagnose::selection::power::{PowerCheck, PLANTED_SIGMAS};
use crate::diagnose::selection::scored::ALPHA;
use crate::diagnose::selection::screen::Screening;
use serde::Serialize;
use std::collections::HashMap;

/// One operator family of the within-run library.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FamilyRow {
    pub family: &'static str,
    /// Candidates in the library (after the cap).
    pub candidates: usize,
    /// Candidates the library's cap left out.
    pub cut_by_cap: usize,
    /// Candidates dropped on this record before the test (not finite, no variation
    /// within runs, a singular fit).
    pub skipped: usize,
    /// Why candidates of the family are missing (the cap, columns without events, ...).
    pub why_cut: Vec<String>,
    /// Shapes of the family planted by the power check, and how many were named.
    pub shapes_planted: usize,
    pub shapes_named: usize,
    /// Largest family-wise p among its planted shapes (None when none was planted).
    pub worst_planted_p: Option<f64>,
    /// The test's power for the family, in words.
    pub power: String,
}

/// What the family rows are built from.
pub struct Inputs<'a> {
    pub built: &'a Built,
    pub screening: &'a Screening,
    pub smallest_attainable_p: f64,
    /// Whether nothing was named (the power check runs only then).
    pub silent: bool,
    pub power_check: Option<&'a PowerCheck>,
}

/// Every family, in the report's order (zero candidates included).
pub fn rows(x: &Inputs) -> Vec<FamilyRow> {
    let family_of: HashMap<String, OperatorFamily> = x
        .built
        .candidates
        .iter()
        .map(|c| (c.label(), OperatorFamily::of(c)))
        .collect();
    families::ALL
        .iter()
        .map(|&f| {
            let candidates = x
                .built
                .candidates
                .iter()
                .filter(|c| OperatorFamily::of(c) == f)
                .count();
            let cut_by_cap = x.built.cut_by_cap.iter().filter(|c| **c == f).count();
            let skipped = x
                .screening
                .skipped
                .iter()
                .filter(|(label, _)| family_of.get(label) == Some(&f))
                .count();
            let tested = x
                .screening
                .scored
                .iter()
                .any(|s| OperatorFamily::of(&s.cand) == f);
            let mut why_cut: Vec<String> = x
                .built
                .notes
                .iter()
                .filter(|n| n.family == f)
                .map(|n| n.note.clone())
                .collect();
            if cut_by_cap > 0 {
                why_cut.push(format!(
                    "library capped at {} candidates ({cut_by_cap} of this family left out)",
                    crate::diagnose::candidates::generic::MAX_CANDIDATES
                ));
            }
            let shapes: Vec<_> = x
                .power_check
                .map(|pc| pc.shapes.iter().filter(|s| s.family == f.name()).collect())
                .unwrap_or_default();
            let named = shapes.iter().filter(|s| s.named).count();
            let worst_planted_p = shapes.iter().map(|s| s.p_value).reduce(f64::max);
            let power = power_words(x, f, tested, &shapes);
            FamilyRow {
                family: f.name(),
                candidates,
                cut_by_cap,
                skipped,
                why_cut,
                shapes_planted: shapes.len(),
                shapes_named: named,
                worst_planted_p,
                power,
            }
        })
        .collect()
}

/// The family's power in words.
fn power_words(
    x: &Inputs,
    f: OperatorFamily,
    tested: bool,
    shapes: &[&crate::diagnose::selection::power::ShapeCheck],
) -> String {
    let name = f.name();
    if !tested {
        return "no candidate of this family was tested on this record".into();
    }
    if x.smallest_attainable_p >= ALPHA {
        return format!(
            "no test power for family {name}: the smallest reachable p is {:.4} >= alpha {ALPHA} with this few validation units",
            x.smallest_attainable_p
        );
    }
    if !x.silent {
        return "not checked: a cause was named (the planted-shape check runs when nothing is named)"
            .into();
    }
    if x.power_check.is_none() {
        return "not checked".into();
    }
    if shapes.is_empty() {
        return format!(
            "not checked for family {name}: each of its best-ranked candidates is mostly predicted by the base \
             (an effect of that shape could not be told from the base: confounding, not a lack of power)"
        );
    }
    let named = shapes.iter().filter(|s| s.named).count();
    match shapes.iter().find(|s| !s.named) {
        Some(miss) => format!(
            "no test power for family {name} at {PLANTED_SIGMAS} sigma: {named} of {} planted shapes named; a copy of {} \
             at the residual's own size was not named (gain {:+.1} %, p {:.4})",
            shapes.len(),
            miss.planted,
            miss.gain_pct,
            miss.p_value
        ),
        None => format!(
            "{named} of {named} planted shapes named at {PLANTED_SIGMAS} sigma (largest p {:.4})",
            shapes.iter().map(|s| s.p_value).fold(0.0, f64::max)
        ),
    }
}
