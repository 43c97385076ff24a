//! The raw rows before averaging (issue 9 item 4): Allan deviation of the drift (ARW on
//! the -1/2 slope, bias instability at the flat minimum, IEEE Std 952 terms),
//! quantisation (smallest step of the thermometer and of the rate) and steps, all
//! computed while the rows stream past on their way into 10 s windows, so memory stays
//! bounded whatever the row count: the Allan deviation is `stats::allan` (overlapping,
//! octave taus, chi-squared intervals, IEEE 952 fit) on its bounded `RateRecord`,
//! quantisation keeps the few smallest distinct steps, the step detector a ring of
//! `2 STEP_WINDOW_ROWS` rows.

use crate::io::bin::WindowBinner;
use crate::io::reader::RunReader;
use crate::io::runs::{Run, RunError};
use crate::stats::allan::{self, RateRecord, Term};
use serde::Serialize;
use std::collections::VecDeque;
use std::path::Path;

/// Rows in each half of the step detector's window.
pub const STEP_WINDOW_ROWS: usize = 30;
/// A step is reported above this many standard errors of the half-window mean difference
/// (Gaussian tail ~1e-15 per test: no false alarms expected in 1e9 rows).
pub const STEP_SIGMA: f64 = 8.0;
/// Steps listed (all are counted).
pub const STEPS_LISTED: usize = 20;
/// Distinct smallest steps kept per column for the quantisation check.
pub const SMALLEST_STEPS: usize = 6;
/// One point of the Allan deviation.
#[derive(Clone, Debug, Serialize)]
pub struct AllanPoint {
    pub tau_s: f64,
    /// Overlapping ADEV and half its 1-sigma chi-squared interval.
    pub adev_dph: f64,
    pub adev_plus_minus_dph: f64,
    pub pairs: u64,
}

/// The few smallest distinct nonzero steps of a column.
#[derive(Clone, Debug, Default)]
struct StepSizes {
    prev: Option<f64>,
    smallest: Vec<f64>,
}

impl StepSizes {
    fn push(&mut self, x: f64) {
        if let Some(p) = self.prev {
            let d = (x - p).abs();
            let tol = 1e-9 * x.abs().max(p.abs()).max(1e-300);
            if d > tol
                && !self
                    .smallest
                    .iter()
                    .any(|s| (s - d).abs() <= tol.max(1e-6 * s))
            {
                self.smallest.push(d);
                self.smallest.sort_by(f64::total_cmp);
                self.smallest.truncate(SMALLEST_STEPS);
            }
        }
        self.prev = Some(x);
    }
}

/// Quantisation of one column.
#[derive(Clone, Debug, Serialize)]
pub struct Quantisation {
    pub column: String,
    /// Smallest nonzero step between consecutive rows.
    pub smallest_step: f64,
    /// The next smallest distinct steps, as multiples of the smallest.
    pub next_steps_in_units: Vec<f64>,
    /// Every kept step an integer multiple of the smallest: a quantised (ADC) column.
    pub quantised: bool,
}

impl StepSizes {
    fn summary(&self, column: &str) -> Option<Quantisation> {
        let q = *self.smallest.first()?;
        let units: Vec<f64> = self.smallest[1..].iter().map(|s| s / q).collect();
        let quantised = units.iter().all(|u| (u - u.round()).abs() < 1e-3);
        Some(Quantisation {
            column: column.to_owned(),
            smallest_step: q,
            next_steps_in_units: units,
            quantised,
        })
    }
}

/// One detected step of the drift.
#[derive(Clone, Debug, Serialize)]
pub struct Step {
    pub run: String,
    /// Time of the jump (first row after it), s.
    pub t_s: f64,
    pub size_dph: f64,
    pub sigma: f64,
}

/// Two adjacent windows of `STEP_WINDOW_ROWS` rows with their own means and one common
/// slope (so a warm-up trend is not a step); a step is the jump between them far beyond
/// the white noise of the rows (estimated from first differences, streaming).
#[derive(Clone, Debug, Default)]
struct StepDetector {
    ring: VecDeque<(f64, f64)>,
    diff_sq: f64,
    diffs: u64,
    last: Option<f64>,
    excursion: Option<(f64, f64, f64)>,
    found: Vec<(f64, f64, f64)>,
}

