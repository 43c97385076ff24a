//! Rows of any rate (1 kHz raw, 1 Hz, already 10 s means) averaged into 10 s windows in
//! fog-core's convention, while streaming: memory grows with the number of windows, not
//! of rows.
//!
//! Convention (the one `compensate` feeds fog-core's compensator with): a row stamped `t`
//! covers `(t - period, t]`; its midpoint `t - period/2` falls in window
//! `k = floor(mid / WINDOW_S)`, i.e. `[k W, (k+1) W)` as in `fog_core::compensation::features::
//! WindowAverager`; the window's row is stamped with its end `(k+1) W` and holds the mean
//! of every other column. `period` is the median spacing of the first [`LEAD_ROWS`]
//! rows. A record whose period is already >= 0.95 W is a record of window means: its rows
//! are passed through unchanged, so existing 10 s files bin to exactly themselves.

use std::path::Path;

use fog_core::consts::WINDOW_S;

use super::reader::RunReader;
use super::runs::{Run, RunError};

/// Window length, s (fog-core's).
pub const BIN_WINDOW_S: f64 = WINDOW_S as f64;
/// Rows whose spacings set the sample period (buffered until then).
pub const LEAD_ROWS: usize = 65;
/// A period at least this fraction of the window means the rows already are window means.
pub const ALREADY_BINNED_FRACTION: f64 = 0.95;

/// The window being filled.
struct OpenWindow {
    index: i64,
    sums: Vec<f64>,
    rows: u32,
}

/// Averages a stream of rows (`values[t_index]` is `t_s`) into 10 s windows.
pub struct WindowBinner {
    t_index: usize,
    period_s: Option<f64>,
    lead: Vec<Vec<f64>>,
    open: Option<OpenWindow>,
    out: Vec<Vec<f64>>,
}

impl WindowBinner {
    /// A binner for rows of `columns` values whose time is column `t_index`.
    pub fn new(columns: usize, t_index: usize) -> Self {
        assert!(t_index < columns, "t_index inside the row");
        WindowBinner {
            t_index,
            period_s: None,
            lead: Vec::with_capacity(LEAD_ROWS),
            open: None,
            out: vec![Vec::new(); columns],
        }
    }

    /// Adds one row (times strictly increasing, as the reader guarantees).
    pub fn push(&mut self, values: &[f64]) {
        match self.period_s {
            Some(p) => self.bin(values, p),
            None => {
                self.lead.push(values.to_vec());
                if self.lead.len() == LEAD_ROWS {
                    self.settle_period();
                }
            }
        }
    }

    fn settle_period(&mut self) {
        let mut dt: Vec<f64> = self
            .lead
            .windows(2)
            .map(|w| w[1][self.t_index] - w[0][self.t_index])
            .collect();
        dt.sort_by(f64::total_cmp);
        let period = dt.get(dt.len() / 2).copied().unwrap_or(BIN_WINDOW_S);
        self.period_s = Some(period);
        for row in std::mem::take(&mut self.lead) {
            self.bin(&row, period);
        }
    }

    fn bin(&mut self, values: &[f64], period_s: f64) {
        if period_s >= ALREADY_BINNED_FRACTION * BIN_WINDOW_S {
            for (col, &v) in self.out.iter_mut().zip(values) {
                col.push(v);
            }
            return;
        }
        let mid_s = values[self.t_index] - 0.5 * period_s;
        let index = (mid_s / BIN_WINDOW_S).floor() as i64;
        if self.open.as_ref().is_some_and(|w| w.index != index) {
            self.close();
        }
        let w = self.open.get_or_insert_with(|| OpenWindow {
            index,
            sums: vec![0.0; values.len()],
            rows: 0,
        });
        for (s, &v) in w.sums.iter_mut().zip(values) {
            *s += v;
        }
        w.rows += 1;
    }

