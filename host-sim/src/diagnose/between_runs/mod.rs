//! Stage 5, between runs. Effects that live between runs: a bias constant within a run but different from run to
//! run (a heading-dependent magnetic bias when each run has its own heading; a
//! dependence on the chamber ambient or on a column's run mean). Within-run screening
//! cannot see them: the free run offset absorbs them. Here the run offsets left by the
//! chosen base (the turn-on biases) are the data: each candidate (run-level features) is
//! validated leaving one run out against the offsets' own mean (the turn-on
//! repeatability), and its per-run held-out gains are scaled by the run's point count so
//! they are drops in held-out squared error like the within-run gains. They then enter
//! a Westfall-Young sign-flip max-T test over the run-level library, Bonferroni with the
//! within-run sequence; the selection is stepwise like the within-run one (`selection::
//! screen`: after a run-level cause is named, the rest are scored conditional on it,
//! until nothing passes; the steps are gated, so no split over them). A run-level permutation test (features
//! shuffled across runs) is reported next to each candidate as a check. The run-level
//! library: the run mean (angles: circular-mean harmonic) of every extra column, the
//! ambient, every metadata key that varies between runs whatever its type (numbers as
//! values, times as days since the earliest run, versions by rank, categories as levels;
//! `candidates::metadata`), and the runs' order (by a time key, else as given); the
//! report counts them per family.
//!
//! Files: `run_features` (the offsets and the run-level library), `loo` (the run-level
//! fits and the permutation check), `heading` (a heading harmonic as azimuth error);
//! this file runs the steps, and `screen_both` runs the within-run selection and this
//! one with alpha shared between them.

pub mod heading;
pub mod loo;
pub mod run_features;

use crate::diagnose::baseline::choice::{BaseChoice, BaseFit};
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::candidates::metadata::MetaColumn;
use crate::diagnose::candidates::transforms::Candidate;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::memprobe;
use crate::diagnose::selection::parsimony::{choose_and_screen, BaseRule};
use crate::diagnose::selection::scored::ALPHA;
use crate::diagnose::selection::screen::{Screening, MAX_STEPS};
use crate::diagnose::validation::folds::Folds;
use crate::diagnose::validation::signflip::{max_t_pvalues, FLIP_SEED};
use crate::stats::rms;
use serde::Serialize;

use heading::{heading_effect, HeadingEffect};
use loo::{fit, loo_errors, loo_gains, permutation_p};
use run_features::{enumerate, family_counts, run_offsets, Family, FamilyCount, RunCandidate};

/// Smallest gain on the turn-on repeatability worth naming, %. The run-level test reads
/// leave-one-run-out gains alone, so it keeps the size the within-run test had before
/// it read scores too (`screen::MIN_GAIN_PCT`).
pub const MIN_RUN_GAIN_PCT: f64 = 0.2;

/// One scored run-level candidate, for the report.
#[derive(Clone, Debug, Serialize)]
pub struct RunRow {
    pub label: String,
    /// Leave-one-run-out rms of the run offsets with the candidate, deg/h.
    pub heldout_offset_rms_dph: f64,
    /// Gain on the turn-on repeatability, %.
    pub gain_pct: f64,
    /// Family-wise p (shared with the within-run candidates).
    pub p_value: f64,
    /// Run-level permutation p (candidate alone).
    pub permutation_p: f64,
    pub significant: bool,
    /// Fitted coefficients on all runs (intercept first), deg/h per unit.
    pub coef: Vec<f64>,
}

/// The between-run analysis.
#[derive(Clone, Debug, Serialize)]
pub struct BetweenRun {
    /// Turn-on repeatability, deg/h: the run-level variance component of the law shared
    /// across runs when that law holds (`levels`), else the rms of the free run offsets
    /// about their leave-one-out mean.
    pub turn_on_repeatability_dph: f64,
    /// rms of the offsets the chosen law leaves about their leave-one-out mean, deg/h.
    pub offsets_heldout_rms_dph: f64,
    /// What the offsets are left by: the chosen base and level treatment.
    pub offsets_from: String,
    pub rows: Vec<RunRow>,
    /// Label of the first named run-level effect, if any.
    pub named: Option<String>,
    /// Every named run-level effect, in the order named, with its conditional gain.
    pub named_steps: Vec<RunRow>,
    pub heading: Option<HeadingEffect>,
    /// How many run-level candidates each family of operators contributed (every family,
    /// zero included; empty when the analysis was not run).
    pub candidate_families: Vec<FamilyCount>,
    /// Why the analysis was not run, if it was not.
    pub note: Option<String>,
}

