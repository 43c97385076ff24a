//! The report in words (stdout), one section after another, and the sentence that says
//! what "nothing named" means. Split from `report/mod.rs`, which holds the report's types
//! (the JSON), because rendering is a job of its own.

use crate::diagnose::report::{CampaignSummary, Report};
use crate::diagnose::selection::cause::Cause;
use std::fmt::Write as _;

/// What "nothing named" means: no structure found, or no test power to find any (too
/// few validation units, or a planted 1-sigma effect that was not named either).
pub fn nothing_named(
    smallest_attainable_p: f64,
    power_check: Option<&crate::diagnose::selection::power::PowerCheck>,
) -> String {
    if smallest_attainable_p >= crate::diagnose::selection::scored::ALPHA {
        return format!(
            "cannot decide: no test power (smallest reachable p {smallest_attainable_p:.4} >= alpha {} with this \
             few validation units); absence of a named cause says nothing about the drift",
            crate::diagnose::selection::scored::ALPHA
        );
    }
    match power_check.map(|pc| (pc, pc.planted.as_deref())) {
        Some((_, None)) => format!(
            "no significant cause: the residual of the chosen base shows no structure that any \
             candidate explains better than chance on held-out data (power not checked: for every \
             shape, each of its {} best-ranked candidates is mostly predicted by the base itself, \
             so an effect of that shape could not be told from the base on this record)",
            crate::diagnose::selection::power::TRIED
        ),
        Some((pc, Some(planted))) if !pc.named => format!(
            "cannot decide: no test power at {} sigma for {} of {} planted shapes (e.g. a copy of {} \
             planted at the residual's own size, {:.4} deg/h rms, was not named: gain {:+.1} %, p {:.4}); \
             absence of a named cause says nothing about effects of that shape and size",
            crate::diagnose::selection::power::PLANTED_SIGMAS,
            pc.shapes.iter().filter(|s| !s.named).count(),
            pc.shapes.len(),
            planted,
            pc.planted_rms_dph,
            pc.gain_pct,
            pc.p_value
        ),
        Some((pc, Some(planted))) => format!(
            "no significant cause: the residual of the chosen base shows no structure that any \
             candidate explains better than chance on held-out data (power check: every one of {} \
             shapes, e.g. {}, planted at {} sigma, {:.4} deg/h rms, is named, p {:.4})",
            pc.shapes.len(),
            planted,
            crate::diagnose::selection::power::PLANTED_SIGMAS,
            pc.planted_rms_dph,
            pc.p_value
        ),
        None => "no significant cause: the residual of the chosen base shows no structure that \
                 any candidate explains better than chance on held-out data"
            .into(),
    }
}

/// Human-readable report, one section after another.
pub fn render_text(r: &Report) -> String {
    let mut s = String::new();
    write_campaign(&mut s, &r.campaign);
    write_baseline(&mut s, r);
    write_residual(&mut s, r);
    write_candidates(&mut s, r);
    write_cause(&mut s, r);
    write_simulator(&mut s, r);
    write_uncertainty(&mut s, &r.uncertainty);
    if let Some(raw) = &r.raw_rows {
        write_raw_rows(&mut s, raw);
    }
    s
}

