//! Per-window drift compensation: the 10 s pipeline the device runs after power-on.
//!
//! Samples go in as they arrive (gyro at its raw rate, temperature at ~1 Hz, optional
//! aux channels); each time a window closes, the compensator produces one `WindowResult`:
//! mean rate, mean temperature, the model's inputs (via `features::FeatureExtractor`, the
//! same code the trainer uses on 10 s means), the RBF drift (f32 or fixed point) and the
//! compensated rate, with a `WindowStatus` saying whether the window can be trusted.
//! Inputs outside the model's trained range are flagged (and the drift is evaluated at
//! the range edge, never extrapolated).

use crate::compensation::cold_start::ColdStartMonitor;
use crate::compensation::features::{
    FeatureError, FeatureExtractor, TempRateEstimator, WindowAverager, WindowMean,
    DEFAULT_RATE_SPAN_S, EXTRACTOR_RATE_POINTS,
};
use crate::hal::{GyroSample, TempSample};
use crate::model::error::ModelError;
use crate::model::fixed::{FixedError, FixedModel};
use crate::model::format::{FeatureSpec, RbfModel, MAX_AUX, MAX_INPUTS};
use crate::model::rbf::{predict_f32, RbfError};

/// Which evaluator computes the drift.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Evaluator {
    /// f32 with `libm::expf` (MCUs with an FPU, the host).
    F32,
    /// Integer-only (`fixed::FixedModel`) for FPU-less parts.
    Fixed,
}

/// Compensator settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CompensatorConfig {
    /// Window length, s (10 s as in the paper).
    pub window_s: f32,
    /// Nominal gyro sample rate, Hz (1..10_000).
    pub gyro_rate_hz: f32,
    /// Nominal temperature (and aux) sample rate, Hz.
    pub temp_rate_hz: f32,
    /// Fraction of the expected gyro samples a valid window needs.
    pub min_fill: f32,
    /// Plausible sensor temperature range, degC; readings outside are a sensor fault.
    pub temp_plausible_min_c: f32,
    pub temp_plausible_max_c: f32,
    /// Tolerance beyond the trained range, as a fraction of the range width.
    pub range_margin_frac: f32,
    /// Number of aux channels pushed with `push_aux` (0..=MAX_AUX).
    pub n_aux: u8,
    pub evaluator: Evaluator,
}

/// Why the compensator could not be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CompensatorError {
    /// Invalid model.
    Model(ModelError),
    /// The model cannot be converted to fixed point.
    Fixed(FixedError),
    /// The model's features cannot be computed.
    Feature(FeatureError),
    /// A configuration value out of range (window, rates, fill, n_aux).
    BadConfig,
    /// The model reads an aux channel the configuration does not provide.
    AuxNotConfigured { channel: u8 },
}

impl core::fmt::Display for CompensatorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            CompensatorError::Model(e) => write!(f, "compensator: {e}"),
            CompensatorError::Fixed(e) => write!(f, "compensator: {e}"),
            CompensatorError::Feature(e) => write!(f, "compensator: {e}"),
            CompensatorError::BadConfig => write!(
                f,
                "compensator: bad configuration (window > 0, rates 0..=10 kHz, 0 < min_fill <= 1, n_aux <= {MAX_AUX})"
            ),
            CompensatorError::AuxNotConfigured { channel } => write!(
                f,
                "compensator: model needs aux channel {channel}, not configured"
            ),
        }
    }
}

impl core::error::Error for CompensatorError {}

/// Whether a window's result can be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WindowStatus {
    /// Enough samples, temperature present and in range, model inputs in the trained range.
    Valid,
    /// A sensor fault was reported during the window, or a reading was implausible.
    SensorFault,
    /// Fewer gyro samples than `min_fill` of the expected count.
    TooFewSamples,
    /// No temperature reading in the window.
    NoTemperature,
    /// A rate/accel feature does not have enough history yet (first windows after power-on).
    FeaturesWarmingUp,
    /// Model input `input` lies outside its trained range (drift taken at the range edge).
    InputOutOfRange { input: u8 },
    /// This power-on warmed less than the model's training cold starts did (a restart of
    /// a warm gyro), and the window lies within the model's cold-start envelope, where the
    /// model's warm-up drift does not apply (`compensation::cold_start`).
    NotColdStart,
}

