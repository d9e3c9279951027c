//! Errors of the quasi-steady baseline.

use std::path::PathBuf;

/// Everything that can go wrong fitting, saving, loading or applying an LRQSM.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum QsError {
    /// An option is out of range.
    #[error("option '{name}' = {value}: {reason}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// The value given, as text.
        value: String,
        /// What is allowed.
        reason: String,
    },
    /// Array sizes do not agree.
    #[error("{what}: {found} values, expected {expected}")]
    Shape {
        /// Which array.
        what: String,
        /// Number found.
        found: usize,
        /// Number expected.
        expected: usize,
    },
    /// A feature or target value is NaN or infinite.
    #[error("{kind} '{name}' has a non-finite value {value} at row {row}")]
    NonFinite {
        /// `feature` or `target`.
        kind: &'static str,
        /// Column name.
        name: String,
        /// Row index (0-based, data rows).
        row: usize,
        /// The value.
        value: f64,
    },
    /// A feature column has no spread, so it cannot be standardized (or is all zero).
    #[error("feature '{name}' is constant{where_} (value {value}); remove it")]
    ConstantFeature {
        /// Column name.
        name: String,
        /// A value of the column.
        value: f64,
        /// Where: empty for all rows, else " in the training rows of fold k".
        where_: String,
    },
    /// The target is constant or orthogonal to every feature: λ_max = 0.
    #[error("target '{name}' is constant or uncorrelated with every feature (lambda_max = 0)")]
    DegenerateTarget {
        /// Target name.
        name: String,
    },
    /// Fewer rows than folds.
    #[error(
        "{rows} rows cannot be split into {folds} cross-validation folds (need at least 2 rows per fold)"
    )]
    TooFewRows {
        /// Rows available.
        rows: usize,
        /// Folds asked for.
        folds: usize,
    },
    /// A column name is not in the table.
    #[error("{file}: unknown {kind} column '{name}'; available columns: {available}")]
    UnknownColumn {
        /// File (or data source) searched.
        file: String,
        /// `target` or `feature`.
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// Available column names, comma separated.
        available: String,
    },
    /// A CSV field is not a finite number.
    #[error("{path}: line {line}: column '{column}' holds '{text}', not a finite number")]
    CsvValue {
        /// File.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Column name.
        column: String,
        /// The field text.
        text: String,
    },
    /// Reading a table failed.
    #[error(transparent)]
    Table(#[from] flapssm_data::table::TableError),
    /// File I/O failed.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A model file is not valid JSON or lacks fields.
    #[error("{path}: not a valid LRQSM model file: {message}")]
    ModelFormat {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A model file has a format version this build cannot read.
    #[error(
        "{path}: model format version {found} is not supported (this build reads version {supported})"
    )]
    ModelVersion {
        /// File.
        path: PathBuf,
        /// Version in the file.
        found: u64,
        /// Version supported.
        supported: u32,
    },
    /// The dataset is invalid or lacks what the fit needs (outputs, training data).
    #[error(transparent)]
    Dataset(#[from] flapssm_wing::dataset::DatasetError),
    /// The data do not fit the model (wrong features, no outputs, …).
    #[error("{0}")]
    Mismatch(String),
}
