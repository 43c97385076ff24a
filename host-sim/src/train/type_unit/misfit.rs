//! Whether a unit belongs to its type: each unit term's own estimate (least squares on the
//! unit's runs, no prior) against the type's value, in units of the type's spread and the
//! estimate's own error together,
//!
//!   z = (own - type mean) / sqrt(spread^2 + se^2 + scatter^2 / units)
//!
//! (se: jackknife over the unit's runs; scatter^2 / units: the type mean's own error, the
//! units' estimates scattered about it, as in a prediction interval for a new unit), tested
//! family-wise over the terms (Bonferroni at `FAMILY_ALPHA`) against Student's t
//! with the Welch-Satterthwaite degrees of freedom of the two variances (the spread from
//! the type's units - 1, the se from the unit's runs - 1): with few runs the se is itself
//! uncertain and a normal quantile would call noise a misfit. A term whose test could not
//! see even a unit `POWER_SIGMAS` spreads out (its se too large, e.g. T and dT/dt from
//! runs at one ambient) has no test power, and is said to have none.
//!
//! Every term tested widens the family's critical value, and nearly collinear terms
//! fitted all at once each have a large se, though the runs resolve their combination; so the terms lacking power are held at the type's mean one by one, farthest from
//! power first, and the rest refitted and tested, a smaller family, each against the same
//! combination of the type's units' own estimates (`resolved`, `calibrate::misfit_of`).
//! Held terms are not tested (no test power, said).
//!
//! A type's own units are tested the same way when the shape is chosen: each unit left out
//! of a fold against the type its other units make (`shape::choose_shape`), so a type unit
//! unlike the others is said before its runs shape the type.

use serde::Serialize;

use crate::stats::student_t::upper_quantile;

/// Family-wise false-alarm rate of the misfit test over a unit's terms.
pub const FAMILY_ALPHA: f64 = 0.01;
/// A term's test has power when a unit this many type spreads out would be flagged.
pub const POWER_SIGMAS: f64 = 5.0;

/// One term's test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TermTest {
    pub name: String,
    /// The unit's own estimate and its jackknife standard error, model units.
    pub own: f64,
    pub se: f64,
    /// The type's mean and spread as learnt from its units, model units, and the mean's
    /// own error (its units' scatter over the square root of their count).
    pub type_mean: f64,
    pub type_spread: f64,
    pub mean_se: f64,
    /// Whether other terms were held at the type's mean for this estimate (`resolved`):
    /// then the own estimate, the type's mean and spread are those of the combination the
    /// fit reads (the term plus the held terms' deviations through the rows).
    pub others_held: bool,
    /// (own - mean) / sqrt(spread^2 + mean_se^2 + se^2).
    pub z: f64,
    /// Critical |z| at the family-wise rate.
    pub critical: f64,
    pub has_power: bool,
    pub outside: bool,
}

impl TermTest {
    /// How far the test is from power: critical |z| x its scale over `POWER_SIGMAS`
    /// spreads (<= 1: a unit that far out would be flagged).
    pub fn power_shortfall(&self) -> f64 {
        let total = (self.type_spread.powi(2) + self.mean_se.powi(2) + self.se.powi(2)).sqrt();
        self.critical * total / (POWER_SIGMAS * self.type_spread)
    }
}

/// The misfit test of one unit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Misfit {
    pub unit_id: String,
    pub terms: Vec<TermTest>,
}

impl Misfit {
    /// Whether any term is outside the type.
    pub fn outside(&self) -> bool {
        self.terms.iter().any(|t| t.outside)
    }

    /// One line per term outside (`unit U3: Shupe coefficient 4.1 sigma outside the type
    /// (critical 3.2)`), then one naming the terms without test power (not those found
    /// outside: their test was strong enough for this unit).
    pub fn lines(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .terms
            .iter()
            .filter(|t| t.outside)
            .map(|t| {
                format!(
                    "unit {}: {} {:.1} sigma outside the type (critical {:.1}, family-wise {FAMILY_ALPHA})",
                    self.unit_id,
                    t.name,
                    t.z.abs(),
                    t.critical
                )
            })
            .collect();
        let blind: Vec<&str> = self
            .terms
            .iter()
            // a term found outside had power enough for this unit
            .filter(|t| !t.has_power && !t.outside)
            .map(|t| t.name.as_str())
            .collect();
        if !blind.is_empty() {
            let held = if self.terms.iter().any(|t| t.others_held) {
                "; the other terms were tested with these held at the type's mean, against the same combination of the type's units"
            } else {
                ""
            };
            v.push(format!(
                "unit {}: no test power for {} (its runs cannot tell a unit {POWER_SIGMAS} spreads out: more of its runs, at more ambients, or a type from more units give the test power){held}",
                self.unit_id,
                blind.join(", ")
            ));
        }
        if v.is_empty() {
            v.push(format!(
                "unit {}: every term within its type (largest |z| {:.1})",
                self.unit_id,
                self.terms.iter().map(|t| t.z.abs()).fold(0.0, f64::max)
            ));
        }
        v
    }
}

/// The type's side of the test: each term's mean, spread and units' scatter (model
/// units), and the units it was learnt from.
#[derive(Clone, Copy, Debug)]
pub struct TypeSide<'a> {
    pub mean: &'a [f64],
    pub spread: &'a [f64],
    pub scatter: &'a [f64],
    pub units: usize,
}

