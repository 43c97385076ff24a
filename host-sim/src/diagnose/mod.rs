//! `diagnose`: from a measured campaign to what the simulation and the paper's model get
//! wrong, the cause, the extended model and its held-out gain (issue 4).
//!
//! Pipeline: [`input`] checks and averages the runs; [`models`] fits the paper's RBF on
//! (T, dT/dt) with run offsets and validates it on held-out runs ([`cv`]); [`simfit`]
//! calibrates the simulator's physics; [`residuals`] describes what is left; [`transforms`]
//! builds every candidate feature; [`screen`] ranks them by held-out gain with the
//! family-wise sign-flip test of [`signflip`]; [`report`] states the result, [`plots`]
//! draws it, [`azimuth`] translates it into north-seeking error.

pub mod azimuth;
pub mod bases;
pub mod basis;
pub mod between;
pub mod cv;
pub mod error;
pub mod input;
pub mod linalg;
pub mod models;
pub mod olscheck;
pub mod outliers;
pub mod plots;
pub mod report;
pub mod residuals;
pub mod screen;
pub mod signflip;
pub mod simfit;
pub mod simterm;
pub mod transforms;

pub use error::DiagnoseError;
pub use report::{Cause, Report};

use crate::io::runs::Run;
use cv::Folds;
use input::Exclusion;
use models::Stacked;
use report::{
    Azimuth, CampaignSummary, CandidateRow, Competitor, DriftStd, Extended, ModelSummary,
    Simulation,
};

/// Everything the diagnosis computed: the report plus the series the plots need.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    pub report: Report,
    pub run_names: Vec<String>,
    pub run_rows: Vec<std::ops::Range<usize>>,
    pub t_s: Vec<f64>,
    /// Drift with run offsets removed as the fits see it, deg/h.
    pub drift_dph: Vec<f64>,
    pub baseline_residual: Vec<f64>,
    pub extended_residual: Vec<f64>,
    /// The named cause's first feature column (stacked), if any.
    pub cause_feature: Option<Vec<f64>>,
    /// The named effect as `fog_sim::sim` drift terms, per run in `run_names` order
    /// (empty lists when nothing is named): add them with `GyroParams::with_term`.
    pub sim_terms: Vec<Vec<crate::sim::DriftTerm>>,
}

