//! `diagnose`: from a measured campaign to what the simulation and the paper's model get
//! wrong, the cause, the extended model and its held-out gain (issues 4, 9 and 18).
//!
//! The pipeline, one folder per stage: [`input`] checks the runs and averages them to
//! 10 s ([`input::rawrows`] streams the files and analyses the raw rows on the way);
//! [`base`] chooses the base model on held-out data, with one temperature law across runs
//! or free run levels; [`library`] builds every candidate feature from the record's
//! columns; [`selection`] ranks them by held-out gain, tests them family-wise and checks
//! the test's power when nothing is named; [`between`] does the same for run-level
//! effects; [`simulator`] calibrates the simulator's physics and maps the named cause
//! onto it; [`uncertainty`] puts block-bootstrap ranges on every coefficient; [`report`]
//! states the result, plots it and translates it into north-seeking error.
//! [`validation`] (folds over whole runs or buffered blocks, the sign-flip test) and
//! [`linalg`] serve every stage.

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
pub use report::Report;
pub use selection::cause::Cause;

use crate::io::runs::Run;
use baseline::models::Stacked;
use input::Exclusion;
use report::{
    Azimuth, CampaignSummary, CandidateRow, Competitor, DriftStd, Extended, ModelSummary,
    NamedCause, Simulation,
};
use selection::scored::Scored;
use selection::screen::Screening;
use validation::folds::Folds;

/// Everything the diagnosis computed: the report plus the series the plots need.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    pub report: Report,
    pub run_names: Vec<String>,
    pub run_rows: Vec<std::ops::Range<usize>>,
    /// Validation units (runs, or time blocks of a few long records).
    pub unit_rows: Vec<std::ops::Range<usize>>,
    pub t_s: Vec<f64>,
    /// What `t_s` is, for axis labels: since power-on, or since the record's start.
    pub time_axis: String,
    pub temp_c: Vec<f64>,
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

impl Diagnosis {
    /// Frees the per-row series (only the plots read them; the report keeps everything
    /// else): five or six values per row the later stages of the command need not hold.
    pub fn drop_series(&mut self) {
        for v in [
            &mut self.t_s,
            &mut self.temp_c,
            &mut self.drift_dph,
            &mut self.baseline_residual,
            &mut self.extended_residual,
        ] {
            *v = Vec::new();
        }
        self.cause_feature = None;
    }
}

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
    let latitude = latitude_of(&campaign);
    let meta = candidates::generic::metadata(runs);
    let (library, cap_note) = library_of(&campaign, &meta, st.temp_rate_half_s);
    let (choice, mut screening, base_rule, between_run, groups) =
        screen_both(&campaign, &meta, &folds, &st, choice, &library, latitude)?;
    let base = &choice.chosen;
    screening.skipped.extend(cap_note);
    let named = screening.steps.first();
    let cause = named.map(|s| Cause::from(&s.scored.cand));
    let (sim_design, sim) = simulator_stage(&campaign, &folds, &st, named)?;
    let causal_derivative = named
        .and_then(|s| candidates::causal::check(&campaign, &folds, base, &s.scored.cand, &s.cols));
    let (extended, ext_resid) = extended_model(base, &screening);
    let named_feature = named.map(|s| uncertainty::NamedFeature {
        label: s.scored.cand.label(),
        cols: &s.cols,
    });
    let uncertainty = uncertainty::estimate(&sim_design, &folds, &st, base, named_feature.as_ref());
    // The simulator's design (its rows' times; rows are computed on demand) is not
    // needed past here: freed before the later stages' own per-row peaks (memory).
    memprobe::stage("uncertainty::estimate");
    drop(sim_design);
    let azimuth = azimuth(&campaign, &folds, &st, base, &ext_resid, latitude);
    let named_causes = named_causes(&folds, &st, base, &screening, &between_run, latitude);
    let smallest_attainable_p = validation::signflip::smallest_p(folds.unit_rows.len());
    let silent = cause.is_none() && between_run.named.is_none();
    let rerun = selection::power::Rerun {
        library: &library,
        groups,
    };
    let power_check =
        selection::power::check(silent, &campaign, &folds, &mut st, base, &screening, rerun)?;
    memprobe::stage("power::check");
    let words = cause_in_words(
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
        campaign: CampaignSummary {
            runs: campaign.runs.len(),
            points: campaign.points(),
            validation: folds.describe(),
            excluded_columns: campaign.exclusions.clone(),
            skipped_candidates: screening.skipped.iter().map(to_exclusion).collect(),
            library_size: library.len(),
            smallest_attainable_p,
            power_check,
        },
        base: base_summary(&choice, base_rule, &st, &campaign),
        residual_structure: report::residuals::structure(&campaign, &folds, &st, &base.cv.residual),
        outliers: report::outliers::locate(&folds, &run_names, &st.t_s, &st.y, &base.cv.residual),
        between_run,
        derivative_widths: campaign.derivative_widths.clone(),
        candidates: screening.scored.iter().map(candidate_row).collect(),
        named_causes,
        named_cause: cause,
        cause_in_words: words,
        competing: competing(
            &screening,
            &report::competing::unit_names(&folds, &run_names),
        ),
        parsimony_note: screening
            .steps
            .iter()
            .find_map(|s| s.parsimony_note.clone()),
        drift_std: drift_std(&folds, &st.y, &base.cv.residual, &ext_resid),
        extended,
        causal_derivative,
        azimuth,
        uncertainty,
        raw_rows: None,
        simulation: simulation_summary(sim, &sim_terms, cause_column.as_deref()),
    };
    Ok(Diagnosis {
        report,
        run_names,
        run_rows: folds.run_rows.clone(),
        unit_rows: folds.unit_rows.clone(),
        t_s: st.t_s.clone(),
        time_axis: time_axis(runs),
        temp_c: st.temp_c.to_vec(),
        drift_dph: base.prepared.target().to_vec(),
        baseline_residual: base.cv.residual.clone(),
        extended_residual: ext_resid,
        cause_feature: named.and_then(|s| s.cols.first().cloned()),
        sim_terms,
    })
}

