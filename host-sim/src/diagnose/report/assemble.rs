//! Builds the report's pieces from the stages' outputs: the base summary, the candidate
//! rows, the named causes ranked across both levels, the cause in words, the drift stds,
//! the azimuth effect and the simulator summary. Here, not in the orchestrator, so that
//! `diagnose/mod.rs` only calls the stages in order and the report stage owns how its
//! data is made from theirs.

use crate::diagnose::baseline::choice::{BaseChoice, BaseFit};
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::between_runs::BetweenRun;
use crate::diagnose::input::derivatives::effective_half_width_s;
use crate::diagnose::input::{Campaign, Exclusion};
use crate::diagnose::memprobe;
use crate::diagnose::report::azimuth::{azimuth_effect, DEFAULT_LATITUDE_DEG};
use crate::diagnose::report::competing::competitor;
use crate::diagnose::report::text::nothing_named;
use crate::diagnose::report::{
    Azimuth, CampaignSummary, CandidateRow, Competitor, DriftStd, Extended, ModelSummary,
    NamedCause, Simulation,
};
use crate::diagnose::selection::cause::Cause;
use crate::diagnose::selection::parsimony::BaseRule;
use crate::diagnose::selection::power::PowerCheck;
use crate::diagnose::selection::scored::{gain_pct, Scored};
use crate::diagnose::selection::screen::{Screening, Skipped};
use crate::diagnose::sim_fit::calibrate::SimCalibration;
use crate::diagnose::sim_fit::drift_terms::{summarize, TermSummary};
use crate::diagnose::validation::folds::Folds;

/// The campaign's latitude (the first run that states one), else the default.
pub fn latitude_of(campaign: &Campaign) -> f64 {
    campaign
        .runs
        .iter()
        .find_map(|s| s.latitude_deg)
        .unwrap_or(DEFAULT_LATITUDE_DEG)
}

/// The azimuth effect of the base's and the extended model's residuals, when the
/// campaign has a heading column.
pub fn azimuth(
    campaign: &Campaign,
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    ext_resid: &[f64],
    latitude: f64,
) -> Option<Azimuth> {
    let has_heading = campaign.extra_names.iter().any(|n| n.contains("heading"));
    has_heading.then(|| Azimuth {
        baseline: azimuth_effect(folds, &st.t_s, &base.cv.residual, latitude),
        extended: azimuth_effect(folds, &st.t_s, ext_resid, latitude),
    })
}

/// The base extended by every named within-run cause (the base itself when nothing is
/// named), and its held-out residual.
pub fn extended_model(base: &BaseFit, screening: &Screening) -> (Extended, Vec<f64>) {
    let mut inputs = base.spec.inputs();
    inputs.extend(screening.steps.iter().map(|s| s.scored.cand.label()));
    let cv = screening.final_cv(base);
    memprobe::stage("extended_model + causal::check");
    (
        Extended {
            inputs,
            heldout_rms_dph: cv.rms(),
            gain_pct: gain_pct(base.cv.rms(), cv.rms()),
        },
        cv.residual.clone(),
    )
}

/// Every named cause, within and between runs, ranked by the drop in held-out squared
/// error it brings (the two are in the same units: (deg/h)^2 x points).
pub fn named_causes(
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    screening: &Screening,
    between_run: &BetweenRun,
    latitude_deg: f64,
) -> Vec<NamedCause> {
    let sigma = |r: &[f64]| azimuth_effect(folds, &st.t_s, r, latitude_deg).azimuth_sigma_deg;
    let mut out: Vec<NamedCause> = Vec::new();
    let mut before = &base.cv;
    for (k, s) in screening.steps.iter().enumerate() {
        out.push(NamedCause {
            label: s.scored.cand.label(),
            level: "within runs",
            conditional_gain_pct: s.scored.gain_pct,
            heldout_sse_drop: before.unit_sse.iter().sum::<f64>()
                - s.cv.unit_sse.iter().sum::<f64>(),
            p_value: s.scored.p_value,
            step: k + 1,
            azimuth_sigma_deg_before: Some(sigma(&before.residual)),
            azimuth_sigma_deg_after: Some(sigma(&s.cv.residual)),
            azimuth_error_bound_deg: None,
        });
        before = &s.cv;
    }
    let points: Vec<f64> = folds.run_rows.iter().map(|r| r.len() as f64).collect();
    let total_points: f64 = points.iter().sum();
    let mut level_rms = between_run.offsets_heldout_rms_dph;
    for (k, r) in between_run.named_steps.iter().enumerate() {
        let drop = total_points * (level_rms.powi(2) - r.heldout_offset_rms_dph.powi(2));
        level_rms = r.heldout_offset_rms_dph;
        let heading = between_run
            .heading
            .as_ref()
            .filter(|h| r.label.starts_with(&h.column));
        out.push(NamedCause {
            label: r.label.clone(),
            level: "between runs",
            conditional_gain_pct: r.gain_pct,
            heldout_sse_drop: drop,
            p_value: r.p_value,
            step: k + 1,
            azimuth_sigma_deg_before: None,
            azimuth_sigma_deg_after: None,
            azimuth_error_bound_deg: heading.map(|h| h.azimuth_error_bound_deg),
        });
    }
    out.sort_by(|a, b| b.heldout_sse_drop.total_cmp(&a.heldout_sse_drop));
    memprobe::stage("azimuth + named_causes");
    out
}