impl StepDetector {
    fn push(&mut self, t: f64, x: f64) {
        let w = STEP_WINDOW_ROWS;
        if let Some(l) = self.last {
            self.diff_sq += (x - l) * (x - l);
            self.diffs += 1;
        }
        self.last = Some(x);
        if self.ring.len() == 2 * w {
            self.ring.pop_front();
        }
        self.ring.push_back((t, x));
        if self.ring.len() < 2 * w || self.diffs < 2 {
            return;
        }
        let sigma_row = (self.diff_sq / self.diffs as f64 / 2.0).sqrt();
        let (size, se) = self.jump(sigma_row);
        let z = size / se.max(1e-300);
        let t_jump = self.ring[w].0;
        if z.abs() > STEP_SIGMA {
            if self.excursion.is_none_or(|e| z.abs() > e.2.abs()) {
                self.excursion = Some((t_jump, size, z));
            }
        } else if let Some(e) = self.excursion.take() {
            self.found.push(e);
        }
    }

    /// The jump between the halves (common-slope fit, separate means) and its standard
    /// error for white noise of `sigma_row`.
    fn jump(&self, sigma_row: f64) -> (f64, f64) {
        let w = STEP_WINDOW_ROWS;
        let wf = w as f64;
        let centre = (wf - 1.0) / 2.0;
        let half = |k: usize| {
            let xs = self.ring.range(k * w..(k + 1) * w).map(|p| p.1);
            let mean = xs.clone().sum::<f64>() / wf;
            let sxy: f64 = xs
                .enumerate()
                .map(|(i, x)| (i as f64 - centre) * (x - mean))
                .sum();
            (mean, sxy)
        };
        let ((ml, sl), (mr, sr)) = (half(0), half(1));
        let sii = wf * (wf * wf - 1.0) / 12.0;
        let slope = (sl + sr) / (2.0 * sii);
        let size = (mr - ml) - slope * wf;
        let se = sigma_row * (2.0 / wf + wf * wf / (2.0 * sii)).sqrt();
        (size, se)
    }

    fn end_run(&mut self) -> Vec<(f64, f64, f64)> {
        if let Some(e) = self.excursion.take() {
            self.found.push(e);
        }
        self.ring.clear();
        self.last = None;
        std::mem::take(&mut self.found)
    }
}

/// Steps found in the campaign.
#[derive(Clone, Debug, Serialize)]
pub struct Steps {
    pub window_rows: usize,
    pub threshold_sigma: f64,
    pub count: usize,
    pub listed: Vec<Step>,
}

/// What the raw rows say.
#[derive(Clone, Debug, Serialize)]
pub struct RawRows {
    pub rows: u64,
    /// Median row spacing of the first run, s (tau0 of the Allan deviation).
    pub sample_period_s: f64,
    /// Allan deviation of rate_dph - earth_dph (the drift), runs pooled, never across a gap.
    pub allan: Vec<AllanPoint>,
    /// IEEE 952 angle random walk N: sigma(tau) = N / sqrt(tau) on the -1/2 slope, deg/sqrt(h).
    pub arw_dpsh: Option<f64>,
    pub arw_plus_minus_dpsh: Option<f64>,
    /// The taus whose points lie on the -1/2 slope (used for N).
    pub arw_fit_taus_s: Vec<f64>,
    /// IEEE 952 bias instability B = sigma_min / 0.664, deg/h, and where the minimum is.
    pub bias_instability_dph: Option<f64>,
    pub bias_instability_tau_s: Option<f64>,
    /// Whether the minimum is a flat floor (neighbours within 2 sigma) or the last point.
    pub bias_instability_note: String,
    pub quantisation: Vec<Quantisation>,
    pub steps: Steps,
    /// Runs left out of the Allan deviation (other sample period) and why.
    pub notes: Vec<String>,
}

/// Everything streamed per campaign.
struct Accumulators {
    tau0_s: Option<f64>,
    allan: RateRecord,
    temp_steps: StepSizes,
    rate_steps: StepSizes,
    detector: StepDetector,
    steps: Vec<Step>,
    step_count: usize,
    rows: u64,
    notes: Vec<String>,
}

