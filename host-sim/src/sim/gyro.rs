//! The streaming simulated FOG: one raw sample per call, from the thermal state, the
//! drift physics, the Earth rate along the input axis and the IEEE 952 noise.
//! Implements `fog_core::hal::{Gyro, TemperatureSensor}` so the same core code that
//! runs on the device runs against it.
//!
//! drift = b0 + b1 (T_c - T_ref) + b2 (T_c - T_ref)^2            temperature bias
//!       + k_S(T_c) dT_c/dt                                        Shupe (radial gradient)
//!       + k_G d(T_h - T_c)/dt                                     gradient rate (~ d2T/dt2)
//!       + turn-on bias + extra terms + noise

use super::error::SimError;
use super::noise::NoiseGen;
use super::params::{GyroParams, SensorPlacement};
use super::spec::{RunSpec, StartState};
use super::terms::{TermInputs, TermState};
use super::thermal::ThermalNet;
use super::tripod::BaseMotion;
use super::turntable::TableLink;
use fog_core::consts::EARTH_RATE_DPH;
use fog_core::hal::{Gyro, GyroSample, TempSample, TemperatureSensor};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::convert::Infallible;

/// Random streams of one run, so that e.g. reading the temperature more often does not
/// change the gyro noise.
const STREAM_GYRO: u64 = 0;
const STREAM_SENSOR: u64 = 1;
const STREAM_RUN: u64 = 2;
/// Stream of the turntable's indexing errors.
pub(crate) const STREAM_TABLE: u64 = 3;
/// Stream of the inclinometer noise.
const STREAM_INCLINOMETER: u64 = 4;

/// A seeded generator on one of the run's streams.
pub(crate) fn stream_rng(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}

/// One raw sample with the truth behind it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawSample {
    /// End of the sample interval, s since power-on.
    pub t_s: f64,
    /// Gyro output (mean rate over the interval, quantised), deg/h.
    pub rate_dph: f64,
    /// Earth rate along the input axis, deg/h.
    pub earth_dph: f64,
    /// Deterministic drift (without noise), deg/h.
    pub drift_dph: f64,
    /// True coil and housing temperatures, degC.
    pub coil_c: f64,
    pub housing_c: f64,
    /// Azimuth of the input axis (horizontal) or of the table zero + table angle, deg.
    pub azimuth_deg: f64,
}

/// The simulated gyro.
#[derive(Debug)]
pub struct SimGyro {
    params: GyroParams,
    dt_s: f64,
    step: u64,
    thermal: ThermalNet,
    sensor_c: f64,
    sensor_alpha: f64,
    noise: NoiseGen,
    terms: Vec<TermState>,
    turn_on_bias_dph: f64,
    earth_vertical_dph: f64,
    earth_horizontal_dph: f64,
    heading_deg: f64,
    vertical: bool,
    table: Option<TableLink>,
    rng_gyro: ChaCha8Rng,
    rng_sensor: ChaCha8Rng,
    last: Option<RawSample>,
    last_input_rate_dph: f64,
    base: Option<BaseMotion>,
    latitude_deg: f64,
    rng_inclinometer: ChaCha8Rng,
}