impl WindowStatus {
    pub fn is_valid(self) -> bool {
        self == WindowStatus::Valid
    }
}

/// One 10 s result.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WindowResult {
    /// Window start and end, s since power-on.
    pub t_start_s: f64,
    pub t_end_s: f64,
    /// Mean gyro output over the window, deg/h.
    pub mean_rate_dph: f32,
    /// Mean gyro temperature, degC (NaN if none).
    pub temp_c: f32,
    /// dT/dt, degC/s (least-squares over `DEFAULT_RATE_SPAN_S` of window means; 0 until known).
    pub temp_rate_cps: f32,
    /// The model's inputs for this window (raw units), `n_inputs` used.
    pub inputs: [f32; MAX_INPUTS],
    pub n_inputs: u8,
    /// Predicted drift, deg/h (0 without a model).
    pub drift_dph: f32,
    /// mean_rate_dph - drift_dph.
    pub compensated_dph: f32,
    /// Gyro samples averaged / expected; gaps seen.
    pub n_samples: u32,
    pub n_expected: u32,
    pub n_gaps: u32,
    /// True if a model was applied.
    pub model_applied: bool,
    pub status: WindowStatus,
}

/// The 10 s compensation pipeline.
///
/// About 8 KB (model, fixed-point copy, feature history), so it is built and re-set in
/// place: `unconfigured` is a `const fn` (a `static` or a slot in a bigger struct), and
/// `configure` / `set_model_from` write the fields without building a whole temporary.
#[derive(Clone, Debug)]
pub struct Compensator {
    cfg: CompensatorConfig,
    /// False until `configure` succeeds: samples are then ignored.
    configured: bool,
    /// The model in use, valid if `has_model` (stored in place, not as an `Option`, so it
    /// can be overwritten with `RbfModel::copy_from`).
    model: RbfModel,
    has_model: bool,
    /// The fixed-point copy of `model`, used if `use_fixed`.
    fixed: FixedModel,
    use_fixed: bool,
    features: FeatureExtractor,
    rate_report: TempRateEstimator<EXTRACTOR_RATE_POINTS>,
    gyro: WindowAverager,
    temp: WindowAverager,
    temp_pending: Option<WindowMean>,
    aux: [WindowAverager; MAX_AUX],
    aux_pending: [Option<WindowMean>; MAX_AUX],
    /// Windows (first, last index) with a reported fault.
    fault_windows: Option<(i64, i64)>,
    /// Whether this power-on warms as a cold start (kept across model changes: it is the
    /// power-on's, not the model's).
    cold_start: ColdStartMonitor,
}

const DEFAULT_SPECS: [FeatureSpec; 2] = crate::model::format::PAPER_INPUTS;

/// The default configuration as a constant.
const DEFAULT_CONFIG: CompensatorConfig = CompensatorConfig {
    window_s: crate::consts::WINDOW_S,
    gyro_rate_hz: 100.0,
    temp_rate_hz: 1.0,
    min_fill: 0.9,
    temp_plausible_min_c: -60.0,
    temp_plausible_max_c: 125.0,
    range_margin_frac: 0.05,
    n_aux: 0,
    evaluator: Evaluator::F32,
};

/// What `unconfigured` holds: all zero bytes, so that a `static` holding an unconfigured
/// compensator goes to `.bss` and costs no flash (it is never used: `configure` checks
/// and replaces it).
const ZERO_CONFIG: CompensatorConfig = CompensatorConfig {
    window_s: 0.0,
    gyro_rate_hz: 0.0,
    temp_rate_hz: 0.0,
    min_fill: 0.0,
    temp_plausible_min_c: 0.0,
    temp_plausible_max_c: 0.0,
    range_margin_frac: 0.0,
    n_aux: 0,
    evaluator: Evaluator::F32,
};

impl Default for CompensatorConfig {
    fn default() -> Self {
        DEFAULT_CONFIG
    }
}

impl Compensator {
    /// Pipeline with an optional model (None: windows are reported uncompensated).
    pub fn new(cfg: CompensatorConfig, model: Option<RbfModel>) -> Result<Self, CompensatorError> {
        let mut c = Compensator::unconfigured();
        c.configure(cfg, model.as_ref())?;
        Ok(c)
    }

