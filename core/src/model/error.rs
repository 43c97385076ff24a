//! Why a model could not be encoded, decoded or accepted (`ModelError`), and which of its
//! fields a validation error names (`ModelField`).
//!
//! Exists as its own file so that every model file that reports an error takes it from
//! below: the cold-start envelope (`cold_start`) validates itself with it, the format
//! (`format`) validates and encodes with it, and the decoder (`in_place`) decodes with it,
//! without importing each other in a circle. The messages (`Display`) stay in `format`,
//! beside the limits (`MAX_ENCODED_LEN`, `MODEL_VERSION`, ...) they quote.

/// Which part of a model a validation error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelField {
    Inputs,
    InputOffset,
    InputScale,
    InputMin,
    InputMax,
    Linear,
    Centers,
    Widths,
    Weights,
    Bias,
    HeldoutRms,
    TimeConstant,
    Poly,
    /// The heading harmonic; index 0 a, 1 b, 2 sigma a, 3 sigma b, 4 correlation,
    /// 5 n_headings.
    Heading,
    /// The temperature-coupled linear terms.
    LinearByT,
    /// The cold-start envelope; index the point.
    ColdStart,
}

impl ModelField {
    /// Field name as written in `RbfModel`.
    pub const fn name(self) -> &'static str {
        match self {
            ModelField::Inputs => "inputs",
            ModelField::InputOffset => "input_offset",
            ModelField::InputScale => "input_scale",
            ModelField::InputMin => "input_min",
            ModelField::InputMax => "input_max",
            ModelField::Linear => "linear",
            ModelField::Centers => "centers",
            ModelField::Widths => "widths",
            ModelField::Weights => "weights",
            ModelField::Bias => "bias_dph",
            ModelField::HeldoutRms => "meta.heldout_rms_dph",
            ModelField::TimeConstant => "inputs[].tau_s",
            ModelField::Poly => "poly",
            ModelField::Heading => "heading",
            ModelField::LinearByT => "linear_by_t",
            ModelField::ColdStart => "cold_start",
        }
    }
}

/// Why a model could not be encoded, decoded or accepted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelError {
    /// The output buffer cannot hold the encoded model.
    BufferTooSmall { needed_at_least: u16 },
    /// The encoded model is larger than `MAX_ENCODED_LEN`.
    TooLarge { len: u32 },
    /// The bytes end before the model does.
    Truncated,
    /// The first field is not `MODEL_MAGIC`.
    BadMagic { found: u32 },
    /// A format version this code does not understand.
    UnsupportedVersion { found: u16 },
    /// CRC-32 of the body does not match the stored one.
    CrcMismatch { stored: u32, computed: u32 },
    /// Bytes left over after the CRC.
    TrailingBytes { count: u16 },
    /// The body is not a well-formed postcard `RbfModel`.
    Malformed,
    /// Zero inputs.
    NoInputs,
    /// More inputs than `MAX_INPUTS`.
    TooManyInputs { count: u16 },
    /// More centres than `MAX_CENTERS`.
    TooManyCenters { count: u16 },
    /// `n_rbf_inputs` is larger than the number of inputs, or 0 with centres present.
    BadRbfInputCount { n_rbf_inputs: u8, n_inputs: u8 },
    /// A per-input or per-centre vector has the wrong length.
    LengthMismatch {
        field: ModelField,
        expected: u16,
        found: u16,
    },
    /// A NaN or infinite number.
    NonFinite { field: ModelField, index: u16 },
    /// An input scale that is not > 0.
    NonPositiveScale { input: u8 },
    /// A Gaussian width that is not > 0.
    NonPositiveWidth { center: u16 },
    /// Trained range with min > max.
    BadRange { input: u8 },
    /// A lag/decay input without a positive time constant, or a negative one elsewhere.
    BadTimeConstant { input: u8 },
    /// An auxiliary channel index >= `MAX_AUX`.
    BadAuxChannel { input: u8, channel: u8 },
    /// A parameter outside its allowed magnitude (see the bound constants).
    OutOfBounds { field: ModelField, index: u16 },
    /// The worst case of |bias| + sum |linear| XN_CLAMP + sum |poly_k| t^k + sum |w|
    /// exceeds `MAX_OUTPUT_DPH` (value in deg/h, saturated to u32).
    OutputUnbounded { worst_dph: u32 },
}

/// `values` all finite, or `NonFinite` naming the first that is not.
pub(crate) fn check_finite(field: ModelField, values: &[f32]) -> Result<(), ModelError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(ModelError::NonFinite {
            field,
            index: i as u16,
        }),
        None => Ok(()),
    }
}

/// `found == expected`, or `LengthMismatch`.
pub(crate) fn check_len(
    field: ModelField,
    expected: usize,
    found: usize,
) -> Result<(), ModelError> {
    if expected == found {
        Ok(())
    } else {
        Err(ModelError::LengthMismatch {
            field,
            expected: expected as u16,
            found: found as u16,
        })
    }
}