/// The simulator's physics calibrated to the campaign (`simulator`), with its design
/// (the uncertainty stage refits on it).
fn simulator_stage(
    campaign: &input::Campaign,
    folds: &Folds,
    st: &Stacked,
    named: Option<&selection::screen::Step>,
) -> Result<
    (
        sim_fit::calibrate::SimDesign,
        sim_fit::calibrate::SimCalibration,
    ),
    DiagnoseError,
> {
    let sim_design = sim_fit::calibrate::SimDesign::new(campaign);
    memprobe::stage("SimDesign::new");
    let sim = sim_fit::calibrate::calibrate(
        &sim_design,
        &folds.run_rows,
        &st.y,
        named.map(|s| s.cols.as_slice()),
    )?;
    memprobe::stage("simulator::calibrate");
    Ok((sim_design, sim))
}

/// The campaign's latitude (the first run that states one), else the default.
fn latitude_of(campaign: &input::Campaign) -> f64 {
    campaign
        .runs
        .iter()
        .find_map(|s| s.latitude_deg)
        .unwrap_or(report::azimuth::DEFAULT_LATITUDE_DEG)
}

/// The azimuth effect of the base's and the extended model's residuals, when the
/// campaign has a heading column.
fn azimuth(
    campaign: &input::Campaign,
    folds: &Folds,
    st: &Stacked,
    base: &baseline::choice::BaseFit,
    ext_resid: &[f64],
    latitude: f64,
) -> Option<Azimuth> {
    let has_heading = campaign.extra_names.iter().any(|n| n.contains("heading"));
    has_heading.then(|| Azimuth {
        baseline: report::azimuth::azimuth_effect(folds, &st.t_s, &base.cv.residual, latitude),
        extended: report::azimuth::azimuth_effect(folds, &st.t_s, ext_resid, latitude),
    })
}

/// Every candidate within one standard error of a named cause, with the cause and what
/// the units where they differ said.
fn competing(screening: &Screening, unit_names: &[String]) -> Vec<Competitor> {
    screening
        .steps
        .iter()
        .flat_map(|s| {
            let named = s.scored.cand.label();
            s.rivals
                .iter()
                .map(move |r| report::competing::competitor(&named, r, unit_names))
        })
        .collect()
}

/// The generic library and, if the cap left candidates out, a note saying so.
fn library_of(
    campaign: &input::Campaign,
    meta: &[candidates::generic::MetaColumn],
    rate_half_s: f64,
) -> (
    Vec<candidates::transforms::Candidate>,
    Option<selection::screen::Skipped>,
) {
    let (library, left_out) = candidates::generic::enumerate(campaign, meta, rate_half_s);
    memprobe::stage("library");
    let note = (left_out > 0).then(|| {
        (
            format!("{left_out} candidates"),
            format!(
                "library capped at {} candidates",
                candidates::generic::MAX_CANDIDATES
            ),
        )
    });
    (library, note)
}

/// The base by parsimony (`selection::parsimony`) with its within-run selection, then
/// the between-run selection on it; alpha shared between the two sequences (Bonferroni;
/// one sequence when runs are too few for the between-run one). Returns the base, both
/// selections, how the base was chosen and the number of sequences.
fn screen_both(
    campaign: &input::Campaign,
    meta: &[candidates::generic::MetaColumn],
    folds: &Folds,
    st: &Stacked,
    choice: baseline::choice::BaseChoice,
    library: &[candidates::transforms::Candidate],
    latitude_deg: f64,
) -> Result<
    (
        baseline::choice::BaseChoice,
        Screening,
        selection::parsimony::BaseRule,
        between_runs::BetweenRun,
        f64,
    ),
    DiagnoseError,
