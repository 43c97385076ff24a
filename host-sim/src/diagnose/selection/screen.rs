//! Stepwise forward selection over the generic library (issue 18 items 3-5).
//!
//! At each step every candidate not yet named is added, as the linear-in-parameters
//! term it is named as (its one or more columns), to the base plus the causes already
//! named, and validated held out (whole runs, or buffered time blocks of single
//! records; one small solve per fold thanks to per-unit Gram matrices). Its per-unit
//! drops in held-out squared error and its per-unit scores (the term made orthogonal to
//! that model, against the model's residual; `validation::score`) feed a Westfall-Young
//! sign-flip test whose maxima are taken over the whole library at that step, one per
//! statistic, joined by min-p (`signflip::max_t_pvalues_with_scores`): the ranking and
//! the smallest gain stay the held-out gain's. The family-wise error is held
//! over the library (max-T) and over the within-run and between-run sequences
//! (Bonferroni, x `groups`: the reported p is the max-T p x groups). Over the steps it
//! needs no further split: the steps are gated (step k is tested only when every earlier
//! step rejected) and their nulls are nested ("nothing left beyond the causes named so
//! far" stays true once true, as later steps only add causes), so only the first true
//! null can be falsely rejected, at the level of one step (the fixed-sequence /
//! gatekeeping argument). Measured: alpha / 2^k spending instead cost a 2-sigma heading
//! bias its name on 2 of 6 seeds (`diagnose_between`, p 0.012-0.015). What no test
//! controls is picking a wrong candidate while a true one remains; the competing list
//! says when the data cannot tell them apart. The term is tested in the form it is
//! named: there is no refit after the test.
//!
//! Naming at a step: among significant candidates the smallest held-out error wins;
//! within one column a simpler transform (value before lag, ...) is preferred unless the
//! more complex one is significantly better (a lag with a free tau can imitate its
//! column's value or derivatives). Significant candidates of other columns within one
//! standard error (of the per-unit difference) of the named one are reported as
//! competing explanations: the data cannot tell them apart. The steps stop when nothing
//! passes or after `MAX_STEPS`.

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::candidates::transforms::{stacked_columns, Candidate};
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::cv::CvResult;
use crate::diagnose::validation::folds::{Folds, Offsets};
use crate::diagnose::validation::signflip::{
    max_t_pvalues_with_scores, paired_pvalue, sse_drop, unit_gains, FLIP_SEED,
};

use super::scored::{gain_pct, Scored, ALPHA};
use super::separate::{find, refit_pair, separate, Pair, Separation, Verdict};

/// Smallest held-out gain worth naming within runs, % of rms. It was 0.2 % while the
/// held-out gain alone was tested; the score finds consistent effects that small too (on
/// the simulator's own campaign, seed 8 at six ambients, `t_s:decay(tau_s=80)` and
/// `temp_c:lag(tau_s=80)` at 0.3 % held out and p 0.005: its start-up seen through the
/// thermometer, which the calibrated simulator holds; `diagnose_self_consistency`), so a
/// name now needs a gain that matters (docs/record/diagnose.md, 2026-12-03).
pub const MIN_GAIN_PCT: f64 = 1.0;
/// Most causes named within runs.
pub const MAX_STEPS: usize = 4;
/// A candidate the data cannot tell from a named cause.
#[derive(Clone, Debug)]
pub struct Rival {
    pub label: String,
    /// Its held-out gain at that step, %.
    pub gain_pct: f64,
    /// Its held-out squared-error excess over the named cause, in standard errors
    /// (negative for a former choice the separating units rejected).
    pub gap_se: f64,
    /// What the units where the two disagree say (`separate`).
    pub separation: Separation,
}

/// One named cause.
#[derive(Clone, Debug)]
pub struct Step {
    pub scored: Scored,
    /// The cause's stacked columns.
    pub cols: Vec<Vec<f64>>,
    /// Held-out result of the base plus every cause named up to this one.
    pub cv: CvResult,
    pub rivals: Vec<Rival>,
    /// When a simpler transform of the same column was chosen over the best one.
    pub parsimony_note: Option<String>,
}