/// Runs the whole diagnosis on a campaign.
// Split along its sections is deferred (issue 12, second part); allowed until then.
#[allow(clippy::too_many_lines)]
pub fn diagnose(runs: &[Run]) -> Result<Diagnosis, DiagnoseError> {
    let campaign = input::prepare(runs)?;
    let st = Stacked::new(&campaign);
    let folds = Folds::new(&st.run_lengths)?;
    let choice = bases::choose(&folds, &st)?;
    let base = &choice.chosen;
    let base_rms = base.cv.rms();
    let structure = residuals::structure(&campaign, &folds, &st, &base.cv.residual);
    let run_names: Vec<String> = campaign.runs.iter().map(|s| s.name.clone()).collect();
    let outliers = outliers::locate(&folds, &run_names, &st.t_s, &st.y, &base.cv.residual);
    let run_level = between::prepare(&campaign, &folds, &st, base);
    let no_gains = Vec::new();
    let screening = screen::screen(
        &campaign,
        &folds,
        &st,
        base,
        transforms::enumerate(&campaign),
        run_level.as_ref().map_or(&no_gains, |p| &p.gains),
    )?;
    let latitude = campaign
        .runs
        .iter()
        .find_map(|s| s.latitude_deg)
        .unwrap_or(azimuth::DEFAULT_LATITUDE_DEG);
    let between_run = match run_level {
        Ok(p) => between::finish(p, &screening.between_p, latitude),
        Err(note) => between::BetweenRun {
            turn_on_repeatability_dph: f64::NAN,
            rows: vec![],
            named: None,
            heading: None,
            note: Some(note),
        },
    };

    let named = screening.named.map(|i| &screening.scored[i]);
    let cause = named.map(|s| Cause {
        column: s.cand.column.clone(),
        transform: s.cand.transform,
        tau_s: s.cand.tau_s,
    });
    let sim = simfit::calibrate(
        &campaign,
        &folds.run_rows,
        &st.y,
        named.map(|s| s.cols.as_slice()),
    )?;
    let base_inputs = base.spec.inputs();
    let (extended, ext_resid) = match named {
        Some(s) => {
            let mut inputs = base_inputs.clone();
            inputs.push(cause.as_ref().map(Cause::label).unwrap_or_default());
            (
                Extended {
                    inputs,
                    mode: Some(s.mode),
                    heldout_rms_dph: s.heldout_rms_dph,
                    gain_pct: s.gain_pct,
                },
                s.cv.residual.clone(),
            )
        }
        None => (
            Extended {
                inputs: base_inputs.clone(),
                mode: None,
                heldout_rms_dph: base_rms,
                gain_pct: 0.0,
            },
            base.cv.residual.clone(),
        ),
    };
    let has_heading = campaign.extra_names.iter().any(|n| n.contains("heading"));
    let azimuth = has_heading.then(|| Azimuth {
        baseline: azimuth::azimuth_effect(&folds, &st.t_s, &base.cv.residual, latitude),
        extended: azimuth::azimuth_effect(&folds, &st.t_s, &ext_resid, latitude),
    });
    let smallest_attainable_p = signflip::smallest_p(folds.unit_rows.len());
    let words = report::cause_in_words(cause.as_ref(), &sim.effect_coef).unwrap_or_else(|| {
        match &between_run.named {
            Some(b) => format!(
                "no within-run cause; between runs: {b} (see the heading / run-level lines)"
            ),
            None => report::nothing_named(smallest_attainable_p),
        }
    });
    let sim_terms = simterm::terms_per_run(runs, cause.as_ref(), &sim.effect_coef);
    let term_summaries: Vec<simterm::TermSummary> = sim_terms
        .first()
        .into_iter()
        .flatten()
        .map(|t| simterm::summarize(t, cause.as_ref().map_or("", |c| c.column.as_str())))
        .collect();
    let to_excl = |(c, r): &(String, String)| Exclusion {
        column: c.clone(),
        reason: r.clone(),
    };
    let report = Report {
        campaign: CampaignSummary {
            runs: campaign.runs.len(),
            points: campaign.points(),
            validation: folds.describe(),
            excluded_columns: campaign.exclusions.clone(),
            skipped_candidates: screening.skipped.iter().map(to_excl).collect(),
            smallest_attainable_p,
        },
        base: ModelSummary {
            name: base.spec.name.clone(),
            poly_degree_t: base.spec.poly_degree_t,
            uses_rate: base.spec.uses_rate,
            inputs: base_inputs,
            heldout_rms_dph: base_rms,
            centres: base.centres,
            width_factor: base.width_factor,
            ridge: base.ridge,
            tried: choice.scores.clone(),
            collinearity_warning: choice.collinearity_warning.clone(),
        },
        residual_structure: structure,
        outliers,
        between_run,
        candidates: screening
            .scored
            .iter()
            .map(|s| CandidateRow {
                column: s.cand.column.clone(),
                transform: s.cand.transform,
                tau_s: s.cand.tau_s,
                mode: s.mode,
                heldout_rms_dph: s.heldout_rms_dph,
                gain_pct: s.gain_pct,
                p_value: s.p_value,
                significant: s.significant,
                units_improved: s.units_improved,
            })
            .collect(),
        named_cause: cause,
        cause_in_words: words,
        competing: screening
            .competing
            .iter()
            .map(|(c, g)| Competitor {
                candidate: c.clone(),
                conditional_gain_pct: *g,
            })
            .collect(),
        parsimony_note: screening.parsimony_note.clone(),
        drift_std: DriftStd {
            uncompensated_dph: crate::stats::pooled_std_of_rows(&folds.run_rows, &st.y),
            baseline_heldout_dph: crate::stats::pooled_std_of_rows(
                &folds.run_rows,
                &base.cv.residual,
            ),
            extended_heldout_dph: crate::stats::pooled_std_of_rows(&folds.run_rows, &ext_resid),
        },
        extended,
        azimuth,
        simulation: Simulation {
            before_rms_dph: sim.before_rms_dph,
            after_rms_dph: sim.after_rms_dph.unwrap_or(sim.before_rms_dph),
            term: term_summaries.first().cloned(),
            terms: term_summaries,
            calibration: sim,
        },
    };
    Ok(Diagnosis {
        report,
        run_names,
        run_rows: folds.run_rows.clone(),
        t_s: st.t_s.clone(),
        drift_dph: base.prepared.target().to_vec(),
        baseline_residual: base.cv.residual.clone(),
        extended_residual: ext_resid,
        cause_feature: named.and_then(|s| s.cols.first().cloned()),
        sim_terms,
    })
}
