//! The RBF drift model as stored in flash and sent over the wire.
//!
//! CONTRACT (shared by trainer, diagnose, firmware): the struct layout below is
//! the one every crate builds against. Encoding is postcard of `WireModel`
//! (magic, version, body, CRC-32 of the body bytes); decoding (`model::in_place`, above
//! this file) validates sizes, finiteness, positive widths and ranges and returns a
//! `ModelError` (`model::error`, below it, with the stored sub-records `model::heading` and
//! `model::cold_start` and the CRC `model::crc`).
//!
//! drift_dph = bias_dph + sum_j (linear[j] + linear_by_t[j] * t) * xn_j + sum_k poly[k-1] * t^k
//!             + sum_i weights[i] * exp(-||xn - c_i||^2 / (2 widths[i]^2))
//! with xn_j = (x_j - input_offset[j]) / input_scale[j] (normalised inputs, each held to
//! +-`XN_CLAMP`) and t = xn_0 held to the trained range of input 0 (a polynomial is not
//! extrapolated). Only the first `n_rbf_inputs` inputs enter the Gaussian distance; inputs
//! after them are linear-only terms (diagnose may add a cause that way).
//!
//! Format versions: 1 has no `poly` (decoded with an empty one), 2 appends `poly` after
//! `meta`, 3 appends `heading` after `poly`: the optional heading harmonic of the bias
//! (`model::heading`, fitted by `seeking::heading_cal`), stored inside the model bytes so that the model's CRC and the upload
//! signature cover it (v1 and v2 decode with none), 4 appends `linear_by_t` after
//! `heading`: linear terms whose coefficients change with temperature (a Shupe coefficient
//! k_S(T) = k_0 + k_1 T makes the drift k_0 dT/dt + k_1 T dT/dt; v1-v3 decode with none), 5
//! appends `cold_start` after `linear_by_t`: the optional envelope of the training cold
//! starts' temperature rise (`model::cold_start`; v1-v4 decode with none). Validation bounds every parameter's magnitude so that any model that decodes
//! gives a finite drift below `MAX_OUTPUT_DPH` at any finite input.

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

use crate::model::cold_start::ColdStartEnvelope;
use crate::model::crc::crc32;
use crate::model::error::{check_finite, check_len, ModelError, ModelField};
use crate::model::heading::{HeadingHarmonic, MIN_HEADINGS};

/// Most RBF centres a model may hold.
pub const MAX_CENTERS: usize = 64;
/// Most model inputs.
pub const MAX_INPUTS: usize = 4;
/// Magic at the start of every encoded model: "FOGM".
pub const MODEL_MAGIC: u32 = 0x4D47_4F46;
/// Current format version (5: the cold-start envelope after the temperature-coupled
/// linear terms).
pub const MODEL_VERSION: u16 = 5;
/// Oldest format version still decoded (1: no polynomial base).
pub const MODEL_VERSION_OLDEST: u16 = 1;
/// Highest power of the polynomial base in the first input.
pub const MAX_POLY_DEGREE: usize = 3;
/// Normalised inputs are held to +-this many standard deviations before evaluation
/// (the fixed-point path's Q.28 limit).
pub const XN_CLAMP: f32 = 120.0;
/// Largest |drift| a valid model can produce at any input, deg/h: validation refuses a
/// model whose worst-case sum of terms exceeds it.
pub const MAX_OUTPUT_DPH: f64 = 1.0e6;
/// Largest |raw| input offset and trained-range bound (any unit).
pub const MAX_ABS_RAW_INPUT: f32 = 1.0e6;
/// Allowed input scales (raw units per normalised unit).
pub const INPUT_SCALE_RANGE: (f32, f32) = (1.0e-6, 1.0e6);
/// Largest |centre coordinate|, normalised units (fixed point needs < 100).
pub const MAX_ABS_CENTER: f32 = 99.0;
/// Allowed Gaussian widths, normalised units (fixed point additionally needs >= 0.0056).
pub const WIDTH_RANGE: (f32, f32) = (1.0e-3, 100.0);
/// Largest |a|, |b| of a stored heading harmonic, deg/h (a magnetic bias of a navigation
/// grade FOG is ~0.01-0.1 deg/h; 10 deg/h is far above any physical one, so a larger value
/// is a units or sign-of-exponent mistake, not a calibration).
pub const MAX_HEADING_HARMONIC_DPH: f32 = 10.0;
/// Largest 1-sigma of a stored heading harmonic coefficient, deg/h.
pub const MAX_HEADING_SIGMA_DPH: f32 = 10.0;
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
    /// d2T/dt2, degC/s^2, with the temperature series taken as flat before its first
    /// reading (a unit soaked before power-on whose thermometer lags the heat; see
    /// `TempRateEstimator::new_flat_start`). Identical to `TempAccelCps2` once the first
    /// reading has left the span. Appended last: existing model files keep their meaning.
    TempAccelFlatStartCps2,
    /// Temperature rise since power-on, degC: the row's temperature minus the first row's
    /// (the soaked unit's start temperature, i.e. about its ambient). With T and dT/dt it
    /// tells a cold start at one ambient from a settled row of a colder one, which the
    /// first minutes' d2T/dt2 can only tell through its noise. Appended last: existing
    /// model files keep their meaning.
    TempRiseC,
}