/// A skipped candidate's label and the reason.
pub type Skipped = (String, String);

/// The outcome of the selection.
#[derive(Clone, Debug)]
pub struct Screening {
    /// Step 1's scores (every candidate against the base), best held-out first.
    pub scored: Vec<Scored>,
    pub skipped: Vec<Skipped>,
    /// The named causes, in the order named (most important first).
    pub steps: Vec<Step>,
}

impl Screening {
    /// The last step's held-out result (the base's when nothing is named).
    pub fn final_cv<'a>(&'a self, base: &'a BaseFit) -> &'a CvResult {
        self.steps.last().map_or(&base.cv, |s| &s.cv)
    }
}

fn has_within_unit_variation(folds: &Folds, col: &[f64]) -> bool {
    let total: f64 = col.iter().map(|v| v * v).sum::<f64>().max(1e-300);
    let within: f64 = folds
        .unit_rows
        .iter()
        .map(|r| {
            let m = col[r.clone()].iter().sum::<f64>() / r.len() as f64;
            col[r.clone()]
                .iter()
                .map(|v| (v - m) * (v - m))
                .sum::<f64>()
        })
        .sum();
    within > 1e-10 * total && within > 1e-200
}

/// Runs the stepwise selection (see the module header); `groups` is the number of
/// sequences sharing alpha (2 when the between-run sequence runs too), `max_steps` caps
/// the causes named.
pub fn screen(
    campaign: &Campaign,
    folds: &Folds,
    base: &BaseFit,
    cands: Vec<Candidate>,
    groups: f64,
    max_steps: usize,
) -> Result<Screening, DiagnoseError> {
    let (cands, mut skipped) = usable(campaign, folds, cands);
    let mut steps: Vec<Step> = Vec::new();
    let mut first: Vec<Scored> = Vec::new();
    let mut model_cols: Vec<Vec<f64>> = Vec::new();
    let mut prev = base.cv.clone();
    for k in 1..=max_steps {
        let open: Vec<&Candidate> = cands
            .iter()
            .filter(|c| !steps.iter().any(|s| same_form(&s.scored.cand, c)))
            .collect();
        let mut scored = Vec::with_capacity(open.len());
        let mut gains = Vec::with_capacity(open.len());
        let mut scores = Vec::with_capacity(open.len());
        for cand in open {
            let mut cols = model_cols.clone();
            let own = stacked_columns(campaign, cand);
            let width = own.len();
            cols.extend(own);
            // Scores of whole runs only: neighbouring time blocks of one record share
            // its noise, and only held-out gains have a buffer against that.
            let tested = if folds.offsets == Offsets::PerUnit {
                width
            } else {
                0
            };
            let Ok((cv, score)) = base.prepared.validate_scored(folds, &cols, tested) else {
                if k == 1 {
                    skipped.push((cand.label(), "singular held-out fit".into()));
                }
                continue;
            };
            gains.push(bounded_gains(&prev, &cv));
            scores.push(score.unwrap_or_default());
            let g = unit_gains(&prev, &cv);
            let rms = cv.rms();
            scored.push(Scored {
                cand: cand.clone(),
                heldout_rms_dph: rms,
                gain_pct: gain_pct(prev.rms(), rms),
                unit_sse: cv.unit_sse,
                p_value: 1.0,
                significant: false,
                units_improved: g.iter().filter(|v| **v > 0.0).count() as f64
                    / g.len().max(1) as f64,
            });
        }
        let family_p = max_t_pvalues_with_scores(&gains, &scores, FLIP_SEED);
        for (s, p) in scored.iter_mut().zip(family_p) {
            s.p_value = (p * groups).min(1.0);
            s.significant = s.p_value < ALPHA && s.gain_pct > MIN_GAIN_PCT;
        }
        scored.sort_by(|a, b| a.heldout_rms_dph.total_cmp(&b.heldout_rms_dph));
        let (chosen, parsimony_note) = choose(&scored);
        let (chosen, rivals, parsimony_note) = match chosen {
            Some(i) => {
                let ctx = Context {
                    campaign,
                    folds,
                    base,
                    model_cols: &model_cols,
                };
                let (named, rivals) = settle(&ctx, &scored, i)?;
                (Some(named), rivals, parsimony_note.filter(|_| named == i))
            }
            None => (None, vec![], None),
        };
        let step = match chosen {
            Some(i) => {
                let cols = stacked_columns(campaign, &scored[i].cand);
                let mut all = model_cols.clone();
                all.extend(cols.iter().cloned());
                let cv = base.prepared.validate_with(folds, &all)?;
                Some(Step {
                    scored: scored[i].clone(),
                    cols,
                    cv,
                    rivals,
                    parsimony_note,
                })
            }
            None => None,
        };
        if k == 1 {
            first = scored;
        }
        let Some(step) = step else { break };
        model_cols.extend(step.cols.iter().cloned());
        prev = step.cv.clone();
        steps.push(step);
    }
    Ok(Screening {
        scored: first,
        skipped,
        steps,
    })
}

