//! The trainer's error type: every way a dataset, a configuration or a fit can be
//! rejected, each saying what was wrong and where, so `fogsim train` can print one line.

use std::fmt;

/// Why the trainer refused a dataset or configuration, or could not fit.
#[derive(Clone, Debug, PartialEq)]
pub enum TrainError {
    /// The dataset has no rows.
    EmptyDataset,
    /// A row or a spec list does not have the dataset's number of inputs.
    InputCount {
        expected: usize,
        found: usize,
        row: usize,
    },
    /// The dataset has more inputs than a model can hold.
    TooManyInputs { found: usize, max: usize },
    /// Rows, targets and group ids have different lengths.
    LengthMismatch {
        rows: usize,
        targets: usize,
        groups: usize,
    },
    /// A NaN or infinite input or target.
    NonFinite {
        what: &'static str,
        row: usize,
        input: usize,
    },
    /// An input has (numerically) no spread, so it cannot be normalised.
    ConstantInput { input: usize },
    /// Grouped validation needs more distinct groups (runs) than the data holds.
    TooFewGroups { found: usize, needed: usize },
    /// An option is out of its allowed range.
    BadConfig { option: &'static str, why: String },
    /// Computing model inputs from a run failed.
    Features { run: String, why: String },
    /// A run lacks a column the requested features need.
    MissingColumn { run: String, column: String },
    /// The assembled model was rejected by fog-core's validation.
    Model { why: String },
    /// fog-core's RBF evaluation rejected an input row.
    Predict { row: usize, why: String },
    /// The seek criterion's dwell is too long for the runs: no run holds one seek (two
    /// dwells), so there is nothing to score.
    NoSeekPairs { dwell_s: f64, longest_run_s: f64 },
    /// The training set would need working memory above the limit.
    TooLarge {
        rows: usize,
        bytes: usize,
        limit: usize,
    },
}

impl fmt::Display for TrainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::EmptyDataset => write!(
                f,
                "training data is empty (no usable 10 s points: a row is usable once its inputs are ready, e.g. dT/dt after 60 s of readings; for sparse or burst-sampled records use `fogsim diagnose`)"
            ),
            Self::InputCount {
                expected,
                found,
                row,
            } => {
                write!(f, "row {row} has {found} inputs, expected {expected}")
            }
            Self::TooManyInputs { found, max } => {
                write!(
                    f,
                    "{found} model inputs requested, a model holds at most {max}"
                )
            }
            Self::LengthMismatch {
                rows,
                targets,
                groups,
            } => write!(
                f,
                "dataset lengths differ: {rows} input rows, {targets} targets, {groups} group ids"
            ),
            Self::NonFinite { what, row, input } => {
                write!(f, "{what} is not finite at row {row} (input {input})")
            }
            Self::ConstantInput { input } => write!(
                f,
                "model input {input} is constant over the training data, it cannot be normalised"
            ),
            Self::TooFewGroups { found, needed } => write!(
                f,
                "grouped validation needs at least {needed} runs, the data holds {found}"
            ),
            Self::BadConfig { option, why } => write!(f, "--{option}: {why}"),
            Self::Features { run, why } => write!(f, "{run}: computing model inputs: {why}"),
            Self::MissingColumn { run, column } => {
                write!(
                    f,
                    "{run}: column `{column}` needed by a model input is missing"
                )
            }
            Self::Model { why } => write!(f, "trained model rejected by fog-core: {why}"),
            Self::Predict { row, why } => write!(f, "RBF evaluation failed at row {row}: {why}"),
            Self::NoSeekPairs {
                dwell_s,
                longest_run_s,
            } => write!(
                f,
                "seek criterion: a seek of two {dwell_s} s positions fits in no run (the longest \
                 is {longest_run_s:.0} s), so no model can be scored by it: give a shorter \
                 seek dwell or the 10 s rms criterion (rms10s)"
            ),
            Self::TooLarge { rows, bytes, limit } => write!(
                f,
                "{rows} training points need {} MiB of working memory (Gram matrices and \
                 per-row arrays), above the {} MiB limit: train on fewer runs, lower \
                 --max-candidates or average to 10 s rows first",
                bytes >> 20,
                limit >> 20
            ),
        }
    }
}

impl std::error::Error for TrainError {}

/// The trainer's result type.
pub type Result<T> = std::result::Result<T, TrainError>;