/// Header: campaign size, validation layout, test power, exclusions.
fn write_campaign(s: &mut String, c: &CampaignSummary) {
    let _ = writeln!(s, "fogsim diagnose: {} runs, {} points (10 s means, or one row per slower sample); validation: {}", c.runs, c.points, c.validation);
    if c.smallest_attainable_p >= crate::diagnose::selection::scored::ALPHA {
        let _ = writeln!(
            s,
            "  note: with this few validation units the smallest attainable p is {:.3} >= alpha {}: no cause can be named",
            c.smallest_attainable_p,
            crate::diagnose::selection::scored::ALPHA
        );
    }
    if let Some((pc, planted)) = c
        .power_check
        .as_ref()
        .and_then(|pc| pc.planted.as_ref().map(|p| (pc, p)))
    {
        let _ = writeln!(
            s,
            "  power check (nothing named): {} of {} shapes named when planted; e.g. a copy of {} planted at {} sigma ({:.4} deg/h rms, orthogonal to the residual) is {}: gain {:+.1} %, p {:.4}",
            pc.shapes.iter().filter(|s| s.named).count(),
            pc.shapes.len(),
            planted,
            crate::diagnose::selection::power::PLANTED_SIGMAS,
            pc.planted_rms_dph,
            if pc.named { "named" } else { "NOT named (no test power at that size)" },
            pc.gain_pct,
            pc.p_value
        );
    }
    for e in &c.excluded_columns {
        let _ = writeln!(s, "  excluded column `{}`: {}", e.column, e.reason);
    }
    if !c.skipped_candidates.is_empty() {
        let _ = writeln!(
            s,
            "  {} candidate(s) skipped (e.g. {}: {})",
            c.skipped_candidates.len(),
            c.skipped_candidates[0].column,
            c.skipped_candidates[0].reason
        );
    }
}

/// Section 1: calibrated simulator and the base chosen on held-out data.
fn write_baseline(s: &mut String, r: &Report) {
    let sim = &r.simulation.calibration;
    let _ = writeln!(s, "\n1. Baseline");
    let _ = writeln!(
        s,
        "  simulator calibrated by least squares: thermal tau {:.0} s / {:.0} s (median over runs), sensor lag {:.1} s (temp rms {:.3} degC), bias {:.4} deg/h/degC, \
         Shupe {:.3} deg/h per degC/s, white noise {:.4} deg/h (10 s)",
        sim.tau_fast_s, sim.tau_slow_s, sim.sensor_lag_s, sim.temp_rms_c, sim.bias_dph_per_c, sim.shupe_dph_per_cps, sim.noise_10s_dph
    );
    let _ = writeln!(
        s,
        "  simulation vs measured drift: rms {:.4} deg/h (run offsets removed)",
        r.simulation.before_rms_dph
    );
    let tried: Vec<String> = r
        .base
        .tried
        .iter()
        .map(|b| {
            let p = b
                .paired_p_vs_best
                .map_or_else(|| " (lowest)".to_owned(), |p| format!(" (p {p:.3})"));
            format!(
                "{} {:.4} +/- {:.4}{p}",
                b.spec.name, b.heldout_rms_dph, b.heldout_se_dph
            )
        })
        .collect();
    let _ = writeln!(
        s,
        "  bases tried (held-out rms +/- standard error, deg/h; run offsets free; paired p that the lowest beats it): {}",
        tried.join(", ")
    );
    let _ = writeln!(
        s,
        "  base rule: {}: {}",
        r.base.rule.rule, r.base.rule.reason
    );
    write_levels(s, r);
    let _ = writeln!(
        s,
        "  chosen base {} ({}; dT/dt over +/-{:.0} s, actual +/-{:.0} s): held-out rms {:.4} deg/h; uncompensated drift std {:.4} deg/h; candidates are screened against it",
        r.base.name,
        r.base.inputs.join(", "),
        r.base.rate_half_width_s,
        r.base.rate_effective_half_width_s,
        r.base.heldout_rms_dph,
        r.drift_std.uncompensated_dph
    );
    if let Some(w) = &r.base.collinearity_warning {
        let _ = writeln!(s, "  warning: {w}");
    }
}

