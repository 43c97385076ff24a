//! Physical parameters of the simulated FOG: thermal network, temperature sensor,
//! drift physics, IEEE Std 952 noise terms, run-to-run variation, and the default
//! gyro calibrated to the paper at 20 degC (`GyroParams::paper_default`).

use super::checks::{finite, fraction, non_negative, positive};
use super::error::SimError;
use super::terms::DriftTerm;

/// Lumped thermal network: fibre coil <-> housing <-> ambient, heat from power-on.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermalParams {
    /// Heat capacity of the fibre coil and its spool, J/K.
    pub coil_heat_capacity_j_per_k: f64,
    /// Heat capacity of the housing, electronics and mounting, J/K.
    pub housing_heat_capacity_j_per_k: f64,
    /// Conductance coil <-> housing, W/K.
    pub coil_housing_w_per_k: f64,
    /// Conductance housing <-> ambient at 20 degC, W/K.
    pub housing_ambient_w_per_k: f64,
    /// Relative change of the housing-ambient conductance per degC of ambient (air
    /// conductivity and convection rise with temperature), 1/K.
    pub housing_ambient_tempco_per_k: f64,
    /// Dissipation after power-on (light source, detector, electronics), W.
    pub power_w: f64,
    /// Fraction of the dissipation released inside the coil enclosure (light source).
    pub coil_power_fraction: f64,
    /// Extra dissipation of the light source's thermo-electric cooler per degC that the
    /// ambient differs from its set point, W/K.
    pub tec_w_per_k: f64,
    /// Light-source TEC set point, degC.
    pub tec_setpoint_c: f64,
}

/// Where the temperature sensor sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SensorPlacement {
    /// On the fibre coil (the paper's "gyro internal temperature").
    Coil,
    /// On the housing.
    Housing,
}

/// The gyro's temperature sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorParams {
    pub placement: SensorPlacement,
    /// First-order lag between the node and the sensor reading, s (0 = none).
    pub lag_s: f64,
    /// White reading noise, degC (1 sigma).
    pub noise_c: f64,
    /// Resolution (LSB), degC; readings are rounded to it.
    pub resolution_c: f64,
    /// How often `simulate_run` reads the sensor, s (its `temp_c` is the window mean).
    pub sample_period_s: f64,
}

/// Deterministic drift physics (deg/h).
#[derive(Clone, Debug, PartialEq)]
pub struct DriftParams {
    /// Fixed bias at the reference temperature, deg/h.
    pub bias_dph: f64,
    /// Reference temperature of the bias polynomial, degC.
    pub bias_ref_c: f64,
    /// Linear bias temperature sensitivity, deg/h per degC (coil temperature).
    pub bias_dph_per_c: f64,
    /// Quadratic bias temperature sensitivity, deg/h per degC^2.
    pub bias_dph_per_c2: f64,
    /// Shupe coefficient at the reference temperature: deg/h per degC/s of coil
    /// temperature rate (the radial gradient inside the coil follows the rate).
    pub shupe_dph_per_cps: f64,
    /// Fractional increase of the Shupe coefficient per degC below the reference
    /// (the fibre coating stiffens in the cold), 1/K.
    pub shupe_cold_gain_per_k: f64,
    /// Gradient-rate term: deg/h per degC/s of d(T_housing - T_coil)/dt, the time rate
    /// of the axial gradient across the coil (~ d2T/dt2 in a lumped model).
    pub gradient_dph_per_cps: f64,
    /// Turn-on to turn-on bias repeatability, deg/h (1 sigma), constant within a run.
    pub turn_on_bias_sigma_dph: f64,
}

/// IEEE Std 952 noise terms.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseParams {
    /// Angle random walk N, deg/sqrt(h).
    pub arw_dpsh: f64,
    /// Bias instability B, deg/h (Allan floor = 0.664 B), made as three Gauss-Markov
    /// processes with correlation times 20, 200 and 2000 s.
    pub bias_instability_dph: f64,
    /// Rate random walk K, deg/h/sqrt(h).
    pub rrw_dph_per_sqrt_h: f64,
    /// Output angle quantum (one pulse), arcsec; 0 = unquantised.
    pub quantization_arcsec: f64,
}

/// Run-to-run variation of one power-on.
#[derive(Clone, Debug, PartialEq)]
pub struct RunVariation {
    /// Relative 1-sigma variation of the dissipation.
    pub power_sigma_frac: f64,
    /// 1-sigma difference of the start temperature from the ambient (imperfect soak), degC.
    pub start_temp_sigma_c: f64,
}

/// Everything that defines a simulated gyro.
#[derive(Clone, Debug, PartialEq)]
pub struct GyroParams {
    pub thermal: ThermalParams,
    pub sensor: SensorParams,
    pub drift: DriftParams,
    pub noise: NoiseParams,
    pub variation: RunVariation,
    /// Additional, pluggable drift terms (a coefficient on an auxiliary signal).
    pub extra_terms: Vec<DriftTerm>,
}