/// Same column, transform family and product (with the same base input or the same
/// other column): a second one adds nothing new (a spline of 4 knots after one of 6, a
/// lag of another tau).
fn same_form(a: &Candidate, b: &Candidate) -> bool {
    a.column == b.column
        && a.transform == b.transform
        && a.times == b.times
        && a.partner.as_ref().map(|p| p.index) == b.partner.as_ref().map(|p| p.index)
}

/// Candidates whose columns are finite and, with run offsets free, vary within runs;
/// the rest with the reason.
fn usable(
    campaign: &Campaign,
    folds: &Folds,
    cands: Vec<Candidate>,
) -> (Vec<Candidate>, Vec<Skipped>) {
    let mut skipped = Vec::new();
    let mut keep = Vec::new();
    for cand in cands {
        let cols = stacked_columns(campaign, &cand);
        if cols.is_empty() || cols.iter().any(|c| c.iter().any(|v| !v.is_finite())) {
            skipped.push((cand.label(), "not finite".to_owned()));
        } else if folds.offsets == Offsets::PerUnit
            && !cols.iter().any(|c| has_within_unit_variation(folds, c))
        {
            skipped.push((
                cand.label(),
                "no variation within runs: tested between runs instead (run-level values)"
                    .to_owned(),
            ));
        } else {
            keep.push(cand);
        }
    }
    (keep, skipped)
}

