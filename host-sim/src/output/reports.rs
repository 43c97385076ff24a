//! Report plumbing shared by `compensate`, `north-seek`, `reproduce` and `demo`:
//! the JSON report structures (their shape is the contract of issue 3), JSON output through
//! the one atomic writer ([`crate::io::atomic`]) and a plain-text table for the terminal.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

/// Serialises `value` as pretty JSON and writes it atomically to `path`.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    crate::io::write_atomic(path, text.as_bytes())
        .map_err(|e| anyhow::anyhow!("{}: cannot write JSON report: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------
// compensate

/// Drift figures of one record (or the pool of records), all from 10 s means with Earth rate removed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DriftStats {
    /// 1 sigma of the 10 s means (pooled over runs for `overall`), deg/h.
    pub std_dph: f64,
    /// Largest |10 s mean - settled mean| (largest over runs for `overall`), deg/h.
    pub max_dev_dph: f64,
    /// Time since power-on after which the 5-min moving std stays under the spec, s;
    /// `null` if it never does (for `overall`: the worst run, `null` if any run never does).
    pub time_to_spec_s: Option<f64>,
}

/// One record's before/after figures.
#[derive(Clone, Debug, Serialize)]
pub struct CompensatedRun {
    pub file: String,
    pub ambient_c: Option<f64>,
    pub before: DriftStats,
    pub after: DriftStats,
    /// 10 s windows whose inputs lay outside the model's trained range (compensated anyway,
    /// flagged by fog-core's compensator).
    pub out_of_range_windows: usize,
}

/// Pooled before/after figures.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BeforeAfter {
    pub before: DriftStats,
    pub after: DriftStats,
}

/// `fogsim compensate --json` output.
#[derive(Clone, Debug, Serialize)]
pub struct CompensateReport {
    pub runs: Vec<CompensatedRun>,
    pub overall: BeforeAfter,
    /// The spec the time-to-spec figures refer to, deg/h (1 sigma of 10 s means).
    pub spec_dph: f64,
}

// ---------------------------------------------------------------------------------------------
// north-seek

/// Azimuth statistics of all seeks of one arm (with or without compensation).
#[derive(Clone, Debug, Serialize)]
pub struct SeekStats {
    /// 1 sigma of all azimuth errors (about their mean), deg.
    pub std_deg: f64,
    /// Largest |azimuth - true azimuth| over all seeks, deg.
    pub max_dev_deg: f64,
    /// Mean azimuth error (azimuth - true), deg.
    pub mean_error_deg: f64,
    /// Root mean square azimuth error against the truth, deg.
    pub rms_error_deg: f64,
    /// Rms error (about the true azimuth) of each seek index over the starts, deg.
    pub per_seek_rms_error_deg: Vec<f64>,
    /// 1 sigma (about that seek's mean error) of each seek index over the starts, deg.
    pub per_seek_std_deg: Vec<f64>,
    /// Mean error of each seek index over the starts, deg.
    pub per_seek_mean_error_deg: Vec<f64>,
    /// Finished seeks per seek index (a seek every attempt of which was refused has none,
    /// and NaN figures).
    pub per_seek_results: Vec<usize>,
    /// Mean over starts of (max - min) of the seeks of one start: the paper's "max deviation", deg.
    pub mean_range_deg: f64,
    /// Mean over starts of the 1 sigma of the seeks of one start (the paper's std), deg.
    pub mean_within_start_std_deg: f64,
    /// Mean 1-sigma uncertainty the north finder reported, deg.
    pub mean_reported_sigma_deg: f64,
    /// Every azimuth, `[start][seek]`, deg (0..360).
    pub azimuths_deg: Vec<Vec<f64>>,
    /// How often seeks were refused, restarted or flagged.
    pub reliability: SeekReliability,
}

/// Refusals and restarts of the seeks of one arm (a refusal is an attempt that ended
/// without a result: blocked at its start, stopped by the finder or by too much motion).
#[derive(Clone, Debug, Serialize)]
pub struct SeekReliability {
    /// Seek attempts: finished + refused.
    pub attempts: usize,
    pub finished: usize,
    pub refused: usize,
    /// Seeks given up after every allowed attempt was refused.
    pub failed_seeks: usize,
    /// refused / attempts.
    pub refusal_rate: f64,
    /// Finished seeks that the supervisor restarted at least once for motion, and the
    /// restarts in total.
    pub restarted_seeks: usize,
    pub restarts: usize,
    /// restarted_seeks / attempts.
    pub restart_rate: f64,
    /// Finished seeks the latitude check flagged.
    pub latitude_flags: usize,
    /// Refusals by reason.
    pub refusal_reasons: std::collections::BTreeMap<String, usize>,
    /// Power-ons whose compensator found them not to be a cold start of the model's
    /// (its cold-start envelope), of `power_ons`.
    pub warm_restarts_detected: usize,
    pub power_ons: usize,
}