/// The run levels the between-run stage explains: the offsets the chosen base leaves
/// under free offsets, or the shared law's levels (refitted with the run features).
pub enum LevelModel {
    Free(Vec<f64>),
    Shared(
        std::sync::Arc<crate::diagnose::baseline::levels::LevelSystems>,
        f64,
    ),
}

impl LevelModel {
    /// Leave-one-run-out level errors with run features `f` (per run; may be empty).
    fn errors(&self, f: &[Vec<f64>]) -> Option<Vec<f64>> {
        match self {
            Self::Free(o) => loo_errors(o, f),
            Self::Shared(lv, th) => lv.with_run_features(f).heldout_level_errors(*th),
        }
    }

    /// Coefficients fitted on every run: intercept, then the last `k` features'.
    fn coef(&self, f: &[Vec<f64>], k: usize) -> Vec<f64> {
        let all = match self {
            Self::Free(o) => fit(o, f, &(0..o.len()).collect::<Vec<_>>()),
            Self::Shared(lv, th) => {
                let with = lv.with_run_features(f);
                with.solve_shared(&vec![1.0; lv.runs()], *th).map(|w| w.w)
            }
        };
        let Some(w) = all else {
            return vec![];
        };
        let mut coef = vec![w[0]];
        coef.extend_from_slice(&w[w.len().saturating_sub(k)..]);
        coef
    }
}

/// Offsets, the level model, the run-level library and step 1's rows (p-values filled
/// in by `finish`).
pub struct Prepared {
    pub offsets: Vec<f64>,
    pub offsets_from: String,
    pub offsets_rms_dph: f64,
    pub model: LevelModel,
    pub lens: Vec<usize>,
    pub cands: Vec<RunCandidate>,
    pub repeatability_dph: f64,
}

/// Whether the layout holds runs out whole (the between-run stage needs it).
pub fn runs_held_out_whole(folds: &Folds) -> bool {
    folds.offsets == crate::diagnose::validation::folds::Offsets::PerUnit
}

/// Offsets, level model and candidates; `Err` (with the reason) when runs are too few.
pub fn prepare(
    c: &Campaign,
    meta: &[MetaColumn],
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    levels: Option<&crate::diagnose::baseline::choice::LevelChoice>,
) -> Result<Prepared, String> {
    if !runs_held_out_whole(folds) {
        return Err("between-run effects need >= 4 runs held out whole".into());
    }
    let (offsets, offsets_from) = match levels {
        Some(l) => (
            l.offsets_left.clone(),
            format!(
                "{} ({})",
                l.base,
                crate::diagnose::baseline::choice::law_name(l.law)
            ),
        ),
        None => (
            run_offsets(folds, st, base),
            format!("{} (free run offsets)", base.spec.name),
        ),
    };
    let lens: Vec<usize> = folds.run_rows.iter().map(|r| r.len()).collect();
    let offsets_rms_dph =
        loo_gains(&offsets, &lens, &vec![vec![]; offsets.len()]).map_or(f64::NAN, |(_, r0, _)| r0);
    let shared = levels
        .filter(|l| l.law == crate::diagnose::baseline::levels::Law::Shared)
        .and_then(|l| Some((l.systems.clone()?, l.theta)));
    let model = match shared {
        Some((lv, th)) if lv.heldout_level_errors(th).is_some() => LevelModel::Shared(lv, th),
        _ => LevelModel::Free(offsets.clone()),
    };
    Ok(Prepared {
        repeatability_dph: levels.map_or(offsets_rms_dph, |l| l.repeatability_dph),
        offsets_rms_dph,
        offsets_from,
        model,
        cands: enumerate(c, meta),
        lens,
        offsets,
    })
}

/// Per run, `given`'s features followed by `cand`'s.
fn joined(given: &[Vec<f64>], cand: &[Vec<f64>]) -> Vec<Vec<f64>> {
    given
        .iter()
        .zip(cand)
        .map(|(g, c)| g.iter().chain(c).copied().collect())
        .collect()
}