/// One model input: its kind and, for lags and decays, a time constant (s; 0 otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FeatureSpec {
    pub kind: FeatureKind,
    pub tau_s: f32,
}

impl FeatureSpec {
    /// An input without a time constant (rate and accel then use the estimator's default span).
    pub const fn plain(kind: FeatureKind) -> Self {
        Self { kind, tau_s: 0.0 }
    }
}

/// The paper's inputs: gyro temperature and its rate.
pub const PAPER_INPUTS: [FeatureSpec; 2] = [
    FeatureSpec::plain(FeatureKind::TempC),
    FeatureSpec::plain(FeatureKind::TempRateCps),
];

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
    /// Polynomial base (format version 2): coefficient k-1 multiplies t^k, deg/h, with
    /// t = normalised input 0 held to its trained range; at most `MAX_POLY_DEGREE` terms.
    pub poly: Vec<f32, MAX_POLY_DEGREE>,
    /// Heading harmonic of the bias (format version 3), applied by the north finder while
    /// this model is active; `None`: no heading calibration (also for v1/v2 models).
    pub heading: Option<HeadingHarmonic>,
    /// Temperature-coupled linear terms (format version 4): coefficient j multiplies
    /// t * xn_j, deg/h per unit^2, t as for `poly` (normalised input 0 held to its trained
    /// range), so input j's linear coefficient is linear[j] + linear_by_t[j] t. Empty
    /// (none, also for v1-v3 models) or one per input.
    pub linear_by_t: Vec<f32, MAX_INPUTS>,
    /// The training cold starts' least temperature rise since power-on (format version 5):
    /// the compensator flags a power-on that rises less as not a cold start. `None`: no
    /// check (also for v1-v4 models).
    pub cold_start: Option<ColdStartEnvelope>,
}

/// Most auxiliary (extra sensor) channels a model may refer to.
pub const MAX_AUX: usize = 4;
/// Bytes reserved in front of the body while encoding (varint magic + version + length).
const HEADER_RESERVE: usize = 5 + 3 + 3;

