//! A list of `FeatureSpec`s -> one input vector a row: the stateful extractor the device
//! feeds its window means and the trainer's helper that runs it over a whole series.

use super::error::{positive_time_constant, FeatureError};
use super::lag::{power_on_decay, power_on_decay_stretch, FirstOrderLag};
use super::rate::TempRateEstimator;
use crate::model::format::{FeatureKind, FeatureSpec, MAX_AUX, MAX_INPUTS};
use heapless::Vec;

/// Default least-squares span of `TempRateCps` / `AuxRate` when `tau_s` is 0, s.
pub const DEFAULT_RATE_SPAN_S: f64 = 60.0;
/// Default least-squares span of `TempAccelCps2` / `TempAccelFlatStartCps2` when `tau_s`
/// is 0, s.
pub const DEFAULT_ACCEL_SPAN_S: f64 = 180.0;
/// Points kept by the estimators inside `FeatureExtractor` (10 s rows: spans up to 310 s).
pub const EXTRACTOR_RATE_POINTS: usize = 32;

/// Model input vector for one row.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FeatureVector {
    /// Values in the order of the specs; entries past `len` are 0.
    pub values: [f32; MAX_INPUTS],
    pub len: u8,
    /// False while a rate/accel estimator has too few points (first row for rates,
    /// first two rows for accelerations); such rows hold 0 there and should not be used.
    pub ready: bool,
}

impl FeatureVector {
    /// The used values.
    pub fn as_slice(&self) -> &[f32] {
        &self.values[..self.len as usize]
    }
}

// No allocator: the estimator lives inline; unused variants cost at most MAX_INPUTS x 544 B.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum FeatureState {
    Plain,
    Rate(TempRateEstimator<EXTRACTOR_RATE_POINTS>),
    Lag(FirstOrderLag),
    /// The first row's temperature (None before it), for `TempRiseC`.
    First(Option<f64>),
}

/// Stateful computation of a list of `FeatureSpec`s, one row (window) at a time.
#[derive(Clone, Debug)]
pub struct FeatureExtractor {
    specs: Vec<FeatureSpec, MAX_INPUTS>,
    states: Vec<FeatureState, MAX_INPUTS>,
    last_t_s: Option<f64>,
    row: u32,
}

/// Span used for a rate or accel spec (its `tau_s`, or the default when 0).
pub fn span_for(spec: &FeatureSpec) -> f64 {
    // the diffusion-clock rate's `tau_s` is its clock's time constant, not a span
    if spec.kind == FeatureKind::TempRateDiffusionCps {
        return DEFAULT_RATE_SPAN_S;
    }
    let default = match spec.kind {
        FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2 => DEFAULT_ACCEL_SPAN_S,
        _ => DEFAULT_RATE_SPAN_S,
    };
    if spec.tau_s > 0.0 {
        spec.tau_s as f64
    } else {
        default
    }
}

/// Why `spec` is invalid, if it is (checked before any state is written).
fn check_spec(spec: &FeatureSpec) -> Result<(), FeatureError> {
    match spec.kind {
        FeatureKind::TempRateCps
        | FeatureKind::TempAccelCps2
        | FeatureKind::TempAccelFlatStartCps2
        | FeatureKind::AuxRate(_) => positive_time_constant(span_for(spec))?,
        kind if kind.needs_time_constant() => positive_time_constant(spec.tau_s as f64)?,
        _ => {}
    }
    if let Some(ch) = spec.kind.aux_channel() {
        if ch as usize >= MAX_AUX {
            return Err(FeatureError::MissingAux { channel: ch });
        }
    }
    Ok(())
}

/// A rate state with its estimator in the all-zero placeholder (`reset_state` restarts it).
const RATE_PLACEHOLDER: FeatureState = FeatureState::Rate(TempRateEstimator::placeholder());

