//! The simulator's error type: an impossible parameter or run specification,
//! named with its value and the reason.

use std::fmt;

/// Why a simulation could not be set up.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// A gyro, table or run parameter is out of its physical range.
    BadParameter {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    /// An auxiliary series has mismatched lengths, too few points or a bad time axis.
    BadSeries { term: String, why: &'static str },
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::BadParameter { name, value, why } => {
                write!(f, "simulator parameter `{name}` = {value}: {why}")
            }
            SimError::BadSeries { term, why } => {
                write!(f, "drift term `{term}`: auxiliary series {why}")
            }
        }
    }
}

impl std::error::Error for SimError {}
