//! Pluggable extra drift terms: `coeff_dph * transform(source)`, evaluated at every raw
//! sample. This is how `diagnose` extends the simulator with a named effect and its
//! fitted coefficient (e.g. drift proportional to a supply-voltage column, to d2T/dt2,
//! to a power-on decay, or a heading-dependent magnetic bias).

use super::checks::{finite, positive};
use super::error::SimError;

/// The signal a term acts on.
#[derive(Clone, Debug, PartialEq)]
pub enum AuxSource {
    /// True coil temperature, degC.
    CoilTempC,
    /// True housing temperature, degC.
    HousingTempC,
    /// The sensor's lagged temperature before noise and rounding, degC.
    SensorTempC,
    /// exp(-t / tau_s), t = time since power-on.
    PowerOnDecay { tau_s: f64 },
    /// cos of the input axis azimuth (deg) -- e.g. a magnetic (Faraday) bias.
    HeadingCos,
    /// sin of the input axis azimuth.
    HeadingSin,
    /// The true angular rate along the input axis (Earth + table), deg/h: a coefficient
    /// on it is a scale-factor error (dK/K).
    InputRateDph,
    /// A measured or synthetic series (e.g. a `supply_v` column): linear interpolation
    /// in `t_s`, held constant outside it.
    Series { t_s: Vec<f64>, values: Vec<f64> },
}

/// What is done to the source before the coefficient multiplies it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AuxTransform {
    Value,
    /// d/dt, per s.
    Rate,
    /// d2/dt2, per s^2.
    Accel,
    /// First-order low-pass with time constant `tau_s`.
    Lag {
        tau_s: f64,
    },
}

/// One extra drift term.
#[derive(Clone, Debug, PartialEq)]
pub struct DriftTerm {
    /// Name for reports, e.g. `supply_v:value`.
    pub label: String,
    pub source: AuxSource,
    pub transform: AuxTransform,
    /// deg/h per unit of the transformed signal.
    pub coeff_dph: f64,
    /// When set, `simulate_run` also writes the (untransformed) source as this column.
    pub column: Option<String>,
}

impl DriftTerm {
    /// Checks the coefficient, time constants and series.
    pub fn validate(&self) -> Result<(), SimError> {
        finite("term.coeff_dph", self.coeff_dph)?;
        if let AuxTransform::Lag { tau_s } = self.transform {
            positive("term.lag.tau_s", tau_s)?;
        }
        match &self.source {
            AuxSource::PowerOnDecay { tau_s } => positive("term.decay.tau_s", *tau_s),
            AuxSource::Series { t_s, values } => {
                let bad = |why| {
                    Err(SimError::BadSeries {
                        term: self.label.clone(),
                        why,
                    })
                };
                if t_s.len() != values.len() {
                    return bad("has different lengths of t_s and values");
                }
                if t_s.is_empty() {
                    return bad("is empty");
                }
                if t_s.iter().chain(values).any(|v| !v.is_finite()) {
                    return bad("holds NaN or infinite values");
                }
                if t_s.windows(2).any(|w| w[1] <= w[0]) {
                    return bad("time does not strictly increase");
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

/// What a term can read from the simulation at one instant.
#[derive(Clone, Copy, Debug)]
pub struct TermInputs {
    pub t_s: f64,
    pub coil_c: f64,
    pub housing_c: f64,
    pub sensor_c: f64,
    pub azimuth_deg: f64,
    pub input_rate_dph: f64,
}

/// Source value at an instant.
pub fn source_value(source: &AuxSource, x: &TermInputs) -> f64 {
    match source {
        AuxSource::CoilTempC => x.coil_c,
        AuxSource::HousingTempC => x.housing_c,
        AuxSource::SensorTempC => x.sensor_c,
        AuxSource::PowerOnDecay { tau_s } => (-x.t_s / tau_s).exp(),
        AuxSource::HeadingCos => x.azimuth_deg.to_radians().cos(),
        AuxSource::HeadingSin => x.azimuth_deg.to_radians().sin(),
        AuxSource::InputRateDph => x.input_rate_dph,
        AuxSource::Series { t_s, values } => interpolate(t_s, values, x.t_s),
    }
}

fn interpolate(t: &[f64], v: &[f64], at: f64) -> f64 {
    let i = t.partition_point(|&ti| ti <= at);
    if i == 0 {
        return v[0];
    }
    if i == t.len() {
        return v[t.len() - 1];
    }
    let f = (at - t[i - 1]) / (t[i] - t[i - 1]);
    v[i - 1] + f * (v[i] - v[i - 1])
}

/// Running state of one term (finite differences and the lag filter).
#[derive(Clone, Debug)]
pub struct TermState {
    prev_value: Option<f64>,
    prev_rate: Option<f64>,
    lag: Option<f64>,
}

impl TermState {
    pub fn new() -> Self {
        Self {
            prev_value: None,
            prev_rate: None,
            lag: None,
        }
    }

    /// The term's drift contribution, deg/h, after one step of `dt_s`.
    pub fn update(&mut self, term: &DriftTerm, x: &TermInputs, dt_s: f64) -> f64 {
        let v = source_value(&term.source, x);
        let rate = self.prev_value.map_or(0.0, |p| (v - p) / dt_s);
        let accel = self.prev_rate.map_or(0.0, |p| (rate - p) / dt_s);
        let transformed = match term.transform {
            AuxTransform::Value => v,
            AuxTransform::Rate => rate,
            AuxTransform::Accel => accel,
            AuxTransform::Lag { tau_s } => {
                let alpha = 1.0 - (-dt_s / tau_s).exp();
                let l = self.lag.map_or(v, |l| l + alpha * (v - l));
                self.lag = Some(l);
                l
            }
        };
        if self.prev_value.is_some() {
            self.prev_rate = Some(rate);
        }
        self.prev_value = Some(v);
        term.coeff_dph * transformed
    }
}

impl Default for TermState {
    fn default() -> Self {
        Self::new()
    }
}