/// Step-wise selection of run-level causes (see the module header); `groups` sequences
/// share alpha (Bonferroni).
pub fn finish(p: Prepared, groups: f64, latitude_deg: f64) -> BetweenRun {
    let runs = p.offsets.len();
    let mut given: Vec<Vec<f64>> = vec![vec![]; runs];
    let mut named_steps: Vec<RunRow> = Vec::new();
    let mut named_idx: Vec<usize> = Vec::new();
    let mut first_rows = Vec::new();
    let mut e0 = p.model.errors(&given);
    for k in 1..=MAX_STEPS {
        let Some(before) = e0.clone() else { break };
        let mut rows = Vec::new();
        let mut gains = Vec::new();
        let mut idx = Vec::new();
        for (i, cand) in p.cands.iter().enumerate() {
            if named_idx.contains(&i) {
                continue;
            }
            let f = joined(&given, &cand.features);
            if f[0].len() + 2 >= runs {
                continue;
            }
            let Some(after) = p.model.errors(&f) else {
                continue;
            };
            gains.push(
                p.lens
                    .iter()
                    .zip(before.iter().zip(&after))
                    .map(|(&n, (a, b))| n as f64 * (a * a - b * b))
                    .collect::<Vec<f64>>(),
            );
            rows.push(RunRow {
                label: cand.label.clone(),
                heldout_offset_rms_dph: rms(&after),
                gain_pct: 100.0 * (1.0 - rms(&after) / rms(&before).max(1e-300)),
                p_value: 1.0,
                permutation_p: if k == 1 {
                    permutation_p(&p.offsets, &p.lens, &cand.features)
                } else {
                    f64::NAN
                },
                significant: false,
                coef: p.model.coef(&f, cand.features[0].len()),
            });
            idx.push(i);
        }
        for (r, fp) in rows.iter_mut().zip(max_t_pvalues(&gains, FLIP_SEED)) {
            r.p_value = (fp * groups).min(1.0);
            r.significant = r.p_value < ALPHA && r.gain_pct > MIN_RUN_GAIN_PCT;
        }
        let best = rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.significant)
            .max_by(|a, b| a.1.gain_pct.total_cmp(&b.1.gain_pct))
            .map(|(j, _)| j);
        if let Some(j) = best {
            named_steps.push(rows[j].clone());
            named_idx.push(idx[j]);
            given = joined(&given, &p.cands[idx[j]].features);
            e0 = p.model.errors(&given);
        }
        if k == 1 {
            first_rows = rows;
        }
        if best.is_none() {
            break;
        }
    }
    let heading = named_idx
        .iter()
        .zip(&named_steps)
        .find(|(i, _)| p.cands[**i].family == Family::Harmonic)
        .map(|(i, r)| heading_effect(&p.cands[*i].column, &r.coef, latitude_deg));
    first_rows.sort_by(|a, b| b.gain_pct.total_cmp(&a.gain_pct));
    BetweenRun {
        turn_on_repeatability_dph: p.repeatability_dph,
        offsets_heldout_rms_dph: p.offsets_rms_dph,
        offsets_from: p.offsets_from,
        rows: first_rows,
        named: named_steps.first().map(|r| r.label.clone()),
        named_steps,
        heading,
        candidate_families: family_counts(&p.cands),
        note: None,
    }
}

/// The base by parsimony (`selection::parsimony`) with its within-run selection, then
/// the between-run selection on it; alpha shared between the two sequences (Bonferroni;
/// one sequence when runs are too few for the between-run one). Returns the base, both
/// selections, how the base was chosen and the number of sequences.
pub fn screen_both(
    campaign: &Campaign,
    meta: &[MetaColumn],
    folds: &Folds,
    st: &Stacked,
    choice: BaseChoice,
    library: &[Candidate],
    latitude_deg: f64,
) -> Result<(BaseChoice, Screening, BaseRule, BetweenRun, f64), DiagnoseError> {
    let groups = if runs_held_out_whole(folds) { 2.0 } else { 1.0 };
    let (choice, screening, base_rule) =
        choose_and_screen(campaign, folds, st, choice, library, groups, MAX_STEPS)?;
    let run_level = prepare(
        campaign,
        meta,
        folds,
        st,
        &choice.chosen,
        choice.levels.as_ref(),
    );
    let between_run = match run_level {
        Ok(p) => finish(p, groups, latitude_deg),
        Err(note) => BetweenRun {
            turn_on_repeatability_dph: f64::NAN,
            offsets_heldout_rms_dph: f64::NAN,
            offsets_from: String::new(),
            rows: vec![],
            named: None,
            named_steps: vec![],
            heading: None,
            candidate_families: vec![],
            note: Some(note),
        },
    };
    memprobe::stage("screen_both");
    Ok((choice, screening, base_rule, between_run, groups))
}