/// The level treatments tried (absolute held-out rms, level included) and the choice.
fn write_levels(s: &mut String, r: &Report) {
    let Some(l) = &r.base.levels else {
        return;
    };
    let tried: Vec<String> = r
        .base
        .tried
        .iter()
        .flat_map(|b| {
            b.levels.iter().map(move |v| {
                format!(
                    "{}/{} {:.4} +/- {:.4}",
                    b.spec.name,
                    match v.law {
                        crate::diagnose::baseline::levels::Law::Shared => "shared",
                        crate::diagnose::baseline::levels::Law::Free => "free",
                    },
                    v.score.heldout_rms_dph,
                    v.score.standard_error_dph
                )
            })
        })
        .collect();
    let _ = writeln!(
        s,
        "  levels (absolute held-out rms of a run never seen, level included, +/- standard error, deg/h): {}",
        tried.join(", ")
    );
    let _ = writeln!(
        s,
        "  levels chosen: {} ({}), {:.4} +/- {:.4} deg/h: the simplest within one standard error of the best, {} {:.4} +/- {:.4}; \
         turn-on repeatability {:.4} deg/h",
        l.base,
        crate::diagnose::baseline::choice::law_name(l.law),
        l.score.heldout_rms_dph,
        l.score.standard_error_dph,
        l.best,
        l.best_heldout_rms_dph,
        l.best_standard_error_dph,
        l.repeatability_dph
    );
}

/// Section 2: the base's held-out residual by time, ambient, signal; the outliers.
fn write_residual(s: &mut String, r: &Report) {
    let _ = writeln!(s, "\n2. What the model gets wrong (held-out residual)");
    for b in &r.residual_structure.by_time {
        let _ = writeln!(
            s,
            "  {:>12}: rms {:.4}  mean {:+.4} deg/h  (n={})",
            b.label, b.rms_dph, b.mean_dph, b.n
        );
    }
    for b in &r.residual_structure.by_ambient {
        let _ = writeln!(
            s,
            "  ambient {:>10}: rms {:.4} deg/h (n={})",
            b.label, b.rms_dph, b.n
        );
    }
    let mut links = r.residual_structure.by_signal.clone();
    links.sort_by(|a, b| b.correlation.abs().total_cmp(&a.correlation.abs()));
    let top: Vec<String> = links
        .iter()
        .take(5)
        .map(|l| format!("{} {:+.2}", l.signal, l.correlation))
        .collect();
    let _ = writeln!(
        s,
        "  within-run correlation with signals: {}",
        top.join(", ")
    );
    let o = &r.outliers;
    let _ = writeln!(
        s,
        "  outliers: {} (beyond {:.2} robust sigma = {:.4} deg/h, or a repeated identical rate)",
        o.count,
        o.threshold_sigma,
        o.threshold_sigma * o.robust_sigma_dph
    );
    for x in o.listed.iter().take(10) {
        let _ = writeln!(
            s,
            "    run {} row {} (t {:.0} s) {}: {:+.1} sigma, value {:.5}; {}",
            x.run, x.row, x.t_s, x.column, x.sigma, x.value, x.pattern
        );
    }
}

/// The validated derivative windows, one line per column.
fn write_derivative_widths(
    s: &mut String,
    widths: &[crate::diagnose::input::derivatives::WidthChoice],
) {
    let _ = writeln!(
        s,
        "  derivative windows (local polynomial, half-width by leave-one-out on the column itself):"
    );
    let mut columns: Vec<&str> = widths.iter().map(|w| w.column.as_str()).collect();
    columns.dedup();
    for col in columns {
        let parts: Vec<String> = widths
            .iter()
            .filter(|w| w.column == col)
            .map(|w| {
                format!(
                    "{} +/-{:.0} s (actual +/-{:.0} s; degree {}, LOO rms {:.3e})",
                    w.derivative,
                    w.half_width_s,
                    w.effective_half_width_s,
                    w.poly_degree,
                    w.loo_rms
                )
            })
            .collect();
        let _ = writeln!(s, "    {col:<14} {}", parts.join("; "));
    }
}

