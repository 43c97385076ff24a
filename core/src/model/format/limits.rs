//! The model format's numbers: sizes, version, magic and the magnitude bounds validation
//! holds every parameter to, with the `ModelError` messages that quote them.

use crate::model::error::ModelError;

/// Most RBF centres a model may hold.
pub const MAX_CENTERS: usize = 64;
/// Most model inputs (format version 6; 4 before).
pub const MAX_INPUTS: usize = 6;
/// Most inputs that enter the Gaussians' distance (`n_rbf_inputs`): the width of a stored
/// centre, 4 in every format version, so that the inputs after them (linear-only: a
/// warm-up law's clocks) cost no centre storage.
pub const MAX_RBF_INPUTS: usize = 4;
/// Magic at the start of every encoded model: "FOGM".
pub const MODEL_MAGIC: u32 = 0x4D47_4F46;
/// Newest format version read (7: the wire layout of version 5 with the diffusion-clock
/// rate `FeatureKind::TempRateDiffusionCps`; 6: up to `MAX_INPUTS` = 6 inputs and the
/// warm-up clock's stretch `FeatureKind::PowerOnDecayStretch`, the same layout). A model is
/// written as the oldest version that holds it (`RbfModel::format_version`).
pub const MODEL_VERSION: u16 = 7;
/// The version a model without a version-7 input kind is written as: its bytes are those
/// of every earlier release.
pub const MODEL_VERSION_BASE: u16 = 6;
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
/// Largest encoded model, bytes (a 64-centre, 6-input model must fit).
pub const MAX_ENCODED_LEN: usize = 2048;

/// Most auxiliary (extra sensor) channels a model may refer to.
pub const MAX_AUX: usize = 4;

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
                "model: n_rbf_inputs = {n_rbf_inputs} is invalid for {n_inputs} inputs (at most {MAX_RBF_INPUTS} enter the Gaussians)"
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