impl SimGyro {
    /// A gyro powered on at t = 0 under `spec`, fixed (no turntable).
    pub fn new(params: &GyroParams, spec: &RunSpec) -> Result<Self, SimError> {
        params.validate()?;
        spec.validate()?;
        let dt_s = 1.0 / spec.raw_rate_hz;
        let mut rng_run = stream_rng(spec.seed, STREAM_RUN);
        let mut rng_gyro = stream_rng(spec.seed, STREAM_GYRO);
        let mut n = || -> f64 { rng_run.sample(StandardNormal) };
        let turn_on_bias_dph = params.drift.turn_on_bias_sigma_dph * n();
        let power_scale = (1.0 + params.variation.power_sigma_frac * n()).max(0.0);
        let soak_error_c = params.variation.start_temp_sigma_c * n();
        let start_c = match spec.start {
            StartState::Soaked => spec.ambient_c + soak_error_c,
            StartState::Restart { above_ambient_c } => spec.ambient_c + above_ambient_c,
            StartState::Warm => spec.ambient_c,
        };
        let mut thermal =
            ThermalNet::new(&params.thermal, spec.ambient_c, power_scale, start_c, dt_s);
        if spec.start == StartState::Warm {
            thermal.settle();
        }
        let lat = spec.latitude_deg.to_radians();
        let noise = NoiseGen::new(&params.noise, dt_s, &mut rng_gyro);
        let mut gyro = Self {
            sensor_c: 0.0,
            sensor_alpha: if params.sensor.lag_s > 0.0 {
                1.0 - (-dt_s / params.sensor.lag_s).exp()
            } else {
                1.0
            },
            terms: vec![TermState::new(); params.extra_terms.len()],
            params: params.clone(),
            dt_s,
            step: 0,
            thermal,
            noise,
            turn_on_bias_dph,
            earth_vertical_dph: EARTH_RATE_DPH * lat.sin(),
            earth_horizontal_dph: EARTH_RATE_DPH * lat.cos(),
            heading_deg: spec.heading_deg,
            vertical: spec.input_axis_vertical,
            table: None,
            rng_gyro,
            rng_sensor: stream_rng(spec.seed, STREAM_SENSOR),
            last: None,
            last_input_rate_dph: 0.0,
            base: None,
            latitude_deg: spec.latitude_deg,
            rng_inclinometer: stream_rng(spec.seed, STREAM_INCLINOMETER),
        };
        gyro.sensor_c = gyro.sensor_node_c();
        Ok(gyro)
    }

    /// Mounts the gyro on a table: its azimuth becomes `heading_deg` + table angle.
    pub(crate) fn attach_table(&mut self, link: TableLink) {
        self.table = Some(link);
    }

    fn sensor_node_c(&self) -> f64 {
        match self.params.sensor.placement {
            SensorPlacement::Coil => self.thermal.coil_c(),
            SensorPlacement::Housing => self.thermal.housing_c(),
        }
    }

    /// Stands the (horizontal-axis) gyro's turntable on a tilted, possibly rocking base.
    pub fn set_base(&mut self, base: BaseMotion) -> Result<(), SimError> {
        base.validate()?;
        self.base = Some(base);
        Ok(())
    }

    /// One inclinometer reading of the base now (level and noiseless without a base).
    pub fn read_inclinometer(&mut self) -> fog_core::seeking::tilt::Tilt {
        let t = self.now_s();
        match &self.base {
            Some(b) => b.read_inclinometer(t, &mut self.rng_inclinometer),
            None => fog_core::seeking::tilt::Tilt::LEVEL,
        }
    }

    /// The gyro's parameters.
    pub fn params(&self) -> &GyroParams {
        &self.params
    }

    /// Raw sample period, s.
    pub fn sample_period_s(&self) -> f64 {
        self.dt_s
    }

    /// Time of the latest sample, s since power-on (0 before the first).
    pub fn now_s(&self) -> f64 {
        self.step as f64 * self.dt_s
    }

    /// The latest sample, if any.
    pub fn last_sample(&self) -> Option<RawSample> {
        self.last
    }

    /// The turn-on bias drawn for this power-on, deg/h.
    pub fn turn_on_bias_dph(&self) -> f64 {
        self.turn_on_bias_dph
    }

    /// True coil temperature now, degC.
    pub fn coil_c(&self) -> f64 {
        self.thermal.coil_c()
    }

    fn table_angle_deg(&self, t_s: f64) -> f64 {
        self.table
            .as_ref()
            .map_or(0.0, |t| t.borrow().angle_deg(t_s))
    }

    /// Deterministic drift at the current thermal state, deg/h (without extra terms).
    fn physics_drift_dph(&self) -> f64 {
        let d = &self.params.drift;
        let dt_c = self.thermal.coil_c() - d.bias_ref_c;
        let [coil_rate, housing_rate] = self.thermal.rates_cps();
        let shupe_gain = (1.0 - d.shupe_cold_gain_per_k * dt_c).max(0.0);
        d.bias_dph
            + d.bias_dph_per_c * dt_c
            + d.bias_dph_per_c2 * dt_c * dt_c
            + d.shupe_dph_per_cps * shupe_gain * coil_rate
            + d.gradient_dph_per_cps * (housing_rate - coil_rate)
    }