    /// Storage for a compensator that ignores every sample until `configure` succeeds
    /// (its `config()` is all zeros until then).
    pub const fn unconfigured() -> Self {
        Compensator {
            cfg: ZERO_CONFIG,
            configured: false,
            model: RbfModel::empty(),
            has_model: false,
            fixed: FixedModel::empty(),
            use_fixed: false,
            features: FeatureExtractor::empty(),
            rate_report: TempRateEstimator::placeholder(),
            gyro: WindowAverager::placeholder(),
            temp: WindowAverager::placeholder(),
            temp_pending: None,
            aux: [
                WindowAverager::placeholder(),
                WindowAverager::placeholder(),
                WindowAverager::placeholder(),
                WindowAverager::placeholder(),
            ],
            aux_pending: [None; MAX_AUX],
            fault_windows: None,
            cold_start: ColdStartMonitor::new(),
        }
    }

    /// Become `new(cfg, model)` in place. On error the compensator is unconfigured
    /// (it ignores samples) until a `configure` succeeds.
    pub fn configure(
        &mut self,
        cfg: CompensatorConfig,
        model: Option<&RbfModel>,
    ) -> Result<(), CompensatorError> {
        self.configured = false;
        let ok_rate = |r: f32| r.is_finite() && r > 0.0 && r <= 10_000.0;
        if !(cfg.window_s.is_finite()
            && cfg.window_s > 0.0
            && ok_rate(cfg.gyro_rate_hz)
            && ok_rate(cfg.temp_rate_hz)
            && cfg.min_fill > 0.0
            && cfg.min_fill <= 1.0
            && cfg.range_margin_frac >= 0.0
            && cfg.temp_plausible_min_c < cfg.temp_plausible_max_c
            && cfg.n_aux as usize <= MAX_AUX)
        {
            return Err(CompensatorError::BadConfig);
        }
        let bad = |_| CompensatorError::BadConfig;
        self.gyro = WindowAverager::new(cfg.window_s, cfg.gyro_rate_hz).map_err(bad)?;
        self.temp = WindowAverager::new(cfg.window_s, cfg.temp_rate_hz).map_err(bad)?;
        for aux in self.aux.iter_mut() {
            aux.clone_from(&self.temp);
        }
        // Restarted in place (not `TempRateEstimator::new` moved in: ~540 B of stack).
        self.rate_report
            .restart(DEFAULT_RATE_SPAN_S, false)
            .map_err(bad)?;
        self.temp_pending = None;
        self.aux_pending = [None; MAX_AUX];
        self.fault_windows = None;
        self.cold_start = ColdStartMonitor::new();
        self.cfg = cfg;
        // No model yet: a failing `set_model_from` below leaves "no model", as `new` did.
        self.has_model = false;
        self.use_fixed = false;
        self.features
            .reset_to(&DEFAULT_SPECS)
            .map_err(CompensatorError::Feature)?;
        self.set_model_from(model)?;
        self.configured = true;
        Ok(())
    }

    /// Replace the model (e.g. after an upload). Feature history restarts.
    pub fn set_model(&mut self, model: Option<RbfModel>) -> Result<(), CompensatorError> {
        self.set_model_from(model.as_ref())
    }

    /// `set_model` from a reference, in place. On error the old model (and its feature
    /// history) stays: everything is checked before the first write.
    pub fn set_model_from(&mut self, model: Option<&RbfModel>) -> Result<(), CompensatorError> {
        let Some(m) = model else {
            self.features
                .reset_to(&DEFAULT_SPECS)
                .map_err(CompensatorError::Feature)?;
            self.has_model = false;
            self.use_fixed = false;
            return Ok(());
        };
        m.validate().map_err(CompensatorError::Model)?;
        for spec in m.inputs.iter() {
            if let Some(ch) = spec.kind.aux_channel() {
                if ch >= self.cfg.n_aux {
                    return Err(CompensatorError::AuxNotConfigured { channel: ch });
                }
            }
        }
        // Check the specs without touching the history...
        FeatureExtractor::check_specs(&m.inputs).map_err(CompensatorError::Feature)?;
        let use_fixed = self.cfg.evaluator == Evaluator::Fixed;
        if use_fixed {
            if let Err(e) = self.fixed.fill_from(m) {
                // Conversion is deterministic: refill from the old model, which converted.
                if self.use_fixed && self.has_model {
                    let _ = self.fixed.fill_from(&self.model);
                }
                return Err(CompensatorError::Fixed(e));
            }
        }
        // ...so this cannot fail any more.
        self.features
            .reset_to(&m.inputs)
            .map_err(CompensatorError::Feature)?;
        self.model.copy_from(m);
        self.has_model = true;
        self.use_fixed = use_fixed;
        Ok(())
    }