/// The named derivative as the device would compute it (causal), next to the centred one.
fn write_causal(s: &mut String, c: &crate::diagnose::candidates::causal::CausalCheck) {
    let causal: Vec<String> = c
        .causal
        .iter()
        .map(|k| {
            format!(
                "    causal, span {:.0} s, delay {:.1} s ({}): held-out rms {:.4} deg/h, gain {:+.2}% \
                 ({} warm-up rows per run at 0)\n",
                k.span_s, k.delay_s, k.estimator, k.heldout_rms_dph, k.gain_pct, k.warmup_rows
            )
        })
        .collect();
    let _ = write!(
        s,
        "  on the device: centred +/-{:.0} s window: held-out rms {:.4} deg/h, gain {:+.2}% (linear term)\n{}  {}\n",
        c.centred_half_width_s,
        c.centred_heldout_rms_dph,
        c.centred_gain_pct,
        causal.concat(),
        c.in_words
    );
}

/// The within-run library per operator family: counts, cuts with their reasons, and the
/// test's power for each family (a "no test power for family F" line where it has none).
fn write_operator_families(s: &mut String, rows: &[crate::diagnose::report::families::FamilyRow]) {
    let counts: Vec<String> = rows
        .iter()
        .map(|f| {
            let cut = if f.cut_by_cap > 0 {
                format!(" (+{} cut by the cap)", f.cut_by_cap)
            } else {
                String::new()
            };
            format!("{} {}{cut}", f.family, f.candidates)
        })
        .collect();
    let _ = writeln!(
        s,
        "  within-run candidates per operator family: {}",
        counts.join(", ")
    );
    for f in rows {
        if f.candidates == 0 && f.cut_by_cap == 0 && f.why_cut.is_empty() {
            continue;
        }
        let why = if f.why_cut.is_empty() {
            String::new()
        } else {
            format!("; cut: {}", f.why_cut.join("; "))
        };
        let _ = writeln!(s, "    {}: {}{why}", f.family, f.power);
    }
}

/// Section 3: ranked within-run candidates, then the between-run ones.
fn write_candidates(s: &mut String, r: &Report) {
    let _ = writeln!(s, "\n3. Candidate causes, first step (ranked by held-out rms; p = family-wise sign-flip max-T over the library and whole validation units, x sequences)");
    write_derivative_widths(s, &r.derivative_widths);
    write_operator_families(s, &r.campaign.operator_families);
    for row in r.candidates.iter().take(8) {
        let _ = writeln!(
            s,
            "  {:<38} rms {:.4}  gain {:+6.2}%  p {:.4}  units improved {:>3.0}%{}",
            row.label,
            row.heldout_rms_dph,
            row.gain_pct,
            row.p_value,
            100.0 * row.units_improved,
            if row.significant { "  *" } else { "" }
        );
    }
    let b = &r.between_run;
    if let Some(n) = &b.note {
        let _ = writeln!(s, "  between runs: not tested ({n})");
        return;
    }
    let _ = writeln!(
        s,
        "  between runs (run offsets left by {}: rms {:.4} deg/h about their leave-one-out mean; turn-on repeatability {:.4} deg/h; p in the same family):",
        b.offsets_from, b.offsets_heldout_rms_dph, b.turn_on_repeatability_dph
    );
    let families: Vec<String> = b
        .candidate_families
        .iter()
        .map(|f| format!("{} {}", f.family, f.candidates))
        .collect();
    let _ = writeln!(
        s,
        "  run-level candidates per family: {} (power not checked per run-level family: the planted-shape check plants within-run shapes)",
        families.join(", ")
    );
    for row in b.rows.iter().take(4) {
        let _ = writeln!(
            s,
            "  {:<28} offset rms {:.4}  gain {:+6.2}%  p {:.4}  (run permutation p {:.4}){}",
            row.label,
            row.heldout_offset_rms_dph,
            row.gain_pct,
            row.p_value,
            row.permutation_p,
            if row.significant { "  *" } else { "" }
        );
    }
}

