//! Errors of the analysis crate.

use std::path::PathBuf;

/// Everything that can go wrong in an analysis, a figure or the report.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// An array does not have the expected length or shape.
    #[error("{what}: expected {expected}, found {found}")]
    Shape {
        /// Which array.
        what: String,
        /// Expected shape, in words.
        expected: String,
        /// Actual shape, in words.
        found: String,
    },
    /// An input that must not be empty is empty.
    #[error("{what} is empty")]
    Empty {
        /// Which input.
        what: String,
    },
    /// A value is NaN or infinite.
    #[error("{what}: non-finite value at index {index}")]
    NonFinite {
        /// Which input.
        what: String,
        /// Flat index of the first offending value.
        index: usize,
    },
    /// A parameter is out of its valid range.
    #[error("parameter `{name}` = {value}: {reason}")]
    Parameter {
        /// Parameter name.
        name: String,
        /// Offending value, formatted.
        value: String,
        /// Valid range, in words.
        reason: String,
    },
    /// A series has zero variance, so its correlation is undefined.
    #[error("{what} is constant (zero standard deviation): correlation undefined")]
    ConstantSeries {
        /// Which series.
        what: String,
    },
    /// A stroke-cycle window does not fit in the series.
    #[error("cycle window start {start} + duration {duration} does not fit in {n_samples} samples")]
    Window {
        /// First sample (0-based).
        start: usize,
        /// Duration in samples (the window holds `duration + 1` samples).
        duration: usize,
        /// Samples available.
        n_samples: usize,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Drawing a figure failed.
    #[error("figure {path}: {message}")]
    Plot {
        /// The figure file.
        path: PathBuf,
        /// What the plotting backend reported.
        message: String,
    },
    /// JSON serialization failed.
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, AnalysisError>;

/// Checks that every value is finite.
pub(crate) fn check_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(AnalysisError::NonFinite {
            what: what.to_string(),
            index,
        }),
        None => Ok(()),
    }
}

/// Builds a [`AnalysisError::Parameter`].
pub(crate) fn param(name: &str, value: impl std::fmt::Display, reason: &str) -> AnalysisError {
    AnalysisError::Parameter {
        name: name.to_string(),
        value: value.to_string(),
        reason: reason.to_string(),
    }
}