/// Set `state` to the fresh state of `spec` (passed by `check_spec`) in place. The rate
/// estimator (~540 B) is restarted where it lives: building it by value and moving it in
/// put three copies on the firmware's boot stack (issue: boot peak 7,764 -> 9,180 B).
fn reset_state(state: &mut FeatureState, spec: &FeatureSpec) -> Result<(), FeatureError> {
    match spec.kind {
        // Only the second derivative has a flat-start kind (the soaked unit at power-on,
        // see `TempRateEstimator::new_flat_start`); the slope keeps its growing window: a
        // flat-start slope is diluted in the first minute, which puts a cold-start row
        // (T near ambient, small slope, large drift) where a later row of a colder run
        // (same T, settled) sits, and a model over several ambients cannot tell them
        // apart (measured: global model, seek 1 at -40 degC 0.0203 -> 0.0276 deg rms).
        FeatureKind::TempRateCps
        | FeatureKind::TempRateDiffusionCps
        | FeatureKind::TempAccelCps2
        | FeatureKind::TempAccelFlatStartCps2
        | FeatureKind::AuxRate(_) => {
            if !matches!(state, FeatureState::Rate(_)) {
                *state = RATE_PLACEHOLDER;
            }
            if let FeatureState::Rate(e) = state {
                let flat_start = spec.kind == FeatureKind::TempAccelFlatStartCps2;
                e.restart(span_for(spec), flat_start)?;
            }
        }
        FeatureKind::TempLagC => *state = FeatureState::Lag(FirstOrderLag::new(spec.tau_s as f64)?),
        FeatureKind::TempRiseC => *state = FeatureState::First(None),
        _ => *state = FeatureState::Plain,
    }
    Ok(())
}

impl FeatureExtractor {
    /// An extractor without specs (every row gives an empty, ready vector): the initial
    /// value of storage that `reset_to` sets up in place.
    pub const fn empty() -> Self {
        FeatureExtractor {
            specs: Vec::new(),
            states: Vec::new(),
            last_t_s: None,
            row: 0,
        }
    }

    /// Extractor for `specs` (at most `MAX_INPUTS`).
    pub fn new(specs: &[FeatureSpec]) -> Result<Self, FeatureError> {
        let mut fe = FeatureExtractor::empty();
        fe.reset_to(specs)?;
        Ok(fe)
    }

    /// The error `new(specs)` would return, if any, without building an extractor.
    pub fn check_specs(specs: &[FeatureSpec]) -> Result<(), FeatureError> {
        for (i, spec) in specs.iter().enumerate() {
            check_spec(spec)?;
            if i >= MAX_INPUTS {
                return Err(FeatureError::TooManyFeatures);
            }
        }
        Ok(())
    }

    /// Become `new(specs)` in place, history cleared. On error `self` is unchanged:
    /// every spec is checked before anything is written.
    pub fn reset_to(&mut self, specs: &[FeatureSpec]) -> Result<(), FeatureError> {
        Self::check_specs(specs)?;
        self.specs.clear();
        self.states.clear();
        self.last_t_s = None;
        self.row = 0;
        for spec in specs {
            // Checked above: neither the pushes nor the state can fail.
            self.specs
                .push(*spec)
                .map_err(|_| FeatureError::TooManyFeatures)?;
            self.states
                .push(FeatureState::Plain)
                .map_err(|_| FeatureError::TooManyFeatures)?;
            if let Some(state) = self.states.last_mut() {
                reset_state(state, spec)?;
            }
        }
        Ok(())
    }

    /// The specs, in order.
    pub fn specs(&self) -> &[FeatureSpec] {
        &self.specs
    }