/// The messages of `model::error::ModelError`, written here beside the limits they quote.
impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ModelError::BufferTooSmall { needed_at_least } => {
                write!(f, "model: output buffer too small (need at least {needed_at_least} bytes)")
            }
            ModelError::TooLarge { len } => {
                write!(f, "model: encoded size {len} bytes exceeds the {MAX_ENCODED_LEN}-byte limit")
            }
            ModelError::Truncated => write!(f, "model: data ends before the model does (truncated)"),
            ModelError::BadMagic { found } => write!(
                f,
                "model: bad magic 0x{found:08X} (expected 0x{MODEL_MAGIC:08X}, not a fog model)"
            ),
            ModelError::UnsupportedVersion { found } => write!(
                f,
                "model: format version {found} is not supported (this build reads versions {MODEL_VERSION_OLDEST}..={MODEL_VERSION})"
            ),
            ModelError::CrcMismatch { stored, computed } => write!(
                f,
                "model: CRC-32 mismatch (stored 0x{stored:08X}, computed 0x{computed:08X}): corrupted"
            ),
            ModelError::TrailingBytes { count } => {
                write!(f, "model: {count} unexpected bytes after the CRC")
            }
            ModelError::Malformed => write!(f, "model: body is not a well-formed model encoding"),
            ModelError::NoInputs => write!(f, "model: has no inputs"),
            ModelError::TooManyInputs { count } => {
                write!(f, "model: {count} inputs, at most {MAX_INPUTS} are supported")
            }
            ModelError::TooManyCenters { count } => {
                write!(f, "model: {count} centres, at most {MAX_CENTERS} are supported")
            }
            ModelError::BadRbfInputCount { n_rbf_inputs, n_inputs } => write!(
                f,
                "model: n_rbf_inputs = {n_rbf_inputs} is invalid for {n_inputs} inputs"
            ),
            ModelError::LengthMismatch { field, expected, found } => write!(
                f,
                "model: field `{}` has {found} entries, expected {expected}",
                field.name()
            ),
            ModelError::NonFinite { field, index } => {
                write!(f, "model: field `{}`[{index}] is NaN or infinite", field.name())
            }
            ModelError::NonPositiveScale { input } => {
                write!(f, "model: input_scale[{input}] must be > 0")
            }
            ModelError::NonPositiveWidth { center } => {
                write!(f, "model: widths[{center}] must be > 0")
            }
            ModelError::BadRange { input } => {
                write!(f, "model: trained range of input {input} has min > max")
            }
            ModelError::BadTimeConstant { input } => write!(
                f,
                "model: input {input} has an invalid tau_s (lags/decays need tau_s > 0, others >= 0)"
            ),
            ModelError::BadAuxChannel { input, channel } => write!(
                f,
                "model: input {input} uses aux channel {channel}, at most {MAX_AUX} channels exist"
            ),
            ModelError::OutOfBounds { field, index } => write!(
                f,
                "model: field `{}`[{index}] is outside its allowed magnitude",
                field.name()
            ),
            ModelError::OutputUnbounded { worst_dph } => write!(
                f,
                "model: parameters allow a drift of {worst_dph} deg/h, above the {MAX_OUTPUT_DPH} deg/h limit"
            ),
        }
    }
}

impl core::error::Error for ModelError {}

/// Counts written before the body so that oversize models get a precise error.
#[derive(Serialize, Deserialize)]
pub(crate) struct BodyCounts {
    pub(crate) n_inputs: u16,
    pub(crate) n_centers: u16,
}

/// The outer envelope: postcard of (magic, version, body bytes, CRC-32 of the body bytes).
#[derive(Serialize, Deserialize)]
pub(crate) struct WireModel<'a> {
    pub(crate) magic: u32,
    pub(crate) version: u16,
    #[serde(borrow)]
    pub(crate) body: &'a [u8],
    pub(crate) crc32: u32,
}

impl FeatureKind {
    /// The auxiliary channel this feature reads, if any.
    pub const fn aux_channel(self) -> Option<u8> {
        match self {
            FeatureKind::AuxValue(n)
            | FeatureKind::AuxRate(n)
            | FeatureKind::AuxCos(n)
            | FeatureKind::AuxSin(n) => Some(n),
            _ => None,
        }
    }

    /// True for kinds whose `tau_s` must be > 0 (lags and decays).
    pub const fn needs_time_constant(self) -> bool {
        matches!(self, FeatureKind::TempLagC | FeatureKind::PowerOnDecay)
    }

    /// True for kinds that take the power-on to be a cold start from a soak: the clock
    /// since power-on, the rise since the first reading, and the lag and flat-start d2T/dt2
    /// that start from the first reading as if it were the unit's settled state. A model
    /// with one of them is valid only for such power-ons (`model::cold_start`).
    pub const fn assumes_cold_start(self) -> bool {
        matches!(
            self,
            FeatureKind::PowerOnDecay
                | FeatureKind::TempRiseC
                | FeatureKind::TempLagC
                | FeatureKind::TempAccelFlatStartCps2
        )
    }
}

impl RbfModel {
    /// A placeholder with no inputs (fails `validate`): the initial value of model storage
    /// that lives in a `static` or is overwritten in place with `copy_from`.
    pub const fn empty() -> Self {
        RbfModel {
            n_rbf_inputs: 0,
            inputs: Vec::new(),
            input_offset: Vec::new(),
            input_scale: Vec::new(),
            input_min: Vec::new(),
            input_max: Vec::new(),
            linear: Vec::new(),
            centers: Vec::new(),
            widths: Vec::new(),
            weights: Vec::new(),
            bias_dph: 0.0,
            meta: TrainingMeta {
                gyro_id: String::new(),
                heldout_rms_dph: 0.0,
                n_train: 0,
            },
            poly: Vec::new(),
            heading: None,
            linear_by_t: Vec::new(),
            cold_start: None,
        }
    }

