//! The raw rows before averaging (issue 9 item 4): Allan deviation of the drift (ARW on
//! the -1/2 slope, bias instability at the flat minimum, IEEE Std 952 terms),
//! quantisation (smallest step of the thermometer and of the rate) and steps, all
//! computed while the rows stream past on their way into 10 s windows, so memory stays
//! bounded whatever the row count: the Allan deviation uses octave-spaced
//! non-overlapping block means (a cascade of pair averages: one pending value and one
//! previous block mean per octave), quantisation keeps the few smallest distinct steps,
//! the step detector a ring of `2 STEP_WINDOW_ROWS` rows.

use crate::io::bin::WindowBinner;
use crate::io::reader::RunReader;
use crate::io::runs::{Run, RunError};
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
/// IEEE Std 952: bias instability B = sigma_min / 0.664 (flicker floor of the Allan deviation).
pub const FLICKER_FLOOR_FACTOR: f64 = 0.664;
/// Fewest block pairs for an Allan point to be reported.
pub const MIN_ALLAN_PAIRS: u64 = 3;

/// One octave of the Allan cascade.
#[derive(Clone, Debug, Default)]
struct Octave {
    pending: Option<f64>,
    prev: Option<f64>,
    sum_sq: f64,
    pairs: u64,
}

/// Streaming non-overlapping Allan variance at tau0 * 2^k.
#[derive(Clone, Debug, Default)]
pub struct AllanCascade {
    octaves: Vec<Octave>,
}

impl AllanCascade {
    /// Adds one sample (a block mean at octave 0).
    pub fn push(&mut self, x: f64) {
        let mut mean = x;
        let mut k = 0;
        loop {
            if self.octaves.len() == k {
                self.octaves.push(Octave::default());
            }
            let o = &mut self.octaves[k];
            if let Some(p) = o.prev {
                o.sum_sq += (mean - p) * (mean - p);
                o.pairs += 1;
            }
            o.prev = Some(mean);
            match o.pending.take() {
                None => {
                    o.pending = Some(mean);
                    return;
                }
                Some(first) => {
                    mean = 0.5 * (first + mean);
                    k += 1;
                }
            }
        }
    }

    /// A gap (new run): blocks never span it; the sums are kept.
    pub fn break_record(&mut self) {
        for o in &mut self.octaves {
            o.pending = None;
            o.prev = None;
        }
    }

    /// (tau, Allan deviation, block pairs) for every octave with enough pairs.
    pub fn points(&self, tau0_s: f64) -> Vec<AllanPoint> {
        self.octaves
            .iter()
            .enumerate()
            .filter(|(_, o)| o.pairs >= MIN_ALLAN_PAIRS)
            .map(|(k, o)| {
                let adev = (o.sum_sq / (2.0 * o.pairs as f64)).sqrt();
                AllanPoint {
                    tau_s: tau0_s * f64::from(1u32 << k.min(31)),
                    adev_dph: adev,
                    // Non-overlapping estimate: relative 1 sigma 1 / sqrt(2 (K - 1)).
                    adev_plus_minus_dph: adev / (2.0 * (o.pairs.max(2) - 1) as f64).sqrt(),
                    pairs: o.pairs,
                }
            })
            .collect()
    }
}

/// One point of the Allan deviation.
#[derive(Clone, Debug, Serialize)]
pub struct AllanPoint {
    pub tau_s: f64,
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
    allan: AllanCascade,
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
        allan: AllanCascade::default(),
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
        self.allan.break_record();
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
        let allan = self.allan.points(tau0);
        let (arw, arw_pm, fit_taus) = arw_from_slope(&allan);
        let (bi, bi_tau, bi_note) = bias_instability(&allan);
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

/// N from the shortest taus whose local log-log slope is -1/2 +/- 1/4 (white rate noise):
/// N = mean of sigma(tau) sqrt(tau) over them, in deg/sqrt(h) (sigma in deg/h, tau in h).
fn arw_from_slope(p: &[AllanPoint]) -> (Option<f64>, Option<f64>, Vec<f64>) {
    let on_slope = |i: usize| {
        ((p[i + 1].adev_dph / p[i].adev_dph).ln() / (p[i + 1].tau_s / p[i].tau_s).ln() + 0.5).abs()
            <= 0.25
    };
    let Some(first) = (0..p.len().saturating_sub(1)).find(|&i| on_slope(i)) else {
        return (None, None, vec![]);
    };
    let mut last = first + 1;
    while last + 1 < p.len() && on_slope(last) {
        last += 1;
    }
    let n = |q: &AllanPoint, v: f64| v * (q.tau_s / 3600.0).sqrt();
    let used = &p[first..=last];
    let arw = used.iter().map(|q| n(q, q.adev_dph)).sum::<f64>() / used.len() as f64;
    // The shortest tau has the most pairs; its relative error stands for the estimate's.
    let pm = n(&used[0], used[0].adev_plus_minus_dph);
    (Some(arw), Some(pm), used.iter().map(|q| q.tau_s).collect())
}

/// B = sigma_min / 0.664 at the minimum of the Allan deviation; says whether the minimum
/// is a floor or just the longest tau measured (then B is an upper bound).
fn bias_instability(p: &[AllanPoint]) -> (Option<f64>, Option<f64>, String) {
    let Some((i, m)) = p
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.adev_dph.total_cmp(&b.1.adev_dph))
    else {
        return (None, None, "no Allan points".into());
    };
    let note = if i + 1 == p.len() {
        "minimum at the longest tau measured: no floor reached, B is an upper bound".to_owned()
    } else {
        let next = &p[i + 1];
        if next.adev_dph - m.adev_dph <= 2.0 * (next.adev_plus_minus_dph + m.adev_plus_minus_dph) {
            "flat minimum (next octave within 2 sigma)".to_owned()
        } else {
            "minimum between a falling and a rising slope (no wide floor)".to_owned()
        }
    };
    (Some(m.adev_dph / FLICKER_FLOOR_FACTOR), Some(m.tau_s), note)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// White rate noise: sigma(tau) = sigma0 / sqrt(tau / tau0), ARW recovered; a twin
    /// with a random walk of the rate (RRW) rises as +1/2 and has no -1/2 region.
    #[test]
    fn white_noise_gives_its_arw_and_a_random_walk_does_not() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let (tau0, sigma0) = (1.0, 0.06); // deg/h at 1 s: N = 0.06 / 60 = 0.001 deg/sqrt(h)
        let mut white = AllanCascade::default();
        let mut walk = AllanCascade::default();
        let mut level = 0.0;
        for _ in 0..200_000 {
            white.push(sigma0 * normal.sample(&mut rng));
            level += 0.01 * normal.sample(&mut rng);
            walk.push(level);
        }
        let p = white.points(tau0);
        let (arw, pm, taus) = arw_from_slope(&p);
        let arw = arw.unwrap();
        assert!((arw / 0.001 - 1.0).abs() < 0.05, "arw {arw}");
        assert!(pm.unwrap() < 0.05 * arw && taus.first() == Some(&1.0));
        let w = walk.points(tau0);
        assert!(
            w[5].adev_dph > w[1].adev_dph,
            "a random walk rises with tau"
        );
        assert!(arw_from_slope(&w).0.is_none());
    }

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
