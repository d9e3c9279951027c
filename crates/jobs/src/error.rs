//! Errors of the jobs; each names the file, trajectory or stage at fault.

use std::path::PathBuf;

use flapssm_analysis::error::AnalysisError;
use flapssm_prssm::train::fit::FitError;
use flapssm_qs::QsError;
use flapssm_wing::cycles::CycleError;

/// Errors of the pipeline, the sweeps and the demo; each names the file, trajectory or stage.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JobError {
    /// The dataset is invalid or unsuitable.
    #[error("dataset: {0}")]
    Dataset(#[from] flapssm_wing::dataset::DatasetError),
    /// A dataset file could not be read or written.
    #[error("dataset file {path}: {source}")]
    DatasetFile {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: flapssm_wing::dataset::StoreError,
    },
    /// A PR-SSM model file could not be read or written.
    #[error("PR-SSM model file {path}: {source}")]
    ModelFile {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: flapssm_prssm::ModelFileError,
    },
    /// The published model's parameter file could not be imported.
    #[error("published model {path}: {source}")]
    PublishedModel {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: flapssm_prssm::published::ImportError,
    },
    /// Trajectories could not be generated or read.
    #[error("trajectories: {0}")]
    Trajectories(#[from] flapssm_wing::trajectories::TrajectoryError),
    /// The LRQSM failed (fit, prediction or model file).
    #[error("LRQSM: {0}")]
    Qs(#[from] QsError),
    /// The ARX baseline failed (settings, fit or prediction).
    #[error(transparent)]
    Arx(#[from] flapssm_qs::arx::ArxError),
    /// The GP baselines' regression failed (shapes, settings, normal equations).
    #[error("GP baseline: {0}")]
    Regression(#[from] flapssm_prssm::regression::RegressionError),
    /// PR-SSM training or prediction failed.
    #[error("PR-SSM {what}: {source}")]
    Prssm {
        /// What was being done (e.g. "prediction of trajectory 3").
        what: String,
        /// Cause.
        source: FitError,
    },
    /// A design's target or settings were refused (naming the field), or its model failed.
    #[error("design: {0}")]
    Design(#[from] flapssm_design::DesignError),
    /// The simulator failed.
    #[error("simulation: {0}")]
    Simulate(#[from] flapssm_wing::virtual_wing::SimulateError),
    /// No stroke cycle could be found in a trajectory.
    #[error("trajectory {trajectory}: stroke cycle: {source}")]
    Cycle {
        /// Trajectory index (0-based).
        trajectory: usize,
        /// Cause.
        source: CycleError,
    },
    /// An analysis, figure or report failed.
    #[error("{what}: {source}")]
    Analysis {
        /// Which analysis or file.
        what: String,
        /// Cause.
        source: AnalysisError,
    },
    /// A setting is out of its range; checked once, before any work.
    #[error("setting {name} = {value}: {expected}")]
    Setting {
        /// The setting's name as the user gives it (`dx`, `val_fraction`, …).
        name: String,
        /// The value given.
        value: String,
        /// What it must be, and why.
        expected: String,
    },
    /// Shapes or settings do not fit together.
    #[error("{what}: expected {expected}, found {found}")]
    Mismatch {
        /// Which item.
        what: String,
        /// Expected, in words.
        expected: String,
        /// Found, in words.
        found: String,
    },
    /// A rig description is at fault (names the file and the field).
    #[error("{path}: {source}")]
    Rig {
        /// The rig description.
        path: PathBuf,
        /// Cause.
        source: flapssm_wing::rig::RigError,
    },
    /// A recording cannot be processed (names the file, and the column, row or field).
    #[error(transparent)]
    Recording(flapssm_wing::rig::RigError),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// A table (CSV, ASCII, MAT) could not be read; names the file, line and column.
    #[error(transparent)]
    Table(#[from] flapssm_data::table::TableError),
    /// An output path that cannot or must not be written (refused before any work).
    #[error("output {0}")]
    Output(std::io::Error),
    /// A line of a text input is malformed (line 0: the input as a whole).
    #[error("{path} line {line}: {message}")]
    Parse {
        /// The input.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A JSON file could not be parsed or written.
    #[error("{path}: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// Cause (with line and column when parsing).
        source: serde_json::Error,
    },
    /// Stopped on request; the training checkpoint allows resuming.
    #[error("interrupted at step {step}{}", resume_note(checkpoint.as_deref()))]
    Interrupted {
        /// Optimizer steps done.
        step: u64,
        /// Checkpoint file, for a run that writes one.
        checkpoint: Option<PathBuf>,
    },
}

fn resume_note(checkpoint: Option<&std::path::Path>) -> String {
    match checkpoint {
        Some(c) => format!("; checkpoint {} written to resume from", c.display()),
        None => "; nothing was written".into(),
    }
}

/// Result alias of the pipeline.
pub type Result<T> = std::result::Result<T, JobError>;

pub(crate) fn analysis(what: impl Into<String>) -> impl FnOnce(AnalysisError) -> JobError {
    let what = what.into();
    move |source| JobError::Analysis { what, source }
}