    /// The model in use.
    pub fn model(&self) -> Option<&RbfModel> {
        self.has_model.then_some(&self.model)
    }

    pub fn config(&self) -> &CompensatorConfig {
        &self.cfg
    }

    /// Whether this power-on has warmed less than the model's training cold starts did
    /// (latched until the next `configure`; always false without an envelope).
    pub fn warm_restart(&self) -> bool {
        self.cold_start.warm_restart()
    }

    /// Add a gyro sample; returns the result of the window it closed, if any.
    pub fn push_gyro(&mut self, s: GyroSample) -> Option<WindowResult> {
        if !self.configured || !s.rate_dph.is_finite() || !s.t_s.is_finite() {
            return None;
        }
        let closed = self.gyro.push(s.t_s, s.rate_dph)?;
        Some(self.finish(closed))
    }

    /// Add a temperature reading. Implausible values mark the window as faulty.
    pub fn push_temp(&mut self, s: TempSample) {
        if !self.configured {
            return;
        }
        if !s.temp_c.is_finite()
            || s.temp_c < self.cfg.temp_plausible_min_c
            || s.temp_c > self.cfg.temp_plausible_max_c
        {
            self.report_fault(s.t_s);
            return;
        }
        if let Some(m) = self.temp.push(s.t_s, s.temp_c) {
            self.temp_pending = Some(m);
        }
    }

    /// Add a reading of aux channel `channel` (< `n_aux`; others are ignored).
    pub fn push_aux(&mut self, channel: u8, t_s: f64, value: f32) {
        let ch = channel as usize;
        if !self.configured || channel >= self.cfg.n_aux {
            return;
        }
        if let Some(m) = self.aux[ch].push(t_s, value) {
            self.aux_pending[ch] = Some(m);
        }
    }

    /// A sensor reported a fault at `t_s` (read error, timeout): that window is invalid.
    pub fn report_fault(&mut self, t_s: f64) {
        if self.configured && t_s.is_finite() {
            let k = self.gyro.window_index(t_s);
            // Faults arrive in real time, so one range (conservatively merged) suffices.
            self.fault_windows = Some(match self.fault_windows {
                Some((a, b)) => (a.min(k), b.max(k)),
                None => (k, k),
            });
        }
    }

    /// Close the current window by time (no gyro sample needed), e.g. from a timer, so a
    /// silent gyro still yields an (invalid) result.
    pub fn poll(&mut self, t_now_s: f64) -> Option<WindowResult> {
        if !self.configured {
            return None;
        }
        let closed = self.gyro.poll(t_now_s)?;
        Some(self.finish(closed))
    }

    fn take_mean(
        avg: &mut WindowAverager,
        pending: &mut Option<WindowMean>,
        t_end_s: f64,
    ) -> Option<f64> {
        let same = |m: &WindowMean| libm::fabs(m.t_end_s - t_end_s) < 1e-6 && m.n_samples > 0;
        if let Some(m) = pending.take() {
            if same(&m) {
                return Some(m.mean);
            }
        }
        match avg.poll(t_end_s) {
            Some(m) if same(&m) => Some(m.mean),
            _ => None,
        }
    }