/// The first within-run cause in words (and the others' labels), else the between-run
/// one, else why nothing is named.
pub fn cause_in_words(
    cause: Option<&Cause>,
    all: &[NamedCause],
    between_run: &BetweenRun,
    coef: &[f64],
    smallest_attainable_p: f64,
    power_check: Option<&PowerCheck>,
) -> String {
    let others: Vec<String> = all
        .iter()
        .filter(|n| cause.is_none_or(|c| c.label() != n.label))
        .map(|n| {
            format!(
                "{} ({}, {:+.1} %)",
                n.label, n.level, n.conditional_gain_pct
            )
        })
        .collect();
    let also = if others.is_empty() {
        String::new()
    } else {
        format!("; also named: {}", others.join(", "))
    };
    match (cause, &between_run.named) {
        (Some(c), _) => format!("{}{also}", c.in_words(coef)),
        (None, Some(b)) => {
            format!("no within-run cause; between runs: {b} (see the heading / run-level lines)")
        }
        (None, None) => nothing_named(smallest_attainable_p, power_check),
    }
}

/// The chosen base and every base tried, for the report.
pub fn base_summary(
    choice: &BaseChoice,
    rule: BaseRule,
    st: &Stacked,
    campaign: &Campaign,
) -> ModelSummary {
    let base = &choice.chosen;
    ModelSummary {
        name: base.spec.name.clone(),
        poly_degree_t: base.spec.poly_degree_t,
        uses_rate: base.spec.uses_rate,
        rate_half_width_s: st.temp_rate_half_s,
        rate_effective_half_width_s: effective_half_width_s(
            &campaign
                .runs
                .iter()
                .map(|s| (s.t_s.as_slice(), s.temp_c.as_slice()))
                .collect::<Vec<_>>(),
            1,
            st.temp_rate_half_s,
        ),
        inputs: base.spec.inputs(),
        heldout_rms_dph: base.cv.rms(),
        centres: base.centres,
        width_factor: base.width_factor,
        ridge: base.ridge,
        tried: choice.scores.clone(),
        collinearity_warning: choice.collinearity_warning.clone(),
        levels: choice.levels.clone(),
        rule,
    }
}

pub fn candidate_row(s: &Scored) -> CandidateRow {
    CandidateRow {
        label: s.cand.label(),
        column: s.cand.column.clone(),
        transform: s.cand.transform,
        tau_s: s.cand.tau_s,
        heldout_rms_dph: s.heldout_rms_dph,
        gain_pct: s.gain_pct,
        p_value: s.p_value,
        significant: s.significant,
        units_improved: s.units_improved,
    }
}

/// Pooled within-run drift std of the raw drift, the base's and the extension's held-out
/// residuals.
pub fn drift_std(folds: &Folds, y: &[f64], base_resid: &[f64], ext_resid: &[f64]) -> DriftStd {
    let pooled = |v: &[f64]| crate::stats::pooled_std_of_rows(&folds.run_rows, v);
    DriftStd {
        uncompensated_dph: pooled(y),
        baseline_heldout_dph: pooled(base_resid),
        extended_heldout_dph: pooled(ext_resid),
    }
}

pub fn to_exclusion((column, reason): &Skipped) -> Exclusion {
    Exclusion {
        column: column.clone(),
        reason: reason.clone(),
    }
}

/// Every candidate within one standard error of a named cause, with the cause and what
/// the units where they differ said.
pub fn competing(screening: &Screening, unit_names: &[String]) -> Vec<Competitor> {
    screening
        .steps
        .iter()
        .flat_map(|s| {
            let named = s.scored.cand.label();
            s.rivals
                .iter()
                .map(move |r| competitor(&named, r, unit_names))
        })
        .collect()
}

/// The simulator before/after and the terms added (listed for the first run).
pub fn simulation_summary(
    sim: SimCalibration,
    sim_terms: &[Vec<crate::sim::DriftTerm>],
    cause_column: Option<&str>,
) -> Simulation {
    let terms: Vec<TermSummary> = sim_terms
        .first()
        .into_iter()
        .flatten()
        .map(|t| summarize(t, cause_column.unwrap_or("")))
        .collect();
    Simulation {
        before_rms_dph: sim.before_rms_dph,
        after_rms_dph: sim.after_rms_dph.unwrap_or(sim.before_rms_dph),
        term: terms.first().cloned(),
        terms,
        calibration: sim,
    }
}

/// The campaign's line of the report: its size, how it is validated, what was left out
/// and how small a p the layout can reach.
pub fn campaign_summary(
    campaign: &Campaign,
    folds: &Folds,
    screening: &Screening,
    built: &crate::diagnose::candidates::generic::Built,
    smallest_attainable_p: f64,
    (silent, power_check): (bool, Option<PowerCheck>),
) -> CampaignSummary {
    let operator_families =
        crate::diagnose::report::families::rows(&crate::diagnose::report::families::Inputs {
            built,
            screening,
            smallest_attainable_p,
            silent,
            power_check: power_check.as_ref(),
        });
    CampaignSummary {
        runs: campaign.runs.len(),
        points: campaign.points(),
        validation: folds.describe(),
        excluded_columns: campaign.exclusions.clone(),
        skipped_candidates: screening.skipped.iter().map(to_exclusion).collect(),
        library_size: built.candidates.len(),
        smallest_attainable_p,
        power_check,
        operator_families,
    }
}