    /// Produces the next raw sample.
    pub fn next_sample(&mut self) -> RawSample {
        let t0 = self.now_s();
        self.step += 1;
        let t1 = self.now_s();
        self.thermal.step();
        self.sensor_c += self.sensor_alpha * (self.sensor_node_c() - self.sensor_c);

        let (a0, a1) = (self.table_angle_deg(t0), self.table_angle_deg(t1));
        if let Some(t) = &self.table {
            t.borrow_mut().set_now(t1);
        }
        let azimuth_deg = self.heading_deg + 0.5 * (a0 + a1);
        let (earth_dph, table_dph) = if self.vertical {
            // Heading increases clockwise seen from above: a negative rotation about "up".
            (self.earth_vertical_dph, -(a1 - a0) / self.dt_s * 3600.0)
        } else if let Some(b) = &self.base {
            let h = 0.5 * (a0 + a1);
            (
                b.input_rate_dph(self.latitude_deg, self.heading_deg, h, t1),
                0.0,
            )
        } else {
            (
                self.earth_horizontal_dph * azimuth_deg.to_radians().cos(),
                0.0,
            )
        };

        let inputs = TermInputs {
            t_s: t1,
            coil_c: self.thermal.coil_c(),
            housing_c: self.thermal.housing_c(),
            sensor_c: self.sensor_c,
            azimuth_deg,
            input_rate_dph: earth_dph + table_dph,
        };
        self.last_input_rate_dph = earth_dph + table_dph;
        let mut drift_dph = self.physics_drift_dph() + self.turn_on_bias_dph;
        for (state, term) in self.terms.iter_mut().zip(&self.params.extra_terms) {
            drift_dph += state.update(term, &inputs, self.dt_s);
        }
        let slow_noise = self.noise.step_bias_dph(&mut self.rng_gyro);
        let white = self.noise.white_dph(&mut self.rng_gyro);
        let true_rate = earth_dph + table_dph + drift_dph + slow_noise + white;
        let rate_dph = self.noise.quantise(true_rate, self.dt_s);
        let s = RawSample {
            t_s: t1,
            rate_dph,
            earth_dph,
            drift_dph,
            coil_c: inputs.coil_c,
            housing_c: inputs.housing_c,
            azimuth_deg,
        };
        self.last = Some(s);
        s
    }

    /// One temperature reading now: lagged node temperature + noise, rounded to the
    /// sensor resolution, degC.
    pub fn read_sensor_c(&mut self) -> f64 {
        let s = &self.params.sensor;
        let noise: f64 = self.rng_sensor.sample(StandardNormal);
        let v = self.sensor_c + s.noise_c * noise;
        if s.resolution_c > 0.0 {
            (v / s.resolution_c).round() * s.resolution_c
        } else {
            v
        }
    }

    /// The inputs the extra drift terms see right now (for writing their columns).
    pub(crate) fn term_inputs(&self) -> TermInputs {
        let t = self.now_s();
        TermInputs {
            t_s: t,
            coil_c: self.thermal.coil_c(),
            housing_c: self.thermal.housing_c(),
            sensor_c: self.sensor_c,
            azimuth_deg: self.heading_deg + self.table_angle_deg(t),
            input_rate_dph: self.last_input_rate_dph,
        }
    }
}

impl Iterator for SimGyro {
    type Item = RawSample;
    fn next(&mut self) -> Option<RawSample> {
        Some(self.next_sample())
    }
}

impl Gyro for SimGyro {
    type Error = Infallible;
    fn read(&mut self) -> Result<Option<GyroSample>, Infallible> {
        let s = self.next_sample();
        Ok(Some(GyroSample {
            t_s: s.t_s,
            rate_dph: s.rate_dph as f32,
        }))
    }
}

impl TemperatureSensor for SimGyro {
    type Error = Infallible;
    fn read_temp(&mut self) -> Result<TempSample, Infallible> {
        let temp_c = self.read_sensor_c() as f32;
        Ok(TempSample {
            t_s: self.now_s(),
            temp_c,
        })
    }
}