    /// Make `self` equal to `src`, field by field in place (`*self = src.clone()` would
    /// build the ~1.7 KB model as a temporary on the stack first).
    pub fn copy_from(&mut self, src: &RbfModel) {
        fn copy<T: Copy, const N: usize>(dst: &mut Vec<T, N>, src: &Vec<T, N>) {
            dst.clear();
            // Same capacity on both sides: cannot fail.
            let _ = dst.extend_from_slice(src);
        }
        self.n_rbf_inputs = src.n_rbf_inputs;
        copy(&mut self.inputs, &src.inputs);
        copy(&mut self.input_offset, &src.input_offset);
        copy(&mut self.input_scale, &src.input_scale);
        copy(&mut self.input_min, &src.input_min);
        copy(&mut self.input_max, &src.input_max);
        copy(&mut self.linear, &src.linear);
        copy(&mut self.centers, &src.centers);
        copy(&mut self.widths, &src.widths);
        copy(&mut self.weights, &src.weights);
        copy(&mut self.poly, &src.poly);
        copy(&mut self.linear_by_t, &src.linear_by_t);
        self.heading = src.heading;
        self.cold_start.clone_from(&src.cold_start);
        self.bias_dph = src.bias_dph;
        self.meta.gyro_id.clear();
        let _ = self.meta.gyro_id.push_str(&src.meta.gyro_id);
        self.meta.heldout_rms_dph = src.meta.heldout_rms_dph;
        self.meta.n_train = src.meta.n_train;
    }

    /// Number of inputs.
    pub fn n_inputs(&self) -> usize {
        self.inputs.len()
    }

    /// Number of RBF centres.
    pub fn n_centers(&self) -> usize {
        self.centers.len()
    }

