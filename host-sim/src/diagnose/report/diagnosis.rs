//! What `diagnose` hands back: the report plus the per-row series the plots draw. Lives in
//! the report stage (not in `diagnose/mod.rs`) so the plots can read it without
//! importing the orchestrator.

use crate::diagnose::report::Report;
use crate::io::runs::Run;

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

/// "time since power-on" when every run says how it was powered on (`start` metadata)
/// and none says it is not a power-on record; else the record's own time.
pub fn time_axis(runs: &[Run]) -> String {
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