    /// Process one row: time since power-on (s), temperature (degC) and aux channel values.
    /// On error the extractor state is unchanged.
    pub fn push(
        &mut self,
        t_s: f64,
        temp_c: f32,
        aux: &[f32],
    ) -> Result<FeatureVector, FeatureError> {
        let row = self.row;
        if !t_s.is_finite() || !temp_c.is_finite() {
            return Err(FeatureError::NonFinite { row });
        }
        if self.last_t_s.is_some_and(|t| t_s <= t) {
            return Err(FeatureError::TimeNotIncreasing { row });
        }
        for spec in self.specs.iter() {
            if let Some(ch) = spec.kind.aux_channel() {
                match aux.get(ch as usize) {
                    None => return Err(FeatureError::MissingAux { channel: ch }),
                    Some(v) if !v.is_finite() => return Err(FeatureError::NonFinite { row }),
                    Some(_) => {}
                }
            }
        }
        let mut out = FeatureVector {
            values: [0.0; MAX_INPUTS],
            len: self.specs.len() as u8,
            ready: true,
        };
        let temp = temp_c as f64;
        for (i, (spec, state)) in self.specs.iter().zip(self.states.iter_mut()).enumerate() {
            let aux_v = spec.kind.aux_channel().map(|ch| aux[ch as usize] as f64);
            let value = match (spec.kind, state) {
                (FeatureKind::TempC, _) => Some(temp),
                (FeatureKind::TempRateCps, FeatureState::Rate(e)) => {
                    e.push(t_s, temp).map(|r| r.rate_per_s)
                }
                (FeatureKind::TempRateDiffusionCps, FeatureState::Rate(e)) => e
                    .push(t_s, temp)
                    .and_then(|_| e.diffusion_clock_rate(spec.tau_s as f64)),
                (
                    FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2,
                    FeatureState::Rate(e),
                ) => e.push(t_s, temp).and_then(|r| r.accel_per_s2),
                (FeatureKind::TempLagC, FeatureState::Lag(l)) => Some(l.push(t_s, temp)),
                (FeatureKind::TempRiseC, FeatureState::First(first)) => {
                    Some(temp - *first.get_or_insert(temp))
                }
                (FeatureKind::PowerOnDecay, _) => Some(power_on_decay(t_s, spec.tau_s as f64)),
                (FeatureKind::PowerOnDecayStretch, _) => {
                    Some(power_on_decay_stretch(t_s, spec.tau_s as f64))
                }
                (FeatureKind::AuxValue(_), _) => aux_v,
                (FeatureKind::AuxRate(_), FeatureState::Rate(e)) => {
                    e.push(t_s, aux_v.unwrap_or(0.0)).map(|r| r.rate_per_s)
                }
                // Sine/cosine of degrees reduced exactly in degrees (`numeric::sin_cos_deg`,
                // f64 to ~2 ulps): no libm radian reduction linked into the firmware.
                (FeatureKind::AuxCos(_), _) => aux_v.map(|d| crate::numeric::sin_cos_deg(d).1),
                (FeatureKind::AuxSin(_), _) => aux_v.map(|d| crate::numeric::sin_cos_deg(d).0),
                _ => None,
            };
            match value {
                Some(v) => out.values[i] = v as f32,
                None => out.ready = false,
            }
        }
        self.last_t_s = Some(t_s);
        self.row += 1;
        Ok(out)
    }
}

/// Host-side helper for the trainer: the input vectors of every row of a series of 10 s
/// means, computed by the same `FeatureExtractor` the device runs.
///
/// `aux[ch][row]` is aux channel `ch`; `out` must have one entry per row. Causal: row k uses
/// rows 0..=k only; rows whose `ready` is false (estimator warm-up) should be left out of
/// training, exactly as the device marks those windows invalid. Rows must be the 10 s means
/// the device computes: the estimators keep at most `EXTRACTOR_RATE_POINTS` rows, so denser
/// (raw-rate) rows would shorten the least-squares span.
pub fn features_for_series(
    specs: &[FeatureSpec],
    t_s: &[f64],
    temp_c: &[f32],
    aux: &[&[f32]],
    out: &mut [FeatureVector],
) -> Result<(), FeatureError> {
    let n = t_s.len();
    let mismatch = |found: usize| FeatureError::LengthMismatch {
        expected: n as u32,
        found: found as u32,
    };
    if temp_c.len() != n {
        return Err(mismatch(temp_c.len()));
    }
    if out.len() != n {
        return Err(mismatch(out.len()));
    }
    if let Some(a) = aux.iter().find(|a| a.len() != n) {
        return Err(mismatch(a.len()));
    }
    if aux.len() > MAX_AUX {
        return Err(FeatureError::MissingAux {
            channel: MAX_AUX as u8,
        });
    }
    let mut fx = FeatureExtractor::new(specs)?;
    let mut row_aux = [0.0f32; MAX_AUX];
    for k in 0..n {
        for (ch, col) in aux.iter().enumerate() {
            row_aux[ch] = col[k];
        }
        out[k] = fx.push(t_s[k], temp_c[k], &row_aux[..aux.len()])?;
    }
    Ok(())
}