/// The unit's side: its own estimate of each term, the estimate's jackknife standard
/// error over its `runs` runs (infinite: not tested), and whether other terms were held
/// at the type's mean for it (`resolved::HeldEstimate`).
#[derive(Clone, Copy, Debug)]
pub struct UnitSide<'a> {
    pub own: &'a [f64],
    pub se: &'a [f64],
    pub others_held: bool,
    pub runs: usize,
}

/// Tests a unit's own estimates against the type (see the module notes).
pub fn test_unit(unit_id: &str, names: &[String], unit: &UnitSide, ty: &TypeSide) -> Misfit {
    let (own, se) = (unit.own, unit.se);
    let unit_runs = unit.runs;
    // the family: the terms tested (a term held at the type's mean, or one the rows
    // cannot see, has an infinite se and is never found outside)
    let p = se.iter().filter(|s| s.is_finite()).count().max(1) as f64;
    let tail = FAMILY_ALPHA / (2.0 * p);
    let dof_type = (ty.units as f64 - 1.0).max(1.0);
    let dof_unit = (unit_runs as f64 - 1.0).max(1.0);
    let terms = (0..own.len())
        .map(|k| {
            // The type's side: the spread of units about the mean, and the mean's own error
            // (its units' scatter over their count), both known to the type's units - 1.
            let mean_se = ty.scatter[k] / (ty.units.max(1) as f64).sqrt();
            let spread = ty.spread[k];
            let s2 = spread * spread + mean_se * mean_se;
            let e2 = if se[k].is_finite() {
                se[k] * se[k]
            } else {
                f64::INFINITY
            };
            let total = (s2 + e2).sqrt();
            let dof = (s2 + e2).powi(2) / (s2 * s2 / dof_type + e2 * e2 / dof_unit);
            let critical = if dof.is_finite() {
                upper_quantile(tail, dof.max(1.0))
            } else {
                f64::INFINITY
            };
            let z = (own[k] - ty.mean[k]) / total;
            let has_power = total.is_finite() && critical * total <= POWER_SIGMAS * spread;
            TermTest {
                name: names[k].clone(),
                own: own[k],
                se: se[k],
                type_mean: ty.mean[k],
                type_spread: ty.spread[k],
                mean_se,
                others_held: unit.others_held && se[k].is_finite(),
                z: if z.is_finite() { z } else { 0.0 },
                critical,
                has_power,
                outside: z.is_finite() && z.abs() > critical,
            }
        })
        .collect();
    Misfit {
        unit_id: unit_id.into(),
        terms,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        vec!["offset".into(), "Shupe coefficient".into()]
    }

    /// `test_unit` of a unit's two terms against a type of mean (0, 1) and spread 0.1 each.
    fn against_type(
        unit: &str,
        own: [f64; 2],
        se: [f64; 2],
        type_units: usize,
        runs: usize,
    ) -> Misfit {
        test_unit(
            unit,
            &names(),
            &UnitSide {
                own: &own,
                se: &se,
                others_held: false,
                runs,
            },
            &TypeSide {
                mean: &[0.0, 1.0],
                spread: &[0.1, 0.1],
                scatter: &[0.1, 0.1],
                units: type_units,
            },
        )
    }

    #[test]
    fn a_unit_far_outside_is_named_and_one_inside_is_not() {
        let out = against_type("U3", [0.02, 1.9], [0.05, 0.05], 10, 6);
        assert!(out.outside());
        let lines = out.lines().join("\n");
        assert!(
            lines.contains("unit U3: Shupe coefficient 7.7 sigma outside the type"),
            "{lines}"
        );
        let inside = against_type("U4", [0.02, 1.15], [0.05, 0.05], 10, 6);
        assert!(!inside.outside(), "{:?}", inside.lines());
    }

    #[test]
    fn a_term_found_outside_is_not_also_said_to_lack_power() {
        // 3 type units: the critical value exceeds the 5-spread power bound, yet a unit
        // 30 spreads out is found; it is not listed as having no test power.
        let out = against_type("U6", [0.0, 4.0], [0.01, 0.01], 3, 3);
        assert!(
            out.terms[1].outside && !out.terms[1].has_power,
            "{:?}",
            out.terms[1]
        );
        let lines = out.lines().join("\n");
        assert!(lines.contains("Shupe coefficient"), "{lines}");
        assert!(!lines.contains("no test power for Shupe"), "{lines}");
    }

    #[test]
    fn a_term_the_runs_cannot_see_has_no_test_power() {
        // an se of 10 spreads: even a unit 5 spreads out would not be flagged
        let out = against_type("U5", [0.0, 3.0], [0.01, 1.0], 10, 6);
        assert!(!out.terms[1].has_power && out.terms[0].has_power);
        assert!(out
            .lines()
            .iter()
            .any(|l| l.contains("no test power for Shupe coefficient")));
        // few runs: the critical value grows (Student's t), so noise is not a misfit
        let few = against_type("U6", [0.0, 1.0], [0.1, 0.1], 10, 2);
        let many = against_type("U6", [0.0, 1.0], [0.1, 0.1], 10, 30);
        assert!(few.terms[0].critical > many.terms[0].critical);
    }
}