/// Section 4: the named cause, competitors, heading effect, extended model, azimuth.
fn write_cause(s: &mut String, r: &Report) {
    let _ = writeln!(s, "\n4. Cause");
    let named = r.named_cause.as_ref().map_or("none".into(), Cause::label);
    let _ = writeln!(s, "  named within runs first: {named}");
    for c in &r.named_causes {
        let _ = writeln!(
            s,
            "  named ({}, step {}): {}  conditional held-out gain {:+.2}%, p {:.4}{}",
            c.level,
            c.step,
            c.label,
            c.conditional_gain_pct,
            c.p_value,
            match (
                c.azimuth_sigma_deg_before,
                c.azimuth_sigma_deg_after,
                c.azimuth_error_bound_deg
            ) {
                (Some(a), Some(b), _) => format!(", azimuth 1 sigma {a:.4} -> {b:.4} deg"),
                (_, _, Some(e)) => format!(", azimuth error up to {e:.3} deg"),
                _ => String::new(),
            }
        );
    }
    let _ = writeln!(s, "  {}", r.cause_in_words);
    if let Some(n) = &r.parsimony_note {
        let _ = writeln!(s, "  {n}");
    }
    for comp in &r.competing {
        let _ = writeln!(
            s,
            "  competes with {}: {} is within {:.2} standard errors over all held-out data (gain {:+.2}%); {}",
            comp.named, comp.candidate, comp.gap_se, comp.conditional_gain_pct, comp.in_words
        );
    }
    if let Some(c) = &r.causal_derivative {
        write_causal(s, c);
    }
    let b = &r.between_run;
    if let Some(n) = &b.named {
        let _ = writeln!(s, "  named between runs: {n}");
    }
    if let Some(h) = &b.heading {
        let _ = writeln!(
            s,
            "  heading-dependent bias: amplitude {:.4} deg/h, maximum at {} = {:.0} deg; two-position seek azimuth error {:+.3} deg at psi 90 deg (up to {:.3} deg where |sin psi| >= 0.5, lat {:.1})",
            h.amplitude_dph, h.column, h.phase_deg, h.azimuth_error_at_90_deg, h.azimuth_error_bound_deg, h.latitude_deg
        );
    }
    let e = &r.extended;
    let _ = writeln!(
        s,
        "  extended model ({}): held-out rms {:.4} deg/h, gain {:+.2}% ; drift std {:.4} -> {:.4} -> {:.4} deg/h (raw -> base -> extended)",
        e.inputs.join(", "),
        e.heldout_rms_dph,
        e.gain_pct,
        r.drift_std.uncompensated_dph,
        r.drift_std.baseline_heldout_dph,
        r.drift_std.extended_heldout_dph
    );
    if let Some(a) = &r.azimuth {
        let _ = writeln!(
            s,
            "  azimuth (two-position seek, {:.0} s dwells, lat {:.1}, psi 90 deg): 1 sigma {:.4} deg -> {:.4} deg",
            a.baseline.dwell_s, a.baseline.latitude_deg, a.baseline.azimuth_sigma_deg, a.extended.azimuth_sigma_deg
        );
    }
}

/// Section 5: the simulator extended with the named effect.
fn write_simulator(s: &mut String, r: &Report) {
    let _ = writeln!(s, "\n5. Simulator extended with the named effect");
    if r.named_cause.is_none() {
        let _ = writeln!(
            s,
            "  no named effect: the simulator is left as calibrated (rms {:.4} deg/h)",
            r.simulation.before_rms_dph
        );
        return;
    }
    let _ = writeln!(
        s,
        "  sim vs measured rms: {:.4} -> {:.4} deg/h (fitted coefficient(s) of the new term: {:?})",
        r.simulation.before_rms_dph,
        r.simulation.after_rms_dph,
        r.simulation.calibration.effect_coef
    );
    for t in &r.simulation.terms {
        let tau = t.tau_s.map_or(String::new(), |v| format!(", tau {v:.0} s"));
        let _ = writeln!(
            s,
            "  simulator extended with: {} = {:.4e} deg/h x {}({}{tau}) (fog_sim::sim::DriftTerm)",
            t.label, t.coeff_dph, t.transform, t.source
        );
    }
}