/// The best significant candidate (sorted), or a simpler transform of the same column
/// that is not significantly worse (with the note saying so).
fn choose(scored: &[Scored]) -> (Option<usize>, Option<String>) {
    let Some(top) = scored.iter().position(|s| s.significant) else {
        return (None, None);
    };
    let simpler = scored
        .iter()
        .enumerate()
        .filter(|(i, s)| {
            *i != top
                && s.significant
                && s.cand.column == scored[top].cand.column
                && s.cand.complexity() < scored[top].cand.complexity()
        })
        .filter(|(_, s)| {
            paired_pvalue(&sse_drop(&s.unit_sse, &scored[top].unit_sse), FLIP_SEED) >= 0.05
        })
        .min_by(|a, b| {
            (a.1.cand.complexity(), a.1.heldout_rms_dph)
                .partial_cmp(&(b.1.cand.complexity(), b.1.heldout_rms_dph))
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .map(|(i, _)| i);
    match simpler {
        Some(i) => (
            Some(i),
            Some(format!(
                "{} chosen over {} (same column, simpler, not significantly worse on held-out data)",
                scored[i].cand.label(),
                scored[top].cand.label()
            )),
        ),
        None => (Some(top), None),
    }
}

/// Significant candidates of other columns whose held-out error is within one standard
/// error of the chosen one's (per-unit differences, whole units): (index, gap in SE).
fn rivals_of(scored: &[Scored], chosen: usize) -> Vec<(usize, f64)> {
    let named = &scored[chosen];
    let mut seen = vec![named.cand.column.clone()];
    let mut out = Vec::new();
    for (i, s) in scored.iter().enumerate().filter(|(_, s)| s.significant) {
        if seen.contains(&s.cand.column) {
            continue;
        }
        if let Some(gap) = gap_se(named, s).filter(|g| *g < 1.0) {
            seen.push(s.cand.column.clone());
            out.push((i, gap));
        }
    }
    out
}

/// `other`'s held-out squared-error excess over `named`, in standard errors of the sum
/// of per-unit differences (None with fewer than 2 units).
fn gap_se(named: &Scored, other: &Scored) -> Option<f64> {
    let d = sse_drop(&named.unit_sse, &other.unit_sse);
    let u = d.len() as f64;
    if u < 2.0 {
        return None;
    }
    let m = d.iter().sum::<f64>() / u;
    let se = (u * d.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (u - 1.0)).sqrt();
    Some(-m * u / se.max(1e-300))
}

/// What the separation tests need besides the scores.
struct Context<'a> {
    campaign: &'a Campaign,
    folds: &'a Folds,
    base: &'a BaseFit,
    model_cols: &'a [Vec<f64>],
}

/// The chosen candidate's competitors, each tested on the units where the two disagree
/// (`separate`); a competitor that wins there is named instead (the best-separated one
/// when several do) and the step's competitors are tested again against it. Returns the
/// named candidate's index and its competitors.
fn settle(
    ctx: &Context,
    scored: &[Scored],
    chosen: usize,
) -> Result<(usize, Vec<Rival>), DiagnoseError> {
    let rivals = rivals_of(scored, chosen);
    let tested = test_rivals(ctx, scored, chosen, &rivals)?;
    let winner = tested
        .iter()
        .filter(|r| r.separation.verdict == Verdict::Separated { rival_won: true })
        .min_by(|a, b| a.separation.p_value.total_cmp(&b.separation.p_value))
        .and_then(|r| find(scored, &r.label));
    let Some(new) = winner else {
        return Ok((chosen, tested));
    };
    let mut others: Vec<(usize, f64)> =
        vec![(chosen, gap_se(&scored[new], &scored[chosen]).unwrap_or(0.0))];
    others.extend(
        rivals
            .iter()
            .filter(|(i, _)| *i != new)
            .map(|(i, _)| (*i, gap_se(&scored[new], &scored[*i]).unwrap_or(0.0))),
    );
    Ok((new, test_rivals(ctx, scored, new, &others)?))
}

/// Each competitor's separation test against the named candidate.
fn test_rivals(
    ctx: &Context,
    scored: &[Scored],
    named: usize,
    rivals: &[(usize, f64)],
) -> Result<Vec<Rival>, DiagnoseError> {
    let named_cols = stacked_columns(ctx.campaign, &scored[named].cand);
    rivals
        .iter()
        .map(|&(i, gap)| {
            let rival_cols = stacked_columns(ctx.campaign, &scored[i].cand);
            let (a, b) = refit_pair(
                ctx.folds,
                ctx.base,
                ctx.model_cols,
                &named_cols,
                &rival_cols,
            )?;
            let pair = Pair {
                named: &a,
                rival: &b,
            };
            Ok(Rival {
                label: scored[i].cand.label(),
                gain_pct: scored[i].gain_pct,
                gap_se: gap,
                separation: separate(ctx.folds, &pair, rivals.len()),
            })
        })
        .collect()
}

/// Per-unit gains for the family-wise test, each bounded by +/- the unit's error before:
/// no candidate can gain more than the whole error in a unit, so a flipped sign must
/// not turn a catastrophic loss (a term extrapolating badly into one block) into a gain
/// no real candidate could have. The bound is odd-symmetric, so a gain symmetric about
/// 0 under "unrelated" stays symmetric and the sign-flip null holds. Measured: on single
/// records without it, a planted term gaining +78 % held out had p 0.84-0.99, because
/// another candidate's one catastrophic block, flipped, dominated the maximum.
pub fn bounded_gains(base: &CvResult, cand: &CvResult) -> Vec<f64> {
    unit_gains(base, cand)
        .into_iter()
        .zip(&base.unit_sse)
        .map(|(g, b)| g.clamp(-b, *b))
        .collect()
}