    fn close(&mut self) {
        if let Some(w) = self.open.take() {
            for (i, (col, sum)) in self.out.iter_mut().zip(&w.sums).enumerate() {
                col.push(if i == self.t_index {
                    (w.index + 1) as f64 * BIN_WINDOW_S
                } else {
                    sum / f64::from(w.rows)
                });
            }
        }
    }

    /// The sample period used, s (None until set: fewer than [`LEAD_ROWS`] rows pushed).
    pub fn period_s(&self) -> Option<f64> {
        self.period_s
    }

    /// Ends the stream: the windows' columns (`out[c][window]`).
    pub fn finish(mut self) -> Vec<Vec<f64>> {
        if self.period_s.is_none() {
            self.settle_period();
        }
        self.close();
        self.out
    }
}

/// Reads a fog-runs file of any rate as 10 s windows (see the module doc), streaming.
pub fn read_binned(path: impl AsRef<Path>) -> Result<Run, RunError> {
    let mut reader = RunReader::open(path)?;
    let header = reader.header().clone();
    let t_index = header.column_index("t_s").unwrap_or(0);
    let mut binner = WindowBinner::new(header.columns.len(), t_index);
    let mut values = Vec::new();
    while reader.next_row_into(&mut values)?.is_some() {
        binner.push(&values);
    }
    Ok(Run {
        path: header.path,
        meta: header.meta,
        columns: header.columns,
        data: binner.finish(),
    })
}

/// [`read_binned`] over files and directories, as [`super::runs::read_runs`] lists them.
pub fn read_runs_binned<P: AsRef<Path>>(paths: &[P]) -> Result<Vec<Run>, RunError> {
    let mut runs = Vec::new();
    for file in super::runs::run_files(paths)? {
        runs.push(read_binned(&file)?);
    }
    Ok(runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binned(t: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut b = WindowBinner::new(2, 0);
        for (&t, &y) in t.iter().zip(y) {
            b.push(&[t, y]);
        }
        let mut out = b.finish();
        let y = out.pop().unwrap();
        (out.pop().unwrap(), y)
    }

    /// Two physical laws (exponential warm-up, sinusoidal wander), each sampled at
    /// 1 kHz and at 1 Hz: the 10 s means agree to the sampling error of the mean.
    #[test]
    fn any_rate_gives_the_same_ten_second_means() {
        let laws: [fn(f64) -> f64; 2] = [
            |t| 0.5 * (-t / 600.0).exp(),
            |t| 0.02 * (t / 97.0).sin() + 0.001 * t / 60.0,
        ];
        for law in laws {
            let fast_t: Vec<f64> = (1..=600_000).map(|i| i as f64 * 1e-3).collect();
            let slow_t: Vec<f64> = (1..=600).map(|i| i as f64).collect();
            let fast = binned(
                &fast_t,
                &fast_t.iter().map(|&t| law(t - 5e-4)).collect::<Vec<_>>(),
            );
            let slow = binned(
                &slow_t,
                &slow_t.iter().map(|&t| law(t - 0.5)).collect::<Vec<_>>(),
            );
            assert_eq!(fast.0, slow.0);
            assert_eq!(fast.0.len(), 60);
            assert_eq!(fast.0[0], 10.0);
            for (a, b) in fast.1.iter().zip(&slow.1) {
                // 1 Hz midpoints sample the same window; the law's curvature over 1 s is the error.
                assert!((a - b).abs() < 1e-5, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn ten_second_rows_pass_through_unchanged() {
        let t: Vec<f64> = (1..=30)
            .map(|i| i as f64 * 10.0 + 0.003 * i as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|t| (t / 77.0).cos()).collect();
        assert_eq!(binned(&t, &y), (t, y));
    }

    #[test]
    fn short_records_still_bin() {
        let t = [0.5, 1.5, 2.5, 10.5, 11.5];
        let (wt, wy) = binned(&t, &[1.0, 2.0, 3.0, 10.0, 20.0]);
        assert_eq!(wt, vec![10.0, 20.0]);
        assert_eq!(wy, vec![2.0, 15.0]);
    }
}