/// `fogsim north-seek --json` output.
#[derive(Clone, Debug, Serialize)]
pub struct NorthSeekReport {
    pub starts: usize,
    pub seeks_per_start: usize,
    pub positions: u8,
    /// The positions in a time-symmetric sequence (`--sequence symmetric`); written only
    /// when true, so a forward seek's report keeps its bytes.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub symmetric: bool,
    /// The time-symmetric positions in Thue-Morse order (`--sequence thue-morse`, with
    /// `symmetric`); written only when true, so the other sequences keep their bytes.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub thue_morse: bool,
    pub latitude_deg: f64,
    pub ambient_c: f64,
    /// Gyro temperature above the ambient at power-on, degC (0: cold start from a soak).
    pub restart_above_ambient_c: f64,
    pub true_azimuth_deg: f64,
    /// Duration of one seek from its start to its result, s (mean over all seeks).
    pub seek_duration_s: f64,
    /// Longest single seek, s.
    pub max_seek_duration_s: f64,
    /// Measuring time actually used per main position, s (whole 10 s windows).
    pub main_dwell_s: f64,
    /// The paper's seek time, s (4 min 56 s), for comparison.
    pub paper_seek_duration_s: f64,
    /// White-noise floor of the azimuth for the simulated ARW and this seek plan, deg.
    pub noise_floor_deg: f64,
    pub arw_dpsh: f64,
    pub seed: u64,
    pub uncompensated: SeekStats,
    pub compensated: SeekStats,
    /// Where the model came from (file or "trained on a default simulated campaign").
    pub model_source: String,
}

// ---------------------------------------------------------------------------------------------
// text tables

/// A plain-text table with right-aligned columns (first column left-aligned).
#[derive(Clone, Debug, Default)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column headings.
    pub fn new<S: ToString>(header: &[S]) -> Self {
        Self {
            header: header.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends one row (cells beyond the header are kept, missing ones are blank).
    pub fn row<S: ToString>(&mut self, cells: &[S]) {
        self.rows
            .push(cells.iter().map(|c| c.to_string()).collect());
    }

    /// Renders the table with a rule under the header.
    pub fn render(&self) -> String {
        let ncol = self
            .rows
            .iter()
            .map(Vec::len)
            .chain([self.header.len()])
            .max()
            .unwrap_or(0);
        let width = |c: usize| {
            self.rows
                .iter()
                .chain([&self.header])
                .filter_map(|r| r.get(c))
                .map(|s| s.chars().count())
                .max()
                .unwrap_or(0)
        };
        let widths: Vec<usize> = (0..ncol).map(width).collect();
        let mut out = String::new();
        let line = |out: &mut String, cells: &[String]| {
            let mut text = String::new();
            for (c, w) in widths.iter().enumerate() {
                let cell = cells.get(c).map(String::as_str).unwrap_or("");
                if c == 0 {
                    let _ = write!(text, "{cell:<w$}");
                } else {
                    let _ = write!(text, "  {cell:>w$}");
                }
            }
            out.push_str(text.trim_end());
            out.push('\n');
        };
        line(&mut out, &self.header);
        let total: usize = widths.iter().sum::<usize>() + 2 * widths.len().saturating_sub(1);
        out.push_str(&"-".repeat(total));
        out.push('\n');
        for r in &self.rows {
            line(&mut out, r);
        }
        out
    }
}

/// A progress bar on stderr for `len` steps (hidden automatically when stderr is not a terminal).
pub fn progress_bar(len: usize, message: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg:<28} [{bar:40}] {pos}/{len} {elapsed_precise}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_string());
    bar
}

/// Column headers of the before/after drift comparison shared by the terminal tables.
pub const DRIFT_COLUMNS: [&str; 6] = [
    "std before",
    "std after",
    "max dev before",
    "max dev after",
    "to spec before",
    "to spec after",
];

/// The cells under `DRIFT_COLUMNS` for one before/after pair.
pub fn drift_cells(before: &DriftStats, after: &DriftStats) -> [String; 6] {
    [
        format!("{:.4}", before.std_dph),
        format!("{:.4}", after.std_dph),
        format!("{:.4}", before.max_dev_dph),
        format!("{:.4}", after.max_dev_dph),
        fmt_minutes(before.time_to_spec_s),
        fmt_minutes(after.time_to_spec_s),
    ]
}

/// Formats an optional time in seconds as minutes ("12.5 min"), "never" when absent.
pub fn fmt_minutes(t_s: Option<f64>) -> String {
    match t_s {
        Some(t) => format!("{:.1} min", t / 60.0),
        None => "never".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_aligns_columns() {
        let mut t = Table::new(&["quantity", "paper", "us"]);
        t.row(&["std", "0.034", "0.1"]);
        t.row(&["x", "1", "22.25"]);
        let s = t.render();
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[2], "std       0.034    0.1");
        assert_eq!(lines[3], "x             1  22.25");
    }
}