    /// Check every invariant the evaluators rely on.
    pub fn validate(&self) -> Result<(), ModelError> {
        let n = self.inputs.len();
        if n == 0 {
            return Err(ModelError::NoInputs);
        }
        let nr = self.n_rbf_inputs as usize;
        if nr > n || (nr == 0 && !self.centers.is_empty()) {
            return Err(ModelError::BadRbfInputCount {
                n_rbf_inputs: self.n_rbf_inputs,
                n_inputs: n as u8,
            });
        }
        check_len(ModelField::InputOffset, n, self.input_offset.len())?;
        check_len(ModelField::InputScale, n, self.input_scale.len())?;
        check_len(ModelField::InputMin, n, self.input_min.len())?;
        check_len(ModelField::InputMax, n, self.input_max.len())?;
        check_len(ModelField::Linear, n, self.linear.len())?;
        let m = self.centers.len();
        check_len(ModelField::Widths, m, self.widths.len())?;
        check_len(ModelField::Weights, m, self.weights.len())?;
        for (i, spec) in self.inputs.iter().enumerate() {
            let tau_ok = spec.tau_s.is_finite()
                && if spec.kind.needs_time_constant() {
                    spec.tau_s > 0.0
                } else {
                    spec.tau_s >= 0.0
                };
            if !tau_ok {
                return Err(ModelError::BadTimeConstant { input: i as u8 });
            }
            if let Some(ch) = spec.kind.aux_channel() {
                if ch as usize >= MAX_AUX {
                    return Err(ModelError::BadAuxChannel {
                        input: i as u8,
                        channel: ch,
                    });
                }
            }
        }
        check_finite(ModelField::InputOffset, &self.input_offset)?;
        check_finite(ModelField::InputScale, &self.input_scale)?;
        check_finite(ModelField::InputMin, &self.input_min)?;
        check_finite(ModelField::InputMax, &self.input_max)?;
        check_finite(ModelField::Linear, &self.linear)?;
        if !self.linear_by_t.is_empty() {
            check_len(ModelField::LinearByT, n, self.linear_by_t.len())?;
        }
        check_finite(ModelField::LinearByT, &self.linear_by_t)?;
        if let Some(c) = &self.cold_start {
            c.validate()?;
        }
        if let Some(i) = self.input_scale.iter().position(|&s| s <= 0.0) {
            return Err(ModelError::NonPositiveScale { input: i as u8 });
        }
        if let Some(i) = (0..n).find(|&i| self.input_min[i] > self.input_max[i]) {
            return Err(ModelError::BadRange { input: i as u8 });
        }
        for (i, c) in self.centers.iter().enumerate() {
            if c.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::NonFinite {
                    field: ModelField::Centers,
                    index: i as u16,
                });
            }
        }
        check_finite(ModelField::Widths, &self.widths)?;
        if let Some(i) = self.widths.iter().position(|&w| w <= 0.0) {
            return Err(ModelError::NonPositiveWidth { center: i as u16 });
        }
        check_finite(ModelField::Weights, &self.weights)?;
        check_finite(ModelField::Bias, &[self.bias_dph])?;
        check_finite(ModelField::HeldoutRms, &[self.meta.heldout_rms_dph])?;
        check_finite(ModelField::Poly, &self.poly)?;
        if self.poly.len() > MAX_POLY_DEGREE {
            return Err(ModelError::OutOfBounds {
                field: ModelField::Poly,
                index: self.poly.len() as u16,
            });
        }
        self.check_heading()?;
        self.check_bounds()
    }

    /// The heading harmonic, if any: finite, |a|, |b| <= `MAX_HEADING_HARMONIC_DPH`,
    /// sigmas in [0, `MAX_HEADING_SIGMA_DPH`], |correlation| <= 1, at least `MIN_HEADINGS`.
    fn check_heading(&self) -> Result<(), ModelError> {
        let Some(h) = &self.heading else {
            return Ok(());
        };
        let values = [
            h.cos_dph,
            h.sin_dph,
            h.cos_sigma_dph,
            h.sin_sigma_dph,
            h.correlation,
        ];
        check_finite(ModelField::Heading, &values)?;
        let limits = [
            (-MAX_HEADING_HARMONIC_DPH, MAX_HEADING_HARMONIC_DPH),
            (-MAX_HEADING_HARMONIC_DPH, MAX_HEADING_HARMONIC_DPH),
            (0.0, MAX_HEADING_SIGMA_DPH),
            (0.0, MAX_HEADING_SIGMA_DPH),
            (-1.0, 1.0),
        ];
        if let Some(i) =
            (0..values.len()).find(|&i| !(limits[i].0..=limits[i].1).contains(&values[i]))
        {
            return Err(ModelError::OutOfBounds {
                field: ModelField::Heading,
                index: i as u16,
            });
        }
        if (h.n_headings as usize) < MIN_HEADINGS {
            return Err(ModelError::OutOfBounds {
                field: ModelField::Heading,
                index: 5,
            });
        }
        Ok(())
    }

    /// Magnitude bounds: every intermediate of the evaluators stays finite and the
    /// drift stays below `MAX_OUTPUT_DPH` whatever the (finite) inputs.
    fn check_bounds(&self) -> Result<(), ModelError> {
        let out = |field, index: usize| {
            Err(ModelError::OutOfBounds {
                field,
                index: index as u16,
            })
        };
        let raw_ok = |v: &f32| v.abs() <= MAX_ABS_RAW_INPUT;
        for (field, values) in [
            (ModelField::InputOffset, &self.input_offset),
            (ModelField::InputMin, &self.input_min),
            (ModelField::InputMax, &self.input_max),
        ] {
            if let Some(i) = values.iter().position(|v| !raw_ok(v)) {
                return out(field, i);
            }
        }
        let (s_lo, s_hi) = INPUT_SCALE_RANGE;
        if let Some(i) = self
            .input_scale
            .iter()
            .position(|&s| !(s_lo..=s_hi).contains(&s))
        {
            return out(ModelField::InputScale, i);
        }
        let n = self.inputs.len();
        if let Some(i) = self
            .centers
            .iter()
            .position(|c| c[..n].iter().any(|v| v.abs() > MAX_ABS_CENTER))
        {
            return out(ModelField::Centers, i);
        }
        let (w_lo, w_hi) = WIDTH_RANGE;
        if let Some(i) = self
            .widths
            .iter()
            .position(|&w| !(w_lo..=w_hi).contains(&w))
        {
            return out(ModelField::Widths, i);
        }
        let worst = self.worst_case_output_dph();
        if worst.is_nan() || worst > MAX_OUTPUT_DPH {
            return Err(ModelError::OutputUnbounded {
                worst_dph: if worst < u32::MAX as f64 {
                    worst as u32
                } else {
                    u32::MAX
                },
            });
        }
        Ok(())
    }

    /// Trained range of input 0 in normalised units (the polynomial's domain), f32 as the
    /// evaluator computes it.
    pub fn poly_domain(&self) -> (f32, f32) {
        let first = |v: &Vec<f32, MAX_INPUTS>| v.first().copied();
        match (
            first(&self.input_min),
            first(&self.input_max),
            first(&self.input_offset),
            first(&self.input_scale),
        ) {
            (Some(lo), Some(hi), Some(off), Some(scale)) => {
                let norm = |v: f32| ((v - off) / scale).clamp(-XN_CLAMP, XN_CLAMP);
                (norm(lo), norm(hi))
            }
            _ => (0.0, 0.0),
        }
    }

    /// Upper bound of |drift| over all inputs, deg/h (f64, from the stored f32 values).
    pub fn worst_case_output_dph(&self) -> f64 {
        let (lo, hi) = self.poly_domain();
        let t = libm::fmax(libm::fabs(lo as f64), libm::fabs(hi as f64));
        let abs = |v: &f32| libm::fabs(*v as f64);
        let linear: f64 = self.linear.iter().map(abs).sum::<f64>() * XN_CLAMP as f64
            + self.linear_by_t.iter().map(abs).sum::<f64>() * XN_CLAMP as f64 * t;
        let mut power = 1.0;
        let mut poly = 0.0;
        for p in &self.poly {
            power *= t;
            poly += abs(p) * power;
        }
        abs(&self.bias_dph) + linear + poly + self.weights.iter().map(abs).sum::<f64>()
    }

    /// Validate and encode into `buf`; returns the number of bytes written.
    ///
    /// Layout: postcard of `(magic: u32, version: u16, body: bytes, crc32: u32)` where body is
    /// postcard of `(n_inputs: u16, n_centers: u16, RbfModel)` and the CRC covers the body bytes.
    pub fn encode(&self, buf: &mut [u8]) -> Result<usize, ModelError> {
        self.validate()?;
        let too_small = ModelError::BufferTooSmall {
            needed_at_least: (buf.len() + 1).min(u16::MAX as usize) as u16,
        };
        if buf.len() <= HEADER_RESERVE + 5 {
            return Err(too_small);
        }
        let buf_len = buf.len();
        let limit = buf_len.min(MAX_ENCODED_LEN + HEADER_RESERVE);
        let counts = BodyCounts {
            n_inputs: self.inputs.len() as u16,
            n_centers: self.centers.len() as u16,
        };
        let body_area = &mut buf[HEADER_RESERVE..limit];
        let counts_len = postcard::to_slice(&counts, body_area)
            .map_err(|_| too_small)?
            .len();
        let model_len = postcard::to_slice(self, &mut body_area[counts_len..])
            .map_err(|_| {
                if limit < buf_len {
                    ModelError::TooLarge { len: limit as u32 }
                } else {
                    too_small
                }
            })?
            .len();
        let body_len = counts_len + model_len;
        let crc = crc32(&buf[HEADER_RESERVE..HEADER_RESERVE + body_len]);
        // Header = postcard(magic, version, body length varint); serialise it with an empty
        // body slice and drop the trailing zero length byte, then write the real length.
        let mut head = [0u8; HEADER_RESERVE + 8];
        let head_len = {
            let fixed = postcard::to_slice(&(MODEL_MAGIC, MODEL_VERSION), &mut head)
                .map_err(|_| ModelError::Malformed)?
                .len();
            let len_varint = postcard::to_slice(&(body_len as u32), &mut head[fixed..])
                .map_err(|_| ModelError::Malformed)?
                .len();
            fixed + len_varint
        };
        buf.copy_within(HEADER_RESERVE..HEADER_RESERVE + body_len, head_len);
        buf[..head_len].copy_from_slice(&head[..head_len]);
        let crc_at = head_len + body_len;
        let crc_len = postcard::to_slice(&crc, &mut buf[crc_at..])
            .map_err(|_| too_small)?
            .len();
        let total = crc_at + crc_len;
        if total > MAX_ENCODED_LEN {
            return Err(ModelError::TooLarge { len: total as u32 });
        }
        Ok(total)
    }
}
