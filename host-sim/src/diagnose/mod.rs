//! `diagnose`: from a measured campaign to what the simulation and the paper's model get
//! wrong, the cause, the extended model and its held-out gain (issues 4, 9 and 18).
//!
//! The pipeline, one folder per stage, each importing only the stages before it (and the
//! ground floor below):
//!
//! [`input`] -> [`baseline`] -> [`candidates`] -> [`selection`] -> [`between_runs`] ->
//! [`sim_fit`] -> [`uncertainty`] -> [`report`]
//!
//! - [`input`] checks the runs, averages them to 10 s and chooses each column's
//!   derivative widths ([`input::rawrows`] streams the files and analyses the raw rows);
//! - [`baseline`] chooses the base model and the validation layout on held-out data, with
//!   one temperature law across runs or free run levels;
//! - [`candidates`] builds every candidate feature from the record's columns;
//! - [`selection`] ranks them by held-out gain, tests them family-wise, separates the
//!   named cause from its rivals and checks the test's power when nothing is named;
//! - [`between_runs`] does the same for run-level effects, alpha shared with the
//!   within-run sequence;
//! - [`sim_fit`] calibrates the simulator's physics to the record and maps the named
//!   cause onto its drift terms;
//! - [`uncertainty`] puts block-bootstrap ranges on every coefficient;
//! - [`report`] assembles the result, states it, plots it and translates it into
//!   north-seeking error.
//!
//! Ground floor, used by every stage and importing none: [`validation`] (folds over
//! whole runs or buffered time blocks, the ridge fits on them, the sign-flip test,
//! designs), [`linalg`], [`error`], [`memprobe`]. This file only calls the stages in
//! order and hands their outputs on.

pub mod baseline;
pub mod between_runs;
pub mod candidates;
pub mod error;
pub mod input;
pub mod linalg;
pub mod memprobe;
pub mod report;
pub mod selection;
pub mod sim_fit;
pub mod uncertainty;
pub mod validation;

pub use error::DiagnoseError;
pub use report::diagnosis::Diagnosis;
pub use report::Report;
pub use selection::cause::Cause;

use crate::io::runs::Run;
use report::assemble;

/// Runs the whole diagnosis on a campaign.
pub fn diagnose(runs: &[Run]) -> Result<Diagnosis, DiagnoseError> {
    diagnose_with(runs, validation::buffer::BufferRule::default())
}

/// [`diagnose`] with a chosen rule for the buffers between time blocks of single records.
pub fn diagnose_with(
    runs: &[Run],
    rule: validation::buffer::BufferRule,
) -> Result<Diagnosis, DiagnoseError> {
    let campaign = input::prepare(runs)?;
    memprobe::stage("input::prepare");
    let (folds, mut st, choice) = baseline::layout::layout_and_base(&campaign, rule)?;
    let run_names: Vec<String> = campaign.runs.iter().map(|s| s.name.clone()).collect();
    let latitude = assemble::latitude_of(&campaign);
    let meta = candidates::metadata::metadata(runs);
    let (built, cap_note) = candidates::library_of(&campaign, &meta, &st, &folds, &choice.chosen);
    let library = &built.candidates;
    let (choice, mut screening, base_rule, between_run, groups) =
        between_runs::screen_both(&campaign, &meta, &folds, &st, choice, library, latitude)?;
    let base = &choice.chosen;
    screening.skipped.extend(cap_note);
    let named = screening.steps.first();
    let cause = named.map(|s| Cause::from(&s.scored.cand));
    let (sim_design, sim) = sim_fit::calibrate_stage(&campaign, &folds, &st, named)?;
    let causal_derivative = named
        .and_then(|s| candidates::causal::check(&campaign, &folds, base, &s.scored.cand, &s.cols));
    let (extended, ext_resid) = assemble::extended_model(base, &screening);
    let named_feature = named.map(|s| uncertainty::NamedFeature {
        label: s.scored.cand.label(),
        cols: &s.cols,
    });
    let uncertainty = uncertainty::estimate(&sim_design, &folds, &st, base, named_feature.as_ref());
    // The simulator's design (its rows' times; rows are computed on demand) is not
    // needed past here: freed before the later stages' own per-row peaks (memory).
    memprobe::stage("uncertainty::estimate");
    drop(sim_design);
    let azimuth = assemble::azimuth(&campaign, &folds, &st, base, &ext_resid, latitude);
    let named_causes =
        assemble::named_causes(&folds, &st, base, &screening, &between_run, latitude);
    let smallest_attainable_p = validation::signflip::smallest_p(folds.unit_rows.len());
    let silent = cause.is_none() && between_run.named.is_none();
    let rerun = selection::power::Rerun { library, groups };
    let power_check =
        selection::power::check(silent, &campaign, &folds, &mut st, base, &screening, rerun)?;
    memprobe::stage("power::check");
    let words = assemble::cause_in_words(
        cause.as_ref(),
        &named_causes,
        &between_run,
        &sim.effect_coef,
        smallest_attainable_p,
        power_check.as_ref(),
    );
    let sim_terms = sim_fit::drift_terms::terms_per_run(runs, cause.as_ref(), &sim.effect_coef);
    let cause_column = cause.as_ref().map(|c| c.column.clone());
    let report = Report {
        campaign: assemble::campaign_summary(
            &campaign,
            &folds,
            &screening,
            &built,
            smallest_attainable_p,
            (silent, power_check),
        ),
        base: assemble::base_summary(&choice, base_rule, &st, &campaign),
        residual_structure: report::residuals::structure(&campaign, &folds, &st, &base.cv.residual),
        outliers: report::outliers::locate(&folds, &run_names, &st.t_s, &st.y, &base.cv.residual),
        between_run,
        derivative_widths: campaign.derivative_widths.clone(),
        candidates: screening
            .scored
            .iter()
            .map(assemble::candidate_row)
            .collect(),
        named_causes,
        named_cause: cause,
        cause_in_words: words,
        competing: assemble::competing(
            &screening,
            &report::competing::unit_names(&folds, &run_names),
        ),
        parsimony_note: screening
            .steps
            .iter()
            .find_map(|s| s.parsimony_note.clone()),
        drift_std: assemble::drift_std(&folds, &st.y, &base.cv.residual, &ext_resid),
        extended,
        causal_derivative,
        azimuth,
        uncertainty,
        raw_rows: None,
        simulation: assemble::simulation_summary(sim, &sim_terms, cause_column.as_deref()),
    };
    Ok(Diagnosis {
        report,
        run_names,
        run_rows: folds.run_rows.clone(),
        unit_rows: folds.unit_rows.clone(),
        t_s: st.t_s.clone(),
        time_axis: report::diagnosis::time_axis(runs),
        temp_c: st.temp_c.to_vec(),
        drift_dph: base.prepared.target().to_vec(),
        baseline_residual: base.cv.residual.clone(),
        extended_residual: ext_resid,
        cause_feature: named.and_then(|s| s.cols.first().cloned()),
        sim_terms,
    })
}
