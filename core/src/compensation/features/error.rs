//! Why a model input could not be computed: the one error of the feature code, and the
//! check of a span or time constant that every estimator shares.

use crate::model::format::MAX_INPUTS;

/// Why a feature could not be computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeatureError {
    /// A NaN or infinite temperature, aux value or time.
    NonFinite { row: u32 },
    /// Time did not increase from one row to the next.
    TimeNotIncreasing { row: u32 },
    /// A feature needs aux channel `channel`, which was not supplied.
    MissingAux { channel: u8 },
    /// Input series (or output slice) of different lengths.
    LengthMismatch { expected: u32, found: u32 },
    /// More feature specs than `MAX_INPUTS`.
    TooManyFeatures,
    /// A span or time constant that is not a positive finite number.
    BadTimeConstant,
}

impl core::fmt::Display for FeatureError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            FeatureError::NonFinite { row } => {
                write!(f, "features: row {row} has a NaN or infinite value")
            }
            FeatureError::TimeNotIncreasing { row } => {
                write!(f, "features: time at row {row} does not increase")
            }
            FeatureError::MissingAux { channel } => {
                write!(
                    f,
                    "features: aux channel {channel} is needed but not supplied"
                )
            }
            FeatureError::LengthMismatch { expected, found } => {
                write!(f, "features: series of length {found}, expected {expected}")
            }
            FeatureError::TooManyFeatures => {
                write!(f, "features: more than {MAX_INPUTS} features requested")
            }
            FeatureError::BadTimeConstant => {
                write!(
                    f,
                    "features: span / time constant must be positive and finite"
                )
            }
        }
    }
}

impl core::error::Error for FeatureError {}

/// `BadTimeConstant` unless `s` (a span or time constant, s) is positive and finite.
pub(super) fn positive_time_constant(s: f64) -> Result<(), FeatureError> {
    if s.is_finite() && s > 0.0 {
        Ok(())
    } else {
        Err(FeatureError::BadTimeConstant)
    }
}
