//! Why `diagnose` refuses a campaign: small, typed errors with the run and column named.

use std::fmt;

/// A campaign `diagnose` cannot analyse (nothing is reported for it).
#[derive(Clone, Debug, PartialEq)]
pub enum DiagnoseError {
    /// No runs were given.
    NoRuns,
    /// Too few runs/points to validate on held-out data.
    TooFewRuns {
        runs: usize,
        points: usize,
        why: &'static str,
    },
    /// A column's length differs from the run's `t_s` length.
    MismatchedLength {
        run: String,
        column: String,
        expected: usize,
        found: usize,
    },
    /// A required column is missing.
    MissingColumn { run: String, column: String },
    /// A required column holds NaN or infinity.
    NotFinite {
        run: String,
        column: String,
        row: usize,
    },
    /// `t_s` is not strictly increasing.
    TimeNotIncreasing { run: String, row: usize },
    /// A required signal is constant over the whole campaign (nothing to learn from).
    ConstantRequired { column: String },
    /// A least-squares system could not be solved (degenerate data).
    Singular { what: &'static str },
}

impl fmt::Display for DiagnoseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoRuns => write!(f, "no runs given"),
            Self::TooFewRuns { runs, points, why } => {
                write!(f, "too few data to validate on held-out data ({runs} runs, {points} points): {why}")
            }
            Self::MismatchedLength { run, column, expected, found } => write!(
                f,
                "run {run}: column `{column}` has {found} values but `t_s` has {expected} (mismatched lengths)"
            ),
            Self::MissingColumn { run, column } => write!(f, "run {run}: required column `{column}` is missing"),
            Self::NotFinite { run, column, row } => {
                write!(f, "run {run}: column `{column}` row {row} is NaN or infinite")
            }
            Self::TimeNotIncreasing { run, row } => write!(f, "run {run}: `t_s` is not strictly increasing at row {row}"),
            Self::ConstantRequired { column } => {
                write!(f, "column `{column}` is constant over the whole campaign: nothing to model")
            }
            Self::Singular { what } => write!(f, "least-squares system for {what} is singular (degenerate data)"),
        }
    }
}

impl std::error::Error for DiagnoseError {}