/// Reads runs like `io::bin::read_runs_binned` (10 s windows, memory bounded by windows)
/// and analyses their raw rows on the way.
pub fn read_runs<P: AsRef<Path>>(paths: &[P]) -> Result<(Vec<Run>, RawRows), RunError> {
    let mut acc = Accumulators {
        tau0_s: None,
        allan: RateRecord::default(),
        temp_steps: StepSizes::default(),
        rate_steps: StepSizes::default(),
        detector: StepDetector::default(),
        steps: vec![],
        step_count: 0,
        rows: 0,
        notes: vec![],
    };
    let mut runs = Vec::new();
    for file in crate::io::runs::run_files(paths)? {
        runs.push(read_one(&file, &mut acc)?);
    }
    Ok((runs, acc.finish()))
}

/// Whether a run's rows are analysed: the first rows are buffered until its period is known.
enum Analysis {
    Buffering(Vec<(f64, f64)>),
    On,
    Off,
}

fn read_one(file: &Path, acc: &mut Accumulators) -> Result<Run, RunError> {
    let mut reader = RunReader::open(file)?;
    let header = reader.header().clone();
    let idx = |n: &str| header.column_index(n);
    let t_index = idx("t_s").unwrap_or(0);
    let (rate, earth, temp) = (idx("rate_dph"), idx("earth_dph"), idx("temp_c"));
    let mut binner = WindowBinner::new(header.columns.len(), t_index);
    let mut values = Vec::new();
    let mut state = Analysis::Buffering(Vec::with_capacity(crate::io::bin::LEAD_ROWS));
    while reader.next_row_into(&mut values)?.is_some() {
        binner.push(&values);
        acc.rows += 1;
        let t = values[t_index];
        let drift = rate.map_or(f64::NAN, |i| values[i]) - earth.map_or(0.0, |i| values[i]);
        if let Some(i) = temp {
            acc.temp_steps.push(values[i]);
        }
        if let Some(i) = rate {
            acc.rate_steps.push(values[i]);
        }
        state = match state {
            Analysis::On => {
                acc.take(t, drift);
                Analysis::On
            }
            Analysis::Off => Analysis::Off,
            Analysis::Buffering(mut lead) => {
                lead.push((t, drift));
                if lead.len() < crate::io::bin::LEAD_ROWS {
                    Analysis::Buffering(lead)
                } else {
                    acc.settle(file, &lead)
                }
            }
        };
    }
    if let Analysis::Buffering(lead) = state {
        acc.settle(file, &lead);
    }
    acc.end_run(file);
    Ok(Run {
        path: header.path,
        meta: header.meta,
        columns: header.columns,
        data: binner.finish(),
    })
}

impl Accumulators {
    fn take(&mut self, t: f64, drift: f64) {
        self.allan.push(drift);
        self.detector.push(t, drift);
    }

    /// Sets or checks the sample period from the buffered rows and feeds them; Off when
    /// this run's period differs from the first run's.
    fn settle(&mut self, file: &Path, lead: &[(f64, f64)]) -> Analysis {
        let mut dt: Vec<f64> = lead.windows(2).map(|w| w[1].0 - w[0].0).collect();
        dt.sort_by(f64::total_cmp);
        let p = dt.get(dt.len() / 2).copied().unwrap_or(f64::NAN);
        let t0 = *self.tau0_s.get_or_insert(p);
        if (p / t0 - 1.0).abs() >= 0.01 {
            self.notes.push(format!(
                "{}: row spacing {p} s differs from the first run's {t0} s; left out of the Allan deviation and step search",
                file.display()
            ));
            return Analysis::Off;
        }
        for &(t, d) in lead {
            self.take(t, d);
        }
        Analysis::On
    }

    /// A gap: no Allan block or step window spans two runs.
    fn end_run(&mut self, file: &Path) {
        self.allan.break_segment();
        let run = file.display().to_string();
        for (t_s, size_dph, sigma) in self.detector.end_run() {
            self.step_count += 1;
            if self.steps.len() < STEPS_LISTED {
                self.steps.push(Step {
                    run: run.clone(),
                    t_s,
                    size_dph,
                    sigma,
                });
            }
        }
    }