    fn finish(&mut self, g: WindowMean) -> WindowResult {
        let t_end = g.t_end_s;
        let window_k = self
            .gyro
            .window_index(g.t_start_s + 0.5 * self.gyro.window_s());
        let temp = Self::take_mean(&mut self.temp, &mut self.temp_pending, t_end);
        let mut aux = [0.0f32; MAX_AUX];
        let mut aux_ok = true;
        let n_aux = self.cfg.n_aux as usize;
        for ((avg, pending), slot) in self
            .aux
            .iter_mut()
            .zip(self.aux_pending.iter_mut())
            .zip(aux.iter_mut())
            .take(n_aux)
        {
            match Self::take_mean(avg, pending, t_end) {
                Some(v) => *slot = v as f32,
                None => aux_ok = false,
            }
        }
        let faulted = self
            .fault_windows
            .is_some_and(|(a, b)| (a..=b).contains(&window_k));
        if self.fault_windows.is_some_and(|(_, b)| b <= window_k) {
            self.fault_windows = None;
        }
        let mean_rate = g.mean as f32;
        let mut r = WindowResult {
            t_start_s: g.t_start_s,
            t_end_s: t_end,
            mean_rate_dph: mean_rate,
            temp_c: temp.map_or(f32::NAN, |t| t as f32),
            temp_rate_cps: 0.0,
            inputs: [0.0; MAX_INPUTS],
            n_inputs: 0,
            drift_dph: 0.0,
            compensated_dph: mean_rate,
            n_samples: g.n_samples,
            n_expected: g.n_expected,
            n_gaps: g.n_gaps,
            model_applied: false,
            status: WindowStatus::Valid,
        };
        let enough =
            g.n_samples > 0 && g.n_samples as f32 >= self.cfg.min_fill * g.n_expected as f32;
        let mut status = if faulted || (self.cfg.n_aux > 0 && !aux_ok) {
            WindowStatus::SensorFault
        } else if !enough {
            WindowStatus::TooFewSamples
        } else if temp.is_none() {
            WindowStatus::NoTemperature
        } else {
            WindowStatus::Valid
        };
        if let Some(t) = temp {
            if let Some(e) = self.rate_report.push(t_end, t as f32 as f64) {
                r.temp_rate_cps = e.rate_per_s as f32;
            }
            if let (true, Some(envelope)) = (self.has_model, &self.model.cold_start) {
                let flag = self.cold_start.push(envelope, t_end as f32, t as f32);
                if flag && status.is_valid() {
                    status = WindowStatus::NotColdStart;
                }
            }
            // Feature history only advances on windows with a real temperature.
            match self
                .features
                .push(t_end, t as f32, &aux[..self.cfg.n_aux as usize])
            {
                Ok(fv) => {
                    r.inputs = fv.values;
                    r.n_inputs = fv.len;
                    if !fv.ready && status.is_valid() {
                        status = WindowStatus::FeaturesWarmingUp;
                    }
                    if fv.ready {
                        let (drift, range) = self.evaluate(&fv.values[..fv.len as usize]);
                        if let Some(d) = drift {
                            r.drift_dph = d;
                            r.compensated_dph = mean_rate - d;
                            r.model_applied = true;
                        }
                        if let (Some(i), true) = (range, status.is_valid()) {
                            status = WindowStatus::InputOutOfRange { input: i };
                        }
                    }
                }
                Err(_) => status = WindowStatus::SensorFault,
            }
        }
        if !mean_rate.is_finite() && status.is_valid() {
            status = WindowStatus::TooFewSamples;
        }
        r.status = status;
        r
    }

    /// Drift at the inputs clamped to the (margin-widened) trained range, and the first
    /// input that was outside it.
    fn evaluate(&self, x: &[f32]) -> (Option<f32>, Option<u8>) {
        if !self.has_model {
            return (None, None);
        }
        let m = &self.model;
        let mut clamped = [0.0f32; MAX_INPUTS];
        let mut outside = None;
        for (j, &v) in x.iter().enumerate() {
            let (lo, hi) = (m.input_min[j], m.input_max[j]);
            let margin = self.cfg.range_margin_frac * (hi - lo);
            let (lo, hi) = (lo - margin, hi + margin);
            if v < lo || v > hi {
                outside.get_or_insert(j as u8);
            }
            // Not f32::clamp: it panics on a NaN bound (an infinite range times 0 margin).
            clamped[j] = if v < lo {
                lo
            } else if v > hi {
                hi
            } else {
                v
            };
        }
        let xs = &clamped[..x.len()];
        let drift: Result<f32, RbfError> = if self.use_fixed {
            self.fixed.predict(xs)
        } else {
            predict_f32(m, xs)
        };
        (drift.ok(), outside)
    }
}