impl GyroParams {
    /// The default gyro, calibrated to the paper at 20 degC (largest startup deviation
    /// ~0.17 deg/h, ~15 min to the 0.021 deg/h spec; see `docs/explain/simulator.md`).
    pub fn paper_default() -> Self {
        Self {
            thermal: ThermalParams {
                coil_heat_capacity_j_per_k: 60.0,
                housing_heat_capacity_j_per_k: 150.0,
                coil_housing_w_per_k: 0.6,
                housing_ambient_w_per_k: 0.6,
                housing_ambient_tempco_per_k: 0.003,
                power_w: 3.0,
                coil_power_fraction: 0.2,
                tec_w_per_k: 0.01,
                tec_setpoint_c: 25.0,
            },
            sensor: SensorParams {
                placement: SensorPlacement::Coil,
                lag_s: 10.0,
                noise_c: 0.02,
                resolution_c: 0.0625,
                sample_period_s: 1.0,
            },
            drift: DriftParams {
                bias_dph: 0.02,
                bias_ref_c: 20.0,
                bias_dph_per_c: 0.002,
                bias_dph_per_c2: 2e-5,
                shupe_dph_per_cps: 14.0,
                shupe_cold_gain_per_k: 0.006,
                gradient_dph_per_cps: 4.0,
                turn_on_bias_sigma_dph: 0.004,
            },
            noise: NoiseParams {
                arw_dpsh: 0.0007,
                bias_instability_dph: 0.002,
                rrw_dph_per_sqrt_h: 0.001,
                quantization_arcsec: 0.01,
            },
            variation: RunVariation {
                power_sigma_frac: 0.02,
                start_temp_sigma_c: 0.2,
            },
            extra_terms: Vec::new(),
        }
    }

    /// Checks that every parameter is finite and physically possible.
    pub fn validate(&self) -> Result<(), SimError> {
        let t = &self.thermal;
        positive(
            "thermal.coil_heat_capacity_j_per_k",
            t.coil_heat_capacity_j_per_k,
        )?;
        positive(
            "thermal.housing_heat_capacity_j_per_k",
            t.housing_heat_capacity_j_per_k,
        )?;
        positive("thermal.coil_housing_w_per_k", t.coil_housing_w_per_k)?;
        positive("thermal.housing_ambient_w_per_k", t.housing_ambient_w_per_k)?;
        finite(
            "thermal.housing_ambient_tempco_per_k",
            t.housing_ambient_tempco_per_k,
        )?;
        non_negative("thermal.power_w", t.power_w)?;
        fraction("thermal.coil_power_fraction", t.coil_power_fraction)?;
        non_negative("thermal.tec_w_per_k", t.tec_w_per_k)?;
        finite("thermal.tec_setpoint_c", t.tec_setpoint_c)?;
        let s = &self.sensor;
        non_negative("sensor.lag_s", s.lag_s)?;
        non_negative("sensor.noise_c", s.noise_c)?;
        non_negative("sensor.resolution_c", s.resolution_c)?;
        positive("sensor.sample_period_s", s.sample_period_s)?;
        let d = &self.drift;
        for (name, v) in [
            ("drift.bias_dph", d.bias_dph),
            ("drift.bias_ref_c", d.bias_ref_c),
            ("drift.bias_dph_per_c", d.bias_dph_per_c),
            ("drift.bias_dph_per_c2", d.bias_dph_per_c2),
            ("drift.shupe_dph_per_cps", d.shupe_dph_per_cps),
            ("drift.shupe_cold_gain_per_k", d.shupe_cold_gain_per_k),
            ("drift.gradient_dph_per_cps", d.gradient_dph_per_cps),
        ] {
            finite(name, v)?;
        }
        non_negative("drift.turn_on_bias_sigma_dph", d.turn_on_bias_sigma_dph)?;
        let n = &self.noise;
        non_negative("noise.arw_dpsh", n.arw_dpsh)?;
        non_negative("noise.bias_instability_dph", n.bias_instability_dph)?;
        non_negative("noise.rrw_dph_per_sqrt_h", n.rrw_dph_per_sqrt_h)?;
        non_negative("noise.quantization_arcsec", n.quantization_arcsec)?;
        non_negative(
            "variation.power_sigma_frac",
            self.variation.power_sigma_frac,
        )?;
        non_negative(
            "variation.start_temp_sigma_c",
            self.variation.start_temp_sigma_c,
        )?;
        for term in &self.extra_terms {
            term.validate()?;
        }
        Ok(())
    }

    /// Adds a pluggable drift term (builder style).
    pub fn with_term(mut self, term: DriftTerm) -> Self {
        self.extra_terms.push(term);
        self
    }

    /// Adds a heading-dependent bias A cos(input axis azimuth), deg/h (a magnetic /
    /// Faraday bias; 0: unchanged). North-seek and the heading campaign plant it.
    pub fn with_heading_bias(self, amplitude_dph: f64) -> Self {
        if amplitude_dph == 0.0 {
            return self;
        }
        self.with_term(DriftTerm {
            label: "heading_bias".to_string(),
            source: super::terms::AuxSource::HeadingCos,
            transform: super::terms::AuxTransform::Value,
            coeff_dph: amplitude_dph,
            column: None,
        })
    }
}
