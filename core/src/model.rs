//! The RBF drift model as stored in flash and sent over the wire.
//!
//! CONTRACT (shared by trainer, diagnose, firmware): the struct layout below is
//! the one every crate builds against. Encoding is postcard of `WireModel`
//! (magic, version, body, CRC-32 of the body bytes); decoding validates sizes,
//! finiteness, positive widths and ranges and returns a `ModelError`.
//!
//! drift_dph = bias_dph + sum_j linear[j] * xn_j + sum_i weights[i] * exp(-||xn - c_i||^2 / (2 widths[i]^2))
//! with xn_j = (x_j - input_offset[j]) / input_scale[j] (normalised inputs).
//! Only the first `n_rbf_inputs` inputs enter the Gaussian distance; inputs after
//! them are linear-only terms (diagnose may add a cause that way).

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

/// Most RBF centres a model may hold.
pub const MAX_CENTERS: usize = 64;
/// Most model inputs.
pub const MAX_INPUTS: usize = 4;
/// Magic at the start of every encoded model: "FOGM".
pub const MODEL_MAGIC: u32 = 0x4D47_4F46;
/// Current format version.
pub const MODEL_VERSION: u16 = 1;
/// Largest encoded model, bytes (a 64-centre, 4-input model must fit).
pub const MAX_ENCODED_LEN: usize = 2048;

/// What one model input is, so the device can compute it from its own sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeatureKind {
    /// Gyro temperature, degC.
    TempC,
    /// dT/dt, degC/s (least-squares slope, see `features`).
    TempRateCps,
    /// d2T/dt2, degC/s^2.
    TempAccelCps2,
    /// Temperature through a first-order lag of `tau_s`, degC.
    TempLagC,
    /// exp(-t / tau_s), t = time since power-on.
    PowerOnDecay,
    /// Auxiliary channel n (extra sensor column), its value.
    AuxValue(u8),
    /// Auxiliary channel n, its rate per second.
    AuxRate(u8),
    /// cos of an angle channel n (deg) -- heading harmonics.
    AuxCos(u8),
    /// sin of an angle channel n (deg).
    AuxSin(u8),
}

/// One model input: its kind and, for lags and decays, a time constant (s; 0 otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FeatureSpec {
    pub kind: FeatureKind,
    pub tau_s: f32,
}

/// Where the model came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainingMeta {
    pub gyro_id: String<16>,
    /// Held-out rms of the compensated 10 s drift, deg/h.
    pub heldout_rms_dph: f32,
    /// Number of training samples (candidate centres).
    pub n_train: u32,
}

/// A validated RBF drift model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RbfModel {
    /// How many of `inputs` (the leading ones) enter the RBF distance; the rest are linear-only.
    pub n_rbf_inputs: u8,
    pub inputs: Vec<FeatureSpec, MAX_INPUTS>,
    pub input_offset: Vec<f32, MAX_INPUTS>,
    pub input_scale: Vec<f32, MAX_INPUTS>,
    /// Trained range of each input, raw units (inclusive).
    pub input_min: Vec<f32, MAX_INPUTS>,
    pub input_max: Vec<f32, MAX_INPUTS>,
    /// Linear terms on the normalised inputs, deg/h per unit (zeros for a pure RBF).
    pub linear: Vec<f32, MAX_INPUTS>,
    /// Centres in normalised input space; each has `inputs.len()` used entries.
    pub centers: Vec<[f32; MAX_INPUTS], MAX_CENTERS>,
    /// Gaussian widths (sigma) in normalised space, > 0.
    pub widths: Vec<f32, MAX_CENTERS>,
    /// Output weights, deg/h.
    pub weights: Vec<f32, MAX_CENTERS>,
    pub bias_dph: f32,
    pub meta: TrainingMeta,
}