    fn finish(self) -> RawRows {
        let tau0 = self.tau0_s.unwrap_or(f64::NAN);
        let analysis = allan::analyse(
            &self.allan,
            tau0,
            allan::Kind::Adev,
            allan::TauSpacing::Octave,
        )
        .ok();
        let (allan, (arw, arw_pm, fit_taus), (bi, bi_tau, bi_note)) =
            from_analysis(analysis.as_ref());
        RawRows {
            rows: self.rows,
            sample_period_s: tau0,
            allan,
            arw_dpsh: arw,
            arw_plus_minus_dpsh: arw_pm,
            arw_fit_taus_s: fit_taus,
            bias_instability_dph: bi,
            bias_instability_tau_s: bi_tau,
            bias_instability_note: bi_note,
            quantisation: [("temp_c", &self.temp_steps), ("rate_dph", &self.rate_steps)]
                .iter()
                .filter_map(|(c, s)| s.summary(c))
                .collect(),
            steps: Steps {
                window_rows: STEP_WINDOW_ROWS,
                threshold_sigma: STEP_SIGMA,
                count: self.step_count,
                listed: self.steps,
            },
            notes: self.notes,
        }
    }
}

/// The Allan points, N (value, 1 sigma, the taus it is read from) and B (value, the
/// middle of its tau range, where it is read from) of `stats::allan`'s analysis.
#[allow(clippy::type_complexity)]
fn from_analysis(
    a: Option<&allan::Analysis>,
) -> (
    Vec<AllanPoint>,
    (Option<f64>, Option<f64>, Vec<f64>),
    (Option<f64>, Option<f64>, String),
) {
    let Some(a) = a else {
        return (
            vec![],
            (None, None, vec![]),
            (None, None, "too few rows for an Allan deviation".into()),
        );
    };
    let points = a
        .adev
        .points
        .iter()
        .map(|p| AllanPoint {
            tau_s: p.tau_s,
            adev_dph: p.dev,
            adev_plus_minus_dph: 0.5 * (p.dev_hi - p.dev_lo),
            pairs: p.terms,
        })
        .collect();
    let range = |t: &allan::TermEstimate| -> Vec<f64> {
        a.adev
            .points
            .iter()
            .map(|p| p.tau_s)
            .filter(|tau| {
                t.tau_from_s.is_some_and(|lo| *tau >= lo) && t.tau_to_s.is_some_and(|hi| *tau <= hi)
            })
            .collect()
    };
    let n = a.noise.detected(Term::N);
    let arw = (
        n.map(|t| t.value),
        n.map(|t| t.sigma),
        n.map(range).unwrap_or_default(),
    );
    let b = a.noise.detected(Term::B);
    let bi = match b {
        Some(t) => (
            Some(t.value),
            t.tau_from_s
                .zip(t.tau_to_s)
                .map(|(lo, hi)| (lo * hi).sqrt()),
            format!(
                "IEEE 952 fit: B {:.2e} +/- {:.1e} deg/h read from tau {:.4}..{:.4} s",
                t.value,
                t.sigma,
                t.tau_from_s.unwrap_or(f64::NAN),
                t.tau_to_s.unwrap_or(f64::NAN)
            ),
        ),
        None => (
            None,
            None,
            "IEEE 952 fit: no bias-instability floor detected".into(),
        ),
    };
    (points, arw, bi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn quantised_steps_and_a_jump_are_found() {
        let mut q = StepSizes::default();
        let mut d = StepDetector::default();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let normal = Normal::new(0.0, 1.0).unwrap();
        for i in 0..2000 {
            let t = i as f64;
            q.push(20.0 + 0.0625 * ((t / 37.0).sin() * 30.0).round());
            let jump = if i >= 1000 { 0.05 } else { 0.0 };
            d.push(t, 0.01 * normal.sample(&mut rng) + jump);
        }
        let s = q.summary("temp_c").unwrap();
        assert!(
            (s.smallest_step - 0.0625).abs() < 1e-9 && s.quantised,
            "{s:?}"
        );
        let found = d.end_run();
        assert_eq!(found.len(), 1, "{found:?}");
        // Twin: a steep warm-up trend (exponential, 10 noise sigma per window) is no step.
        let mut trend = StepDetector::default();
        for i in 0..2000 {
            let t = i as f64;
            trend.push(t, 0.01 * normal.sample(&mut rng) + 3.0 * (-t / 300.0).exp());
        }
        assert!(trend.end_run().is_empty());
        assert!((found[0].0 - 1000.0).abs() <= 3.0 && (found[0].1 - 0.05).abs() < 0.01);
    }
}