> {
    let groups = if between_runs::runs_held_out_whole(folds) {
        2.0
    } else {
        1.0
    };
    let (choice, screening, base_rule) = selection::parsimony::choose_and_screen(
        campaign,
        folds,
        st,
        choice,
        library,
        groups,
        selection::screen::MAX_STEPS,
    )?;
    let run_level = between_runs::prepare(
        campaign,
        meta,
        folds,
        st,
        &choice.chosen,
        choice.levels.as_ref(),
    );
    let between_run = match run_level {
        Ok(p) => between_runs::finish(p, groups, latitude_deg),
        Err(note) => between_runs::BetweenRun {
            turn_on_repeatability_dph: f64::NAN,
            offsets_heldout_rms_dph: f64::NAN,
            offsets_from: String::new(),
            rows: vec![],
            named: None,
            named_steps: vec![],
            heading: None,
            note: Some(note),
        },
    };
    memprobe::stage("screen_both");
    Ok((choice, screening, base_rule, between_run, groups))
}

/// The base extended by every named within-run cause (the base itself when nothing is
/// named), and its held-out residual.
fn extended_model(base: &baseline::choice::BaseFit, screening: &Screening) -> (Extended, Vec<f64>) {
    let mut inputs = base.spec.inputs();
    inputs.extend(screening.steps.iter().map(|s| s.scored.cand.label()));
    let cv = screening.final_cv(base);
    memprobe::stage("extended_model + causal::check");
    (
        Extended {
            inputs,
            heldout_rms_dph: cv.rms(),
            gain_pct: selection::scored::gain_pct(base.cv.rms(), cv.rms()),
        },
        cv.residual.clone(),
    )
}

/// Every named cause, within and between runs, ranked by the drop in held-out squared
/// error it brings (the two are in the same units: (deg/h)^2 x points).
fn named_causes(
    folds: &Folds,
    st: &Stacked,
    base: &baseline::choice::BaseFit,
    screening: &Screening,
    between_run: &between_runs::BetweenRun,
    latitude_deg: f64,
) -> Vec<NamedCause> {
    let sigma = |r: &[f64]| {
        report::azimuth::azimuth_effect(folds, &st.t_s, r, latitude_deg).azimuth_sigma_deg
    };
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

/// The chosen base and every base tried, for the report.
fn base_summary(
    choice: &baseline::choice::BaseChoice,
    rule: selection::parsimony::BaseRule,
    st: &Stacked,
    campaign: &input::Campaign,
) -> ModelSummary {
    let base = &choice.chosen;
    ModelSummary {
        name: base.spec.name.clone(),
        poly_degree_t: base.spec.poly_degree_t,
        uses_rate: base.spec.uses_rate,
        rate_half_width_s: st.temp_rate_half_s,
        rate_effective_half_width_s: input::derivatives::effective_half_width_s(
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

fn candidate_row(s: &Scored) -> CandidateRow {
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
fn drift_std(folds: &Folds, y: &[f64], base_resid: &[f64], ext_resid: &[f64]) -> DriftStd {
    let pooled = |v: &[f64]| crate::stats::pooled_std_of_rows(&folds.run_rows, v);
    DriftStd {
        uncompensated_dph: pooled(y),
        baseline_heldout_dph: pooled(base_resid),
        extended_heldout_dph: pooled(ext_resid),
    }
}

fn to_exclusion((column, reason): &selection::screen::Skipped) -> Exclusion {
    Exclusion {
        column: column.clone(),
        reason: reason.clone(),
    }
}

/// The first within-run cause in words (and the others' labels), else the between-run
/// one, else why nothing is named.
fn cause_in_words(
    cause: Option<&Cause>,
    all: &[NamedCause],
    between_run: &between_runs::BetweenRun,
    coef: &[f64],
    smallest_attainable_p: f64,
    power_check: Option<&selection::power::PowerCheck>,
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
        (None, None) => report::nothing_named(smallest_attainable_p, power_check),
    }
}

/// The simulator before/after and the terms added (listed for the first run).
fn simulation_summary(
    sim: sim_fit::calibrate::SimCalibration,
    sim_terms: &[Vec<crate::sim::DriftTerm>],
    cause_column: Option<&str>,
) -> Simulation {
    let terms: Vec<sim_fit::drift_terms::TermSummary> = sim_terms
        .first()
        .into_iter()
        .flatten()
        .map(|t| sim_fit::drift_terms::summarize(t, cause_column.unwrap_or("")))
        .collect();
    Simulation {
        before_rms_dph: sim.before_rms_dph,
        after_rms_dph: sim.after_rms_dph.unwrap_or(sim.before_rms_dph),
        term: terms.first().cloned(),
        terms,
        calibration: sim,
    }
}

/// "time since power-on" when every run says how it was powered on (`start` metadata)
/// and none says it is not a power-on record; else the record's own time.
fn time_axis(runs: &[Run]) -> String {
    let power_on = runs.iter().all(|r| r.meta_value("start").is_some())
        && !runs.iter().any(|r| {
            r.meta_value("note")
                .is_some_and(|n| n.contains("not a power-on"))
        });
    if power_on {
        "time since power-on".into()
    } else {
        "t_s (time since the record's start)".into()
    }
}