/// Section 6: every fitted coefficient with its bootstrap range, ratios to the simulator.
fn write_uncertainty(s: &mut String, u: &crate::diagnose::uncertainty::Uncertainty) {
    let _ = writeln!(s, "\n6. Coefficients with +/- ({})", u.method);
    let groups = [
        ("base", &u.base),
        ("extension", &u.extension),
        ("calibrated simulator", &u.simulator),
    ];
    for (what, list) in groups {
        for e in list {
            let _ = writeln!(
                s,
                "  {what}: {} = {:.4e} +/- {:.2e} {} (95 %: {:.4e} .. {:.4e})",
                e.name, e.value, e.plus_minus, e.unit, e.ci95[0], e.ci95[1]
            );
        }
    }
    for r in &u.ratios {
        let _ = writeln!(
            s,
            "  measured / simulator, {}: {:.4e} +/- {:.2e} vs {:.4e} {} -> ratio {:.3} +/- {:.3}",
            r.name,
            r.measured,
            r.measured_plus_minus,
            r.simulator,
            r.unit,
            r.ratio.value,
            r.ratio.plus_minus
        );
    }
}

/// Section 7: Allan deviation, quantisation and steps of the raw rows.
fn write_raw_rows(s: &mut String, raw: &crate::diagnose::input::rawrows::RawRows) {
    let _ = writeln!(
        s,
        "\n7. Raw rows ({} rows, period {:.4} s; drift = rate_dph - earth_dph, runs pooled, never across a gap)",
        raw.rows, raw.sample_period_s
    );
    let pts: Vec<String> = raw
        .allan
        .iter()
        .map(|p| format!("{:.4}s {:.3e}", p.tau_s, p.adev_dph))
        .collect();
    let _ = writeln!(s, "  Allan deviation, deg/h: {}", pts.join(", "));
    match (raw.arw_dpsh, raw.arw_plus_minus_dpsh) {
        (Some(n), Some(pm)) => {
            let sim = crate::sim::GyroParams::paper_default().noise.arw_dpsh;
            let _ = writeln!(
                s,
                "  ARW (IEEE 952 N, -1/2 slope over tau {} s): {n:.3e} +/- {pm:.1e} deg/sqrt(h); simulator {sim:.1e}: ratio {:.3} +/- {:.3}",
                raw.arw_fit_taus_s.iter().map(|t| format!("{t:.4}")).collect::<Vec<_>>().join(", "),
                n / sim,
                pm / sim
            );
        }
        _ => {
            let _ = writeln!(s, "  ARW: no -1/2 slope in the Allan deviation (white rate noise not dominant at any tau measured)");
        }
    }
    if let (Some(b), Some(t)) = (raw.bias_instability_dph, raw.bias_instability_tau_s) {
        let _ = writeln!(
            s,
            "  bias instability (IEEE 952 B = sigma_min / 0.664): {b:.3e} deg/h at tau {t:.4} s; {}",
            raw.bias_instability_note
        );
    }
    for q in &raw.quantisation {
        let _ = writeln!(
            s,
            "  {}: smallest step {:.6e}; {}",
            q.column,
            q.smallest_step,
            if q.quantised {
                "quantised (every step a multiple of it)"
            } else {
                "not quantised at this step"
            }
        );
    }
    let st = &raw.steps;
    let _ = writeln!(
        s,
        "  steps of the drift (two {}-row windows, > {} sigma): {}",
        st.window_rows, st.threshold_sigma, st.count
    );
    for x in &st.listed {
        let _ = writeln!(
            s,
            "    {} t {:.1} s: {:+.4e} deg/h ({:+.1} sigma)",
            x.run, x.t_s, x.size_dph, x.sigma
        );
    }
    for n in &raw.notes {
        let _ = writeln!(s, "  note: {n}");
    }
}
