//! The evaluation pipeline: both models on a dataset → accuracy metrics, cycle averages,
//! control authority of the PR-SSM latent states, figures and the HTML report.
//!
//! Per trajectory `i` (n samples):
//! - PR-SSM: open-loop prediction from the model's initial-state rule
//!   ([`flapssm_prssm::train::fit::predict_raw`], `particles` particles, seed
//!   `derive_seed(seed, 7, i)`): output mean/variance in N and N·mm, latent means (standardized
//!   latent units, `n × D_x`).
//! - LRQSM: [`flapssm_qs::lrqsm::predict_dataset`] with the fitted intercept.
//! - Standardized errors `e = (y − ŷ)/σ_y` with the dataset's training statistics
//!   ([`Dataset::standardization`]), pooled from `start_sample` on (published: the first 93
//!   samples dropped): per-output RMSE, overall `√mean(e²)`, 2.5/97.5 % intervals.
//! - Coefficients `C_F = F/(½ρSU_ref²)`, `C_M = M/(½ρc̄SU_ref²·1000)` per trajectory; the last
//!   full cycle from [`flapssm_wing::cycles::published_window`]; per-trajectory C_Fx/C_Fy RMSE
//!   over it; half-stroke averages and their errors (measured − predicted) with intervals.
//! - Control authority: [`flapssm_analysis::authority`] on (inputs, PR-SSM latent means) from
//!   `start_sample` on, every trajectory (training and test), period = the cycle duration.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use flapssm_data::{Dataset, OUTPUT_NAMES, Trajectory};
use flapssm_prssm::train::fit::{
    FitError, FitOutcome, FitSpec, Preset, fit, predict_raw, training_record,
};
use flapssm_prssm::train::{Budget, Checkpoint, LrSchedule, TrainEvent, TrainHooks, derive_seed};
use flapssm_prssm::{PrssmModel, Sequence};
use flapssm_qs::{InterceptMode, LrqsmModel, QsError};
use flapssm_wing::cycles::{CycleError, published_window};
use serde::{Deserialize, Serialize};

use flapssm_analysis::authority::{
    AuthorityConfig, AuthoritySummary, AuthorityTrajectory, peak_table,
};
use flapssm_analysis::cycles_avg::{CycleAverageErrors, CycleWindow};
use flapssm_analysis::error::AnalysisError;
use flapssm_analysis::metrics::{
    CoefficientScales, Histogram, PUBLISHED_START_SAMPLE, PooledErrors,
};
use flapssm_analysis::metrics::{coefficients_of, window_rmse};
use flapssm_analysis::plots::{authority as pa, errors as pe, timeseries as pt, training, wing3d};
use flapssm_analysis::report::{Figure, Report, Section, Table};
use flapssm_analysis::stats::{Interval, Rows, median};

/// Display names of the 7 inputs (dataset order).
pub const INPUT_LABELS: [&str; 7] = ["AoA", "|v|", "a_x", "a_y", "a_z", "dα/dt", "d²α/dt²"];
/// Display names of the 5 outputs as coefficients.
pub const COEFFICIENT_LABELS: [&str; 5] = ["C_Fx", "C_Fy", "C_Mx", "C_My", "C_Mz"];

/// Errors of the pipeline, the sweeps and the demo; each names the file, trajectory or stage.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// The dataset is invalid or unsuitable.
    #[error("dataset: {0}")]
    Dataset(#[from] flapssm_data::DatasetError),
    /// A dataset file could not be read or written.
    #[error("dataset file {path}: {source}")]
    DatasetFile {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: flapssm_data::StoreError,
    },
    /// A PR-SSM model file could not be read or written.
    #[error("PR-SSM model file {path}: {source}")]
    ModelFile {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: flapssm_prssm::ModelFileError,
    },
    /// The LRQSM failed (fit, prediction or model file).
    #[error("LRQSM: {0}")]
    Qs(#[from] QsError),
    /// PR-SSM training or prediction failed.
    #[error("PR-SSM {what}: {source}")]
    Prssm {
        /// What was being done (e.g. "prediction of trajectory 3").
        what: String,
        /// Cause.
        source: FitError,
    },
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
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
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
    #[error("interrupted at step {step}; rerun the same command to resume from {checkpoint}")]
    Interrupted {
        /// Optimizer steps done.
        step: u64,
        /// Checkpoint file.
        checkpoint: PathBuf,
    },
}

/// Result alias of the pipeline.
pub type Result<T> = std::result::Result<T, PipelineError>;

fn analysis(what: impl Into<String>) -> impl FnOnce(AnalysisError) -> PipelineError {
    let what = what.into();
    move |source| PipelineError::Analysis { what, source }
}

/// Progress of long stages (implemented by the CLI with progress bars). All methods default to
/// doing nothing; `advance` may be called from several threads.
pub trait Progress: Sync {
    /// A stage with `total` units of work starts (`total` 0: unknown).
    fn start(&self, _stage: &str, _total: u64) {}
    /// `n` units of the current stage are done.
    fn advance(&self, _n: u64) {}
    /// The current stage's position is `pos` of `total` units.
    fn set(&self, _pos: u64, _total: u64) {}
    /// A status line for the current stage.
    fn message(&self, _msg: &str) {}
    /// A line to print above the progress bars.
    fn println(&self, _line: &str) {}
    /// The current stage is done; `note` says how (e.g. "skipped: up to date").
    fn finish(&self, _note: &str) {}
}

/// A [`Progress`] that reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;
impl Progress for NoProgress {}

/// Settings of [`evaluate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalOptions {
    /// Particles of the PR-SSM predictions (published 30).
    pub particles: usize,
    /// Seed of the PR-SSM prediction draws.
    pub seed: u64,
    /// First analysed sample, 0-based ([`PUBLISHED_START_SAMPLE`] = 93).
    pub start_sample: usize,
    /// Level of the central intervals, % (95).
    pub level: f64,
    /// Control-authority analysis settings.
    pub authority: AuthorityConfig,
    /// Test trajectories shown in Figs. 2C and 3 (at most).
    pub example_trajectories: usize,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            particles: 30,
            seed: 0,
            start_sample: PUBLISHED_START_SAMPLE,
            level: 95.0,
            authority: AuthorityConfig::default(),
            example_trajectories: 6,
        }
    }
}

/// PR-SSM open-loop prediction of one trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct PrssmPrediction {
    /// Output means (N, N·mm), row-major `n × 5`.
    pub mean: Vec<f64>,
    /// Output variances (N², (N·mm)²), `n × 5`.
    pub var: Vec<f64>,
    /// Latent means (standardized latent units), `n × D_x`.
    pub latent_mean: Vec<f64>,
}

/// The raw PR-SSM sequence of a trajectory (7 inputs, 5 outputs, row-major; outputs empty for
/// kinematics-only trajectories).
pub fn trajectory_sequence(t: &Trajectory) -> Sequence {
    Sequence {
        inputs: t.inputs.as_flattened().to_vec(),
        outputs: t
            .outputs
            .as_ref()
            .map(|y| y.as_flattened().to_vec())
            .unwrap_or_default(),
    }
}

fn check_model_shape(model: &PrssmModel) -> Result<()> {
    let c = &model.config;
    if c.n_input != 7 || c.n_output != 5 {
        return Err(PipelineError::Mismatch {
            what: "PR-SSM model inputs/outputs".into(),
            expected: "7 inputs and 5 outputs (the dataset's)".into(),
            found: format!("{} inputs, {} outputs", c.n_input, c.n_output),
        });
    }
    Ok(())
}

/// The model as it applies to `ds`'s physical units: unchanged when it carries normalization
/// statistics; otherwise (a model trained in standardized units, e.g. the published one) a copy
/// that standardizes with `ds`'s training statistics, as the published post-processing did.
///
/// # Errors
/// [`PipelineError::Dataset`] when the model has no statistics and `ds` has no outputs to
/// compute them from.
pub fn in_dataset_units<'m>(
    model: &'m PrssmModel,
    ds: &Dataset,
) -> Result<std::borrow::Cow<'m, PrssmModel>> {
    if model.normalization.is_some() {
        return Ok(std::borrow::Cow::Borrowed(model));
    }
    let s = ds.standardization()?;
    let mut m = model.clone();
    m.normalization = Some(flapssm_prssm::Normalization {
        input_mean: s.mean_u.to_vec(),
        input_std: s.std_u.to_vec(),
        output_mean: s.mean_y.to_vec(),
        output_std: s.std_y.to_vec(),
    });
    Ok(std::borrow::Cow::Owned(m))
}

/// Predicts every trajectory of `ds` with the PR-SSM (in parallel with feature `parallel`;
/// results do not depend on threading). `progress.advance(1)` per trajectory.
///
/// # Errors
/// [`PipelineError::Mismatch`] for a model that is not 7 → 5, [`PipelineError::Prssm`] naming
/// the trajectory.
pub fn predict_prssm(
    model: &PrssmModel,
    ds: &Dataset,
    particles: usize,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<PrssmPrediction>> {
    check_model_shape(model)?;
    let model = &*in_dataset_units(model, ds)?;
    let one = |(i, t): (usize, &Trajectory)| -> Result<PrssmPrediction> {
        let p = predict_raw(
            model,
            &trajectory_sequence(t),
            particles,
            derive_seed(seed, 7, i as u64),
        )
        .map_err(|source| PipelineError::Prssm {
            what: format!("prediction of trajectory {i}"),
            source,
        })?;
        progress.advance(1);
        Ok(PrssmPrediction {
            mean: p.output_mean,
            var: p.output_var,
            latent_mean: p.latent_mean,
        })
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        ds.trajectories.par_iter().enumerate().map(one).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        ds.trajectories.iter().enumerate().map(one).collect()
    }
}

/// LRQSM predictions (N, N·mm) of every trajectory, one `n × 5` table each.
///
/// # Errors
/// [`PipelineError::Qs`] for a model that does not fit the dataset.
pub fn predict_lrqsm(model: &LrqsmModel, ds: &Dataset) -> Result<Vec<Vec<f64>>> {
    let p = flapssm_qs::lrqsm::predict_dataset(model, ds, InterceptMode::Fitted)?;
    let per = p.n_samples * 5;
    Ok(p.raw.chunks_exact(per).map(<[f64]>::to_vec).collect())
}

/// Accuracy of one model on one set of trajectories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SplitMetrics {
    /// Trajectories.
    pub n_trajectories: usize,
    /// Samples per output pooled (from `start_sample` on).
    pub n_samples: usize,
    /// RMSE per output of standardized errors [F_x, F_y, M_x, M_y, M_z] (σ units).
    pub rmse_standardized: Vec<f64>,
    /// `√mean(e²)` over all outputs and samples (σ units).
    pub overall_rmse_standardized: f64,
    /// Central interval of the standardized errors per output (σ units).
    pub error_interval: Vec<Interval>,
    /// Median over trajectories of the last-cycle RMSE of C_Fx and of C_Fy.
    pub median_cycle_rmse_cf: [f64; 2],
    /// Central interval of the half-stroke-average errors per coefficient (C_F, C_M).
    pub cycle_average_error_interval: Vec<Interval>,
}

/// Accuracy of one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelMetrics {
    /// "PR-SSM" or "LRQSM".
    pub model: String,
    /// Training trajectories.
    pub train: SplitMetrics,
    /// Test trajectories (none when the dataset has no test part).
    pub test: Option<SplitMetrics>,
    /// Half-stroke-average error intervals over training and test together (as the paper).
    pub cycle_average_error_interval_all: Vec<Interval>,
}

/// Per-trajectory results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryMetrics {
    /// Index in the dataset.
    pub index: usize,
    /// "train" or "test".
    pub split: String,
    /// Family label.
    pub family: String,
    /// U_ref (m/s).
    pub u_ref_m_s: f64,
    /// Stroke period (samples).
    pub period_samples: usize,
    /// First sample of the last-cycle window (0-based).
    pub window_start: usize,
    /// PR-SSM last-cycle RMSE of [C_Fx, C_Fy].
    pub prssm_cycle_rmse_cf: [f64; 2],
    /// LRQSM last-cycle RMSE of [C_Fx, C_Fy].
    pub lrqsm_cycle_rmse_cf: [f64; 2],
    /// PR-SSM overall standardized RMSE from `start_sample` on.
    pub prssm_overall_rmse: f64,
    /// LRQSM overall standardized RMSE from `start_sample` on.
    pub lrqsm_overall_rmse: f64,
}

/// The influence of one input on one latent state (a row of Fig. 5B).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuthorityFinding {
    /// Input name.
    pub input: String,
    /// State name.
    pub state: String,
    /// Median over trajectories of max |r|.
    pub median_abs_r: f64,
    /// Median lag (stroke cycles).
    pub median_lag_cycles: f64,
    /// Interquartile range of the lag (cycles).
    pub lag_iqr_cycles: f64,
    /// Lag of the KDE mode (cycles).
    pub mode_lag_cycles: f64,
    /// Median |r| above the strong threshold (0.5).
    pub strong: bool,
}

/// Everything [`evaluate`] computes (written as `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvaluationReport {
    /// Dataset description (file name or origin).
    pub dataset: String,
    /// Training trajectories.
    pub n_train: usize,
    /// Test trajectories.
    pub n_test: usize,
    /// Settings.
    pub options: EvalOptions,
    /// PR-SSM accuracy.
    pub prssm: ModelMetrics,
    /// LRQSM accuracy.
    pub lrqsm: ModelMetrics,
    /// Test RMSE ratio PR-SSM / LRQSM per output (training set when there is no test set).
    pub rmse_ratio: Vec<f64>,
    /// Per-trajectory results.
    pub trajectories: Vec<TrajectoryMetrics>,
    /// Influence of AoA and a_x on the output states x1..x5 (paper: AoA near zero lag, a_x
    /// about 0.2 cycle).
    pub authority_findings: Vec<AuthorityFinding>,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
}

/// Text and settings the caller adds to the HTML report.
#[derive(Debug, Clone, Default)]
pub struct ReportContext {
    /// Page title.
    pub title: String,
    /// Introductory paragraph.
    pub intro: String,
    /// Extra headline rows (e.g. timings).
    pub headline: Vec<(String, String)>,
    /// Configuration shown in the report.
    pub config: serde_json::Value,
}

/// Picks a model's (standardized, coefficient) tables from a [`Prepared`].
type Pick<'p> = &'p dyn Fn(&Prepared) -> (&[f64], &[f64]);

/// One trajectory's tables for the analyses.
struct Prepared {
    window: CycleWindow,
    measured_z: Vec<f64>,
    measured_c: Vec<f64>,
    prssm_z: Vec<f64>,
    prssm_c: Vec<f64>,
    prssm_std_c: Vec<f64>,
    lrqsm_z: Vec<f64>,
    lrqsm_c: Vec<f64>,
}

fn rows<'a>(v: &'a [f64], c: usize, what: &str) -> Result<Rows<'a>> {
    Rows::new(v, c).map_err(analysis(what))
}

fn split_metrics(
    prep: &[&Prepared],
    pick: Pick<'_>,
    opts: &EvalOptions,
    what: &str,
) -> Result<SplitMetrics> {
    let meas_z: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_z, 5, what))
        .collect::<Result<_>>()?;
    let pred_z: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p).0, 5, what))
        .collect::<Result<_>>()?;
    let e = PooledErrors::new(&meas_z, &pred_z, opts.start_sample).map_err(analysis(what))?;
    let meas_c: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_c, 5, what))
        .collect::<Result<_>>()?;
    let pred_c: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p).1, 5, what))
        .collect::<Result<_>>()?;
    let windows: Vec<CycleWindow> = prep.iter().map(|p| p.window).collect();
    let cyc = CycleAverageErrors::new(&meas_c, &pred_c, &windows).map_err(analysis(what))?;
    let mut med = [0.0; 2];
    for (c, m) in med.iter_mut().enumerate() {
        let v: Vec<f64> = meas_c
            .iter()
            .zip(&pred_c)
            .zip(&windows)
            .map(|((a, b), w)| window_rmse(*a, *b, c, *w))
            .collect::<std::result::Result<_, _>>()
            .map_err(analysis(what))?;
        *m = median(&v).map_err(analysis(what))?;
    }
    Ok(SplitMetrics {
        n_trajectories: prep.len(),
        n_samples: e.errors[0].len(),
        rmse_standardized: e.rmse(),
        overall_rmse_standardized: e.overall_rmse(),
        error_interval: e.intervals(opts.level).map_err(analysis(what))?,
        median_cycle_rmse_cf: med,
        cycle_average_error_interval: cyc.intervals(opts.level).map_err(analysis(what))?,
    })
}

/// Standardized errors of one model on a set, for the histograms.
fn pooled(
    prep: &[&Prepared],
    pick: &dyn Fn(&Prepared) -> &[f64],
    start: usize,
) -> Result<PooledErrors> {
    let m: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_z, 5, "errors"))
        .collect::<Result<_>>()?;
    let q: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p), 5, "errors"))
        .collect::<Result<_>>()?;
    PooledErrors::new(&m, &q, start).map_err(analysis("pooled errors"))
}

fn cycle_errors(
    prep: &[&Prepared],
    pick: &dyn Fn(&Prepared) -> &[f64],
) -> Result<CycleAverageErrors> {
    let m: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_c, 5, "cycle averages"))
        .collect::<Result<_>>()?;
    let q: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p), 5, "cycle averages"))
        .collect::<Result<_>>()?;
    let w: Vec<CycleWindow> = prep.iter().map(|p| p.window).collect();
    CycleAverageErrors::new(&m, &q, &w).map_err(analysis("cycle averages"))
}

fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_vec_pretty(value).map_err(|source| PipelineError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    flapssm_data::atomic::write_bytes_atomic(path, &text).map_err(|source| PipelineError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    flapssm_data::atomic::write_bytes_atomic(path, text.as_bytes()).map_err(|source| {
        PipelineError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Writes `value` as pretty JSON, atomically.
///
/// # Errors
/// [`PipelineError::Json`] / [`PipelineError::Io`] naming the file.
pub fn save_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    write_json(path, value)
}

/// Reads a JSON file.
///
/// # Errors
/// [`PipelineError::Io`] / [`PipelineError::Json`] (with line and column) naming the file.
pub fn load_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let bytes = std::fs::read(path).map_err(|source| PipelineError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_slice(&bytes).map_err(|source| PipelineError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// Evaluates both models on `ds` and writes into `out_dir`: `metrics.json`
/// ([`EvaluationReport`]), `trajectories.csv`, `authority_summary.{json,csv}`,
/// `authority_peaks.csv`, `predictions.npz`, the figures (`fig2c_wing_motion.png`,
/// `fig3_time_histories.png`, `fig4a_histograms_{train,test}.png`, `fig4b_cycle_averages.png`,
/// `fig5a_hdr.png`, `fig5a_scatter_x1.png`, `fig5b_summary.png`, `training_*.png`) and
/// `report.html`. Every file is written atomically.
///
/// # Errors
/// A dataset without outputs or training trajectories, models that do not fit it, trajectories
/// without a full stroke cycle, analysis and I/O errors — each naming its item.
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    ds: &Dataset,
    dataset_label: &str,
    prssm: &PrssmModel,
    lrqsm: &LrqsmModel,
    opts: &EvalOptions,
    context: &ReportContext,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<EvaluationReport> {
    ds.validate()?;
    if !ds.has_outputs() {
        return Err(flapssm_data::DatasetError::NoOutputs.into());
    }
    let stats = ds.standardization()?;
    let n = ds.n_samples();
    if opts.start_sample >= n {
        return Err(PipelineError::Mismatch {
            what: "start_sample".into(),
            expected: format!("fewer than the {n} samples per trajectory"),
            found: opts.start_sample.to_string(),
        });
    }
    std::fs::create_dir_all(out_dir).map_err(|source| PipelineError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;

    progress.start("predict PR-SSM", ds.len() as u64);
    let pp = predict_prssm(prssm, ds, opts.particles, opts.seed, progress)?;
    progress.finish("");
    let lq = predict_lrqsm(lrqsm, ds)?;
    let dx = prssm.config.n_state;

    progress.start("analyse", 0);
    let fluid = &ds.meta.fluid;
    let wing = &ds.meta.wing;
    let z = |y: &[f64]| -> Vec<f64> {
        y.chunks_exact(5)
            .flat_map(|r| (0..5).map(move |j| (r[j] - stats.mean_y[j]) / stats.std_y[j]))
            .collect()
    };
    let mut prep = Vec::with_capacity(ds.len());
    for (i, t) in ds.trajectories.iter().enumerate() {
        let what = format!("trajectory {i}");
        let stroke: Vec<f64> = t.euler_rad.iter().map(|e| e[0]).collect();
        let w = published_window(&stroke).map_err(|source| PipelineError::Cycle {
            trajectory: i,
            source,
        })?;
        let window = CycleWindow {
            start: w.first,
            duration: w.duration,
        };
        let scales = CoefficientScales::new(
            fluid.density_kg_m3,
            wing.area_m2(),
            wing.chord_m,
            t.u_ref_m_s,
        )
        .map_err(analysis(format!("{what} coefficient scales")))?;
        let measured = t.outputs.as_deref().unwrap_or_default().as_flattened();
        let coef = |v: &[f64]| -> Result<Vec<f64>> {
            coefficients_of(rows(v, 5, &what)?, &scales).map_err(analysis(what.clone()))
        };
        let std_raw: Vec<f64> = pp[i].var.iter().map(|v| v.max(0.0).sqrt()).collect();
        prep.push(Prepared {
            window,
            measured_z: z(measured),
            measured_c: coef(measured)?,
            prssm_z: z(&pp[i].mean),
            prssm_c: coef(&pp[i].mean)?,
            prssm_std_c: coef(&std_raw)?,
            lrqsm_z: z(&lq[i]),
            lrqsm_c: coef(&lq[i])?,
        });
    }
    let n_train = ds.n_train.min(ds.len());
    if n_train == 0 {
        return Err(flapssm_data::DatasetError::NoTrainingData { n_train }.into());
    }
    let train: Vec<&Prepared> = prep[..n_train].iter().collect();
    let test: Vec<&Prepared> = prep[n_train..].iter().collect();
    let all: Vec<&Prepared> = prep.iter().collect();
    fn pick_p(p: &Prepared) -> (&[f64], &[f64]) {
        (&p.prssm_z, &p.prssm_c)
    }
    fn pick_l(p: &Prepared) -> (&[f64], &[f64]) {
        (&p.lrqsm_z, &p.lrqsm_c)
    }
    let model_metrics = |name: &str, pick: Pick<'_>| {
        Ok::<_, PipelineError>(ModelMetrics {
            model: name.into(),
            train: split_metrics(&train, pick, opts, &format!("{name} training metrics"))?,
            test: if test.is_empty() {
                None
            } else {
                Some(split_metrics(
                    &test,
                    pick,
                    opts,
                    &format!("{name} test metrics"),
                )?)
            },
            cycle_average_error_interval_all: cycle_errors(&all, &|p| pick(p).1)?
                .intervals(opts.level)
                .map_err(analysis(format!("{name} cycle averages")))?,
        })
    };
    let pm = model_metrics("PR-SSM", &pick_p)?;
    let lm = model_metrics("LRQSM", &pick_l)?;
    let (pr, lr) = match (&pm.test, &lm.test) {
        (Some(a), Some(b)) => (&a.rmse_standardized, &b.rmse_standardized),
        _ => (&pm.train.rmse_standardized, &lm.train.rmse_standardized),
    };
    let rmse_ratio: Vec<f64> = pr.iter().zip(lr).map(|(a, b)| a / b).collect();

    let mut trajectories = Vec::with_capacity(ds.len());
    for (i, (t, p)) in ds.trajectories.iter().zip(&prep).enumerate() {
        let what = format!("trajectory {i} metrics");
        let m = rows(&p.measured_c, 5, &what)?;
        let cyc = |v: &[f64]| -> Result<[f64; 2]> {
            let q = rows(v, 5, &what)?;
            Ok([
                window_rmse(m, q, 0, p.window).map_err(analysis(what.clone()))?,
                window_rmse(m, q, 1, p.window).map_err(analysis(what.clone()))?,
            ])
        };
        let overall = |v: &[f64]| -> Result<f64> {
            let e = PooledErrors::new(
                &[rows(&p.measured_z, 5, &what)?],
                &[rows(v, 5, &what)?],
                opts.start_sample,
            )
            .map_err(analysis(what.clone()))?;
            Ok(e.overall_rmse())
        };
        trajectories.push(TrajectoryMetrics {
            index: i,
            split: if i < n_train { "train" } else { "test" }.into(),
            family: t.family.clone(),
            u_ref_m_s: t.u_ref_m_s,
            period_samples: p.window.duration,
            window_start: p.window.start,
            prssm_cycle_rmse_cf: cyc(&p.prssm_c)?,
            lrqsm_cycle_rmse_cf: cyc(&p.lrqsm_c)?,
            prssm_overall_rmse: overall(&p.prssm_z)?,
            lrqsm_overall_rmse: overall(&p.lrqsm_z)?,
        });
    }

    // Control authority on the latent means, every trajectory, transient dropped.
    let s0 = opts.start_sample;
    let auth_traj: Vec<AuthorityTrajectory<'_>> = ds
        .trajectories
        .iter()
        .zip(&pp)
        .zip(&prep)
        .map(|((t, p), q)| {
            Ok(AuthorityTrajectory {
                inputs: rows(&t.inputs.as_flattened()[s0 * 7..], 7, "authority inputs")?,
                states: rows(&p.latent_mean[s0 * dx..], dx, "authority states")?,
                period_samples: q.window.duration as f64,
            })
        })
        .collect::<Result<_>>()?;
    let table = peak_table(&auth_traj, &opts.authority).map_err(analysis("cross-correlations"))?;
    let state_names: Vec<String> = (1..=dx).map(|j| format!("x{j}")).collect();
    let input_names: Vec<String> = INPUT_LABELS.iter().map(|s| s.to_string()).collect();
    let summary = AuthoritySummary::new(
        &table,
        state_names.clone(),
        input_names.clone(),
        &opts.authority,
    )
    .map_err(analysis("control-authority summary"))?;
    let mut authority_findings = Vec::new();
    for input in [0usize, 2] {
        for (state, state_name) in state_names.iter().enumerate().take(5) {
            let s = summary.pair(state, input);
            authority_findings.push(AuthorityFinding {
                input: input_names[input].clone(),
                state: state_name.clone(),
                median_abs_r: s.median_abs_r,
                median_lag_cycles: s.median_lag_cycles,
                lag_iqr_cycles: s.lag_iqr_cycles,
                mode_lag_cycles: s.mode_lag_cycles,
                strong: s.strong,
            });
        }
    }
    progress.finish("");

    // Files.
    progress.start("write outputs", 0);
    let mut files = Vec::new();
    let mut file = |name: &str| {
        files.push(name.to_string());
        out_dir.join(name)
    };
    let p_json = file("authority_summary.json");
    summary
        .write_json(&p_json)
        .map_err(analysis(p_json.display().to_string()))?;
    let p_csv = file("authority_summary.csv");
    summary
        .write_csv(&p_csv)
        .map_err(analysis(p_csv.display().to_string()))?;
    let p_peaks = file("authority_peaks.csv");
    table
        .write_csv(&p_peaks, &state_names, &input_names)
        .map_err(analysis(p_peaks.display().to_string()))?;
    write_text(&file("trajectories.csv"), &trajectories_csv(&trajectories))?;
    write_predictions(&file("predictions.npz"), ds, &pp, &lq, dx)?;

    // Figures.
    let examples = example_trajectories(ds, opts.example_trajectories);
    let mut fig = |name: &str| file(name);
    let f_2c = fig("fig2c_wing_motion.png");
    let f_3 = fig("fig3_time_histories.png");
    let f_4a_train = fig("fig4a_histograms_train.png");
    let f_4a_test = fig("fig4a_histograms_test.png");
    let f_4b = fig("fig4b_cycle_averages.png");
    let f_5a = fig("fig5a_hdr.png");
    let f_5s = fig("fig5a_scatter_x1.png");
    let f_5b = fig("fig5b_summary.png");
    let f_loss = fig("training_loss.png");
    let f_rmse = fig("training_rmse.png");
    let labels: Vec<String> = examples
        .iter()
        .map(|&i| example_title(ds, i, &trajectories[i]))
        .collect();
    let paths: Vec<wing3d::WingPath<'_>> = examples
        .iter()
        .zip(&labels)
        .map(|(&i, l)| wing3d::WingPath {
            label: l,
            euler_rad: &ds.trajectories[i].euler_rad[prep[i].window.range(n).unwrap_or(0..=0)],
        })
        .collect();
    let geom = wing3d::WingSketchGeometry {
        r_m: wing.u_ref_radius_m,
        chord_m: wing.chord_m,
        pitch_axis_frac: wing.pitch_axis_frac,
        ..Default::default()
    };
    wing3d::wing_motion_3d(&f_2c, &paths, &geom).map_err(analysis("Fig. 2C"))?;
    draw_fig3(&f_3, ds, &prep, &examples, &labels)?;
    let names5: Vec<&str> = COEFFICIENT_LABELS.to_vec();
    let edges = Histogram::uniform_edges(-1.1, 1.1, 0.01);
    let out_names = OUTPUT_NAMES
        .iter()
        .map(|s| format!("{s}/σ"))
        .collect::<Vec<_>>();
    let out_refs: Vec<&str> = out_names.iter().map(String::as_str).collect();
    for (path, set, label) in [(&f_4a_train, &train, "train"), (&f_4a_test, &test, "test")] {
        if set.is_empty() {
            continue;
        }
        let ep = pooled(set, &|p| &p.prssm_z, s0)?;
        let el = pooled(set, &|p| &p.lrqsm_z, s0)?;
        let lp = format!("PR-SSM {label}");
        let ll = format!("LRQSM {label}");
        pe::error_histograms(
            path,
            &out_refs,
            &[
                pe::ModelErrors {
                    label: &lp,
                    errors: &ep.errors,
                },
                pe::ModelErrors {
                    label: &ll,
                    errors: &el.errors,
                },
            ],
            &edges,
            opts.level,
        )
        .map_err(analysis("Fig. 4A"))?;
    }
    let cp = cycle_errors(&all, &|p| &p.prssm_c)?;
    let cl = cycle_errors(&all, &|p| &p.lrqsm_c)?;
    pe::cycle_average_scatter(
        &f_4b,
        &names5,
        &[
            pe::ModelCycleAverages {
                label: "PR-SSM",
                observed: &cp.observed,
                error: &cp.error,
            },
            pe::ModelCycleAverages {
                label: "LRQSM",
                observed: &cl.observed,
                error: &cl.error,
            },
        ],
        Some(&[0.75, 0.75, 2.0, 2.0, 2.0]),
        opts.level,
    )
    .map_err(analysis("Fig. 4B"))?;
    pa::hdr_contours(&f_5a, &summary).map_err(analysis("Fig. 5Ai"))?;
    pa::pair_scatter(&f_5s, &table, &summary, 0).map_err(analysis("Fig. 5Aii"))?;
    pa::summary_grid(&f_5b, &summary).map_err(analysis("Fig. 5B"))?;
    let have_curves = draw_training(&f_loss, &f_rmse, prssm)?;
    if !have_curves {
        files.retain(|f| !f.starts_with("training_"));
    }
    if test.is_empty() {
        files.retain(|f| f != "fig4a_histograms_test.png");
    }

    let report = EvaluationReport {
        dataset: dataset_label.to_string(),
        n_train,
        n_test: test.len(),
        options: opts.clone(),
        prssm: pm,
        lrqsm: lm,
        rmse_ratio,
        trajectories,
        authority_findings,
        files: {
            let mut f = files.clone();
            f.push("metrics.json".into());
            f.push("report.html".into());
            f
        },
    };
    write_json(&out_dir.join("metrics.json"), &report)?;
    let html = html_report(
        &report,
        context,
        ReportFigures {
            f_2c,
            f_3,
            f_4a_train,
            f_4a_test: (!test.is_empty()).then_some(f_4a_test),
            f_4b,
            f_5a,
            f_5s,
            f_5b,
            training: have_curves.then_some((f_loss, f_rmse)),
        },
        prssm,
        lrqsm,
    );
    let p_html = out_dir.join("report.html");
    html.write(&p_html)
        .map_err(analysis(p_html.display().to_string()))?;
    progress.finish("");
    Ok(report)
}

/// Up to `k` test trajectories (training ones when there is no test set), distinct families
/// first, in dataset order.
fn example_trajectories(ds: &Dataset, k: usize) -> Vec<usize> {
    let n_train = ds.n_train.min(ds.len());
    let pool: Vec<usize> = if n_train < ds.len() {
        (n_train..ds.len()).collect()
    } else {
        (0..ds.len()).collect()
    };
    let mut chosen: Vec<usize> = Vec::new();
    for &i in &pool {
        if chosen.len() < k
            && !chosen
                .iter()
                .any(|&c| ds.trajectories[c].family == ds.trajectories[i].family)
        {
            chosen.push(i);
        }
    }
    for &i in &pool {
        if chosen.len() < k && !chosen.contains(&i) {
            chosen.push(i);
        }
    }
    chosen.sort_unstable();
    chosen
}

fn example_title(ds: &Dataset, i: usize, m: &TrajectoryMetrics) -> String {
    let n_train = ds.n_train.min(ds.len());
    let name = if i >= n_train {
        format!("test #{}", i - n_train + 1)
    } else {
        format!("train #{}", i + 1)
    };
    format!("{name} ({})", m.family)
}

fn draw_fig3(
    path: &Path,
    ds: &Dataset,
    prep: &[Prepared],
    examples: &[usize],
    labels: &[String],
) -> Result<()> {
    let n = ds.n_samples();
    struct Data {
        t: Vec<f64>,
        euler: Vec<[f64; 3]>,
        cols: [[Vec<f64>; 2]; 4],
        title: String,
    }
    let data: Vec<Data> = examples
        .iter()
        .zip(labels)
        .map(|(&i, label)| {
            let p = &prep[i];
            let range = p.window.range(n).map_err(analysis("Fig. 3 window"))?;
            let col = |v: &[f64], j: usize| range.clone().map(|k| v[k * 5 + j]).collect();
            let pair = |v: &[f64]| [col(v, 0), col(v, 1)];
            let rm = |v: &[f64], j: usize| -> f64 {
                let e: Vec<f64> = range
                    .clone()
                    .map(|k| p.measured_c[k * 5 + j] - v[k * 5 + j])
                    .collect();
                flapssm_analysis::metrics::rms(&e)
            };
            Ok(Data {
                t: (0..=p.window.duration)
                    .map(|k| k as f64 / p.window.duration as f64)
                    .collect(),
                euler: range
                    .clone()
                    .map(|k| ds.trajectories[i].euler_rad[k])
                    .collect(),
                cols: [
                    pair(&p.measured_c),
                    pair(&p.prssm_c),
                    pair(&p.prssm_std_c),
                    pair(&p.lrqsm_c),
                ],
                title: format!(
                    "{label}: RMSE C_Fx {:.2}/{:.2}",
                    rm(&p.prssm_c, 0),
                    rm(&p.lrqsm_c, 0)
                ),
            })
        })
        .collect::<Result<_>>()?;
    let models: Vec<[pt::CoefficientCurves<'_>; 2]> = data
        .iter()
        .map(|d| {
            [
                pt::CoefficientCurves {
                    label: "PR-SSM ±2σ",
                    cfx: &d.cols[1][0],
                    cfy: &d.cols[1][1],
                    cfx_std: Some(&d.cols[2][0]),
                    cfy_std: Some(&d.cols[2][1]),
                },
                pt::CoefficientCurves {
                    label: "LRQSM",
                    cfx: &d.cols[3][0],
                    cfy: &d.cols[3][1],
                    cfx_std: None,
                    cfy_std: None,
                },
            ]
        })
        .collect();
    let panels: Vec<pt::TrajectoryPanel<'_>> = data
        .iter()
        .zip(&models)
        .map(|(d, m)| pt::TrajectoryPanel {
            title: &d.title,
            t: &d.t,
            euler_rad: &d.euler,
            measured: pt::CoefficientCurves {
                label: "measured",
                cfx: &d.cols[0][0],
                cfy: &d.cols[0][1],
                cfx_std: None,
                cfy_std: None,
            },
            models: m,
        })
        .collect();
    let sketch = pt::ChordSketch {
        chord_deg: (ds.meta.wing.chord_m / ds.meta.wing.u_ref_radius_m).to_degrees(),
        pitch_axis_frac: ds.meta.wing.pitch_axis_frac,
        ..Default::default()
    };
    pt::time_histories(path, "t̂ (cycles)", &panels, &sketch).map_err(analysis("Fig. 3"))
}

/// Draws the training curves of a model fitted by the trainer; `false` when it has no history.
fn draw_training(f_loss: &Path, f_rmse: &Path, model: &PrssmModel) -> Result<bool> {
    let Ok(rec) = training_record(model) else {
        return Ok(false);
    };
    if rec.history.is_empty() {
        return Ok(false);
    }
    let ep: Vec<f64> = rec.history.iter().map(|r| r.epoch as f64 + 1.0).collect();
    let loss: Vec<f64> = rec.history.iter().map(|r| r.mean_loss).collect();
    let log = loss.iter().all(|v| *v > 0.0);
    training::training_curves(
        f_loss,
        "PR-SSM training objective",
        "mean minibatch −ELBO",
        &[training::TrainingCurve {
            label: "−ELBO",
            epochs: &ep,
            values: &loss,
        }],
        log,
    )
    .map_err(analysis("training loss figure"))?;
    let series = |f: &dyn Fn(&flapssm_prssm::train::EpochRecord) -> Option<f64>| {
        let (e, v): (Vec<f64>, Vec<f64>) = rec
            .history
            .iter()
            .filter_map(|r| f(r).map(|v| (r.epoch as f64 + 1.0, v)))
            .unzip();
        (e, v)
    };
    let (et, vt) = series(&|r| r.train_rmse);
    let (ev, vv) = series(&|r| r.val_rmse);
    let mut curves = Vec::new();
    if !et.is_empty() {
        curves.push(training::TrainingCurve {
            label: "training RMSE",
            epochs: &et,
            values: &vt,
        });
    }
    if !ev.is_empty() {
        curves.push(training::TrainingCurve {
            label: "validation RMSE",
            epochs: &ev,
            values: &vv,
        });
    }
    if curves.is_empty() {
        return Ok(false);
    }
    training::training_curves(
        f_rmse,
        "PR-SSM open-loop RMSE during training",
        "RMSE (standardized, after burn-in)",
        &curves,
        false,
    )
    .map_err(analysis("training RMSE figure"))?;
    Ok(true)
}

fn trajectories_csv(t: &[TrajectoryMetrics]) -> String {
    let mut s = String::from(
        "index,split,family,u_ref_m_s,period_samples,window_start,prssm_rmse_cfx,prssm_rmse_cfy,lrqsm_rmse_cfx,lrqsm_rmse_cfy,prssm_overall_rmse_std,lrqsm_overall_rmse_std\n",
    );
    for m in t {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            m.index,
            m.split,
            m.family,
            m.u_ref_m_s,
            m.period_samples,
            m.window_start,
            m.prssm_cycle_rmse_cf[0],
            m.prssm_cycle_rmse_cf[1],
            m.lrqsm_cycle_rmse_cf[0],
            m.lrqsm_cycle_rmse_cf[1],
            m.prssm_overall_rmse,
            m.lrqsm_overall_rmse
        ));
    }
    s
}

fn write_predictions(
    path: &Path,
    ds: &Dataset,
    pp: &[PrssmPrediction],
    lq: &[Vec<f64>],
    dx: usize,
) -> Result<()> {
    use flapssm_data::npz::{NpyData, NpzWriter};
    let (k, n) = (ds.len(), ds.n_samples());
    let cat = |parts: Vec<&[f64]>| NpyData::F64(parts.concat());
    let mut w = NpzWriter::new();
    w.add(
        "prssm_mean",
        &[k, n, 5],
        cat(pp.iter().map(|p| p.mean.as_slice()).collect()),
    )
    .add(
        "prssm_var",
        &[k, n, 5],
        cat(pp.iter().map(|p| p.var.as_slice()).collect()),
    )
    .add(
        "prssm_latent_mean",
        &[k, n, dx],
        cat(pp.iter().map(|p| p.latent_mean.as_slice()).collect()),
    )
    .add(
        "lrqsm",
        &[k, n, 5],
        cat(lq.iter().map(Vec::as_slice).collect()),
    )
    .add(
        "is_train",
        &[k],
        NpyData::Bool((0..k).map(|i| i < ds.n_train).collect()),
    );
    w.save(path).map_err(|e| PipelineError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    })
}

struct ReportFigures {
    f_2c: PathBuf,
    f_3: PathBuf,
    f_4a_train: PathBuf,
    f_4a_test: Option<PathBuf>,
    f_4b: PathBuf,
    f_5a: PathBuf,
    f_5s: PathBuf,
    f_5b: PathBuf,
    training: Option<(PathBuf, PathBuf)>,
}

fn f3(v: f64) -> String {
    format!("{v:.3}")
}

fn interval_cells(v: &[Interval]) -> Vec<String> {
    v.iter()
        .map(|i| format!("[{:.2}, {:.2}]", i.lo, i.hi))
        .collect()
}

fn html_report(
    r: &EvaluationReport,
    ctx: &ReportContext,
    f: ReportFigures,
    prssm: &PrssmModel,
    lrqsm: &LrqsmModel,
) -> Report {
    let row = |label: String, cells: Vec<String>| std::iter::once(label).chain(cells).collect();
    let header = |first: &str, names: &[&str]| -> Vec<String> {
        std::iter::once(first.to_string())
            .chain(names.iter().map(|s| s.to_string()))
            .collect()
    };
    let mut rmse_rows = Vec::new();
    let mut ci_rows = Vec::new();
    let mut cyc_rows = Vec::new();
    for m in [&r.prssm, &r.lrqsm] {
        for (split, s) in [("train", Some(&m.train)), ("test", m.test.as_ref())] {
            let Some(s) = s else { continue };
            let mut cells: Vec<String> = s.rmse_standardized.iter().map(|v| f3(*v)).collect();
            cells.push(f3(s.overall_rmse_standardized));
            cells.push(format!(
                "{:.3} / {:.3}",
                s.median_cycle_rmse_cf[0], s.median_cycle_rmse_cf[1]
            ));
            rmse_rows.push(row(format!("{} {split}", m.model), cells));
            ci_rows.push(row(
                format!("{} {split}", m.model),
                interval_cells(&s.error_interval),
            ));
            cyc_rows.push(row(
                format!("{} {split}", m.model),
                interval_cells(&s.cycle_average_error_interval),
            ));
        }
        cyc_rows.push(row(
            format!("{} train + test", m.model),
            interval_cells(&m.cycle_average_error_interval_all),
        ));
    }
    rmse_rows.push(row(
        "ratio PR-SSM / LRQSM (test)".into(),
        r.rmse_ratio.iter().map(|v| f3(*v)).collect(),
    ));
    let mut rmse_header = header("model, set", &OUTPUT_NAMES);
    rmse_header.push("overall".into());
    rmse_header.push("median last-cycle RMSE C_Fx / C_Fy".into());
    let auth_rows: Vec<Vec<String>> = r
        .authority_findings
        .iter()
        .map(|a| {
            vec![
                a.input.clone(),
                a.state.clone(),
                f3(a.median_abs_r),
                f3(a.median_lag_cycles),
                f3(a.lag_iqr_cycles),
                f3(a.mode_lag_cycles),
                if a.strong { "yes" } else { "no" }.into(),
            ]
        })
        .collect();
    let test_traj: Vec<Vec<String>> = r
        .trajectories
        .iter()
        .filter(|t| t.split == "test")
        .map(|t| {
            vec![
                format!("{}", t.index - r.n_train + 1),
                t.family.clone(),
                format!("{:.3}", t.u_ref_m_s),
                t.period_samples.to_string(),
                f3(t.prssm_cycle_rmse_cf[0]),
                f3(t.lrqsm_cycle_rmse_cf[0]),
                f3(t.prssm_cycle_rmse_cf[1]),
                f3(t.lrqsm_cycle_rmse_cf[1]),
            ]
        })
        .collect();
    let overall = |m: &ModelMetrics| {
        m.test
            .as_ref()
            .unwrap_or(&m.train)
            .overall_rmse_standardized
    };
    let mut headline = vec![
        (
            "dataset".to_string(),
            format!("{} ({} train / {} test)", r.dataset, r.n_train, r.n_test),
        ),
        (
            "overall test RMSE PR-SSM / LRQSM (σ units)".into(),
            format!("{:.3} / {:.3}", overall(&r.prssm), overall(&r.lrqsm)),
        ),
        (
            "test RMSE ratio PR-SSM / LRQSM per output".into(),
            r.rmse_ratio
                .iter()
                .zip(OUTPUT_NAMES)
                .map(|(v, n)| format!("{n} {v:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
        ),
    ];
    for input in ["AoA", "a_x"] {
        let lags: Vec<String> = r
            .authority_findings
            .iter()
            .filter(|a| a.input == input)
            .map(|a| format!("{} {:.2}", a.state, a.median_lag_cycles))
            .collect();
        headline.push((
            format!("median lag of {input} → output states (cycles)"),
            lags.join(", "),
        ));
    }
    headline.extend(ctx.headline.iter().cloned());
    let mut accuracy_figs = vec![
        Figure {
            caption: "Fig. 3 — last full cycle of test trajectories: chord sketch, Euler angles, measured and predicted C_Fx, C_Fy (title: last-cycle C_Fx RMSE PR-SSM/LRQSM)".into(),
            path: f.f_3,
        },
        Figure {
            caption: "Fig. 4A — standardized-error histograms, training set, with 95 % intervals".into(),
            path: f.f_4a_train,
        },
    ];
    if let Some(p) = f.f_4a_test {
        accuracy_figs.push(Figure {
            caption: "Fig. 4A — standardized-error histograms, test set, with 95 % intervals"
                .into(),
            path: p,
        });
    }
    accuracy_figs.push(Figure {
        caption: "Fig. 4B — half-stroke averages: error vs measured value, training and test, with 95 % intervals".into(),
        path: f.f_4b,
    });
    let mut sections = vec![
        Section {
            heading: "Accuracy".into(),
            paragraphs: vec![format!(
                "Errors are measured − predicted. Standardized errors use the training mean and standard deviation of each output and samples from {} on (0-based; the first {} samples are dropped). Intervals are the {}-% central percentile intervals (MATLAB prctile). Cycle averages are half-stroke means of the load coefficients over the last full stroke cycle.",
                r.options.start_sample, r.options.start_sample, r.options.level
            )],
            tables: vec![
                Table {
                    caption: "RMSE per output (σ units) and median last-cycle coefficient RMSE".into(),
                    header: rmse_header,
                    rows: rmse_rows,
                },
                Table {
                    caption: "95 % intervals of the standardized errors".into(),
                    header: header("model, set", &OUTPUT_NAMES),
                    rows: ci_rows,
                },
                Table {
                    caption: "95 % intervals of the half-stroke-average errors (coefficients)".into(),
                    header: header("model, set", &COEFFICIENT_LABELS),
                    rows: cyc_rows,
                },
                Table {
                    caption: "Test trajectories: last-cycle RMSE of the force coefficients".into(),
                    header: [
                        "test #", "family", "U_ref (m/s)", "period (samples)",
                        "C_Fx PR-SSM", "C_Fx LRQSM", "C_Fy PR-SSM", "C_Fy LRQSM",
                    ]
                    .iter()
                    .map(|s| s.to_string())
                    .collect(),
                    rows: test_traj,
                },
            ],
            figures: accuracy_figs,
        },
        Section {
            heading: "Control authority (cross-correlation of the PR-SSM latent means)".into(),
            paragraphs: vec![format!(
                "Per trajectory, state and input: the largest |r| of the normalized cross-correlation (MATLAB crosscorr) over lags 0 < lag < {} cycle, state lagging input; pooled over all {} trajectories with a reflected 2-D Gaussian KDE (bandwidth {}).",
                r.options.authority.max_lag_cycles,
                r.n_train + r.n_test,
                r.options.authority.bandwidth
            )],
            tables: vec![Table {
                caption: "AoA and a_x on the output states".into(),
                header: [
                    "input", "state", "median max |r|", "median lag (cycles)",
                    "lag IQR", "mode lag", "strong (median |r| > 0.5)",
                ]
                .iter()
                .map(|s| s.to_string())
                .collect(),
                rows: auth_rows,
            }],
            figures: vec![
                Figure {
                    caption: "Fig. 5Ai — 70 % highest-density regions and modes (+)".into(),
                    path: f.f_5a,
                },
                Figure {
                    caption: "Fig. 5Aii — state x1: max |r| vs lag per trajectory".into(),
                    path: f.f_5s,
                },
                Figure {
                    caption: "Fig. 5B — summary: radius ∝ median max |r|, lightness ∝ lag IQR, median lag printed for strong pairs".into(),
                    path: f.f_5b,
                },
            ],
        },
        Section {
            heading: "Wing motions".into(),
            figures: vec![Figure {
                caption: "Fig. 2C — last full cycle of the example test trajectories (chord at the U_ref radius, LE dotted)".into(),
                path: f.f_2c,
            }],
            ..Default::default()
        },
    ];
    if let Some((loss, rmse)) = f.training {
        sections.push(Section {
            heading: "PR-SSM training".into(),
            figures: vec![
                Figure {
                    caption: "Mean minibatch negative ELBO per epoch".into(),
                    path: loss,
                },
                Figure {
                    caption: "Open-loop RMSE on training and validation sequences".into(),
                    path: rmse,
                },
            ],
            ..Default::default()
        });
    }
    let config = serde_json::json!({
        "run": ctx.config,
        "evaluation": r.options,
        "prssm_model": prssm.config,
        "prssm_training": training_record(prssm).ok().map(|t| t.spec),
        "lrqsm": { "feature_set": lrqsm.feature_set, "options": lrqsm.options,
                   "lambda": lrqsm.chosen.iter().map(|c| c.lambda).collect::<Vec<_>>() },
    });
    Report {
        title: if ctx.title.is_empty() {
            "flapssm evaluation: PR-SSM vs LRQSM".into()
        } else {
            ctx.title.clone()
        },
        intro: ctx.intro.clone(),
        headline,
        sections,
        config,
        versions: versions(),
    }
}

/// Versions of the flapssm crates used.
pub fn versions() -> Vec<(String, String)> {
    vec![
        ("flapssm".into(), env!("CARGO_PKG_VERSION").into()),
        (
            "build".into(),
            if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            }
            .into(),
        ),
        (
            "parallel".into(),
            if cfg!(feature = "parallel") {
                "rayon"
            } else {
                "off"
            }
            .into(),
        ),
    ]
}

/// PR-SSM training settings shared by the sweeps and the demo: a preset with overrides.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingOptions {
    /// Named preset (paper: D_x 12, M 100, 30 particles, batch 16, lr 0.03, 1000 epochs).
    pub preset: Preset,
    /// Latent dimension D_x.
    pub dx: Option<usize>,
    /// Inducing points M.
    pub inducing: Option<usize>,
    /// Particles per window (also used for the per-epoch evaluation rollouts).
    pub particles: Option<usize>,
    /// Epochs.
    pub epochs: Option<u64>,
    /// Optimizer steps (instead of epochs; wins over `epochs` when both are given).
    pub iterations: Option<u64>,
    /// Windows per minibatch.
    pub batch: Option<usize>,
    /// Adam learning rate.
    pub lr: Option<f64>,
    /// Learning-rate schedule.
    pub schedule: Option<LrSchedule>,
    /// Evaluate (best-model tracking) every this many epochs.
    pub eval_every: Option<u64>,
    /// Seed of initialization, shuffles and draws.
    pub seed: u64,
    /// Fraction of the training trajectories (the last ones) held out for best-model selection.
    pub val_fraction: f64,
    /// Checkpoint every this many epochs (0: only when interrupted).
    pub checkpoint_every: u64,
}

impl Default for TrainingOptions {
    /// The paper preset, no overrides, seed 0, 10 % validation, checkpoint every 10 epochs.
    fn default() -> Self {
        Self {
            preset: Preset::Paper,
            dx: None,
            inducing: None,
            particles: None,
            epochs: None,
            iterations: None,
            batch: None,
            lr: None,
            schedule: None,
            eval_every: None,
            seed: 0,
            val_fraction: 0.1,
            checkpoint_every: 10,
        }
    }
}

impl TrainingOptions {
    /// The fit specification for 7 inputs and 5 outputs.
    pub fn spec(&self) -> FitSpec {
        let mut spec = FitSpec::preset(self.preset, 7, 5);
        if let Some(v) = self.dx {
            spec.model.n_state = v;
        }
        if let Some(v) = self.inducing {
            spec.model.n_inducing = v;
        }
        if let Some(v) = self.particles {
            spec.particles = v;
            spec.eval_particles = v;
        }
        if let Some(v) = self.epochs {
            spec.train.budget = Budget::Epochs(v);
        }
        if let Some(v) = self.iterations {
            spec.train.budget = Budget::Iterations(v);
        }
        if let Some(v) = self.batch {
            spec.train.batch_size = v;
        }
        if let Some(v) = self.lr {
            spec.train.lr = v;
        }
        if let Some(v) = self.schedule {
            spec.train.schedule = v;
        }
        if let Some(v) = self.eval_every {
            spec.train.eval_every = v;
        }
        spec.train.seed = self.seed;
        spec.train.checkpoint_every = self.checkpoint_every;
        spec
    }

    /// Splits training trajectories into (fit, validation): the last
    /// `round(n · val_fraction)` (at most `n − 1`) validate.
    ///
    /// # Errors
    /// [`PipelineError::Mismatch`] for a fraction outside [0, 1) or no trajectory.
    pub fn split<'a>(
        &self,
        train: &'a [Trajectory],
    ) -> Result<(&'a [Trajectory], &'a [Trajectory])> {
        if !(0.0..1.0).contains(&self.val_fraction) || train.is_empty() {
            return Err(PipelineError::Mismatch {
                what: "training split".into(),
                expected: "val_fraction in [0, 1) and at least one training trajectory".into(),
                found: format!("{} of {} trajectories", self.val_fraction, train.len()),
            });
        }
        let n_val =
            ((train.len() as f64 * self.val_fraction).round() as usize).min(train.len() - 1);
        Ok(train.split_at(train.len() - n_val))
    }
}

/// Trains a PR-SSM on `train` (split by [`TrainingOptions::split`]), reporting steps to
/// `progress` (`set(step, total)`, one line per evaluated epoch), checkpointing to
/// `checkpoint` and resuming from `resume`. Polls `stop` before every step.
///
/// # Errors
/// [`PipelineError::Prssm`] for a failed fit, [`PipelineError::Interrupted`] when stopped.
pub fn train_prssm(
    train: &[Trajectory],
    opts: &TrainingOptions,
    checkpoint: Option<&Path>,
    resume: Option<Checkpoint>,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<FitOutcome> {
    let (fit_set, val_set) = opts.split(train)?;
    let fit_seqs: Vec<Sequence> = fit_set.iter().map(trajectory_sequence).collect();
    let val_seqs: Vec<Sequence> = val_set.iter().map(trajectory_sequence).collect();
    let spec = opts.spec();
    let mut on_event = |e: &TrainEvent<'_>| match e {
        TrainEvent::Step {
            step,
            total_steps,
            epoch,
            loss,
            ..
        } => {
            progress.set(step + 1, *total_steps);
            progress.message(&format!("epoch {epoch} loss {loss:.3e}"));
        }
        TrainEvent::Epoch(r) => {
            let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
            progress.println(&format!(
                "epoch {:>4}: -ELBO {:.4e}  train RMSE {}  val RMSE {}{}",
                r.epoch,
                r.mean_loss,
                f(r.train_rmse),
                f(r.val_rmse),
                if r.is_best { "  (best)" } else { "" }
            ));
        }
        TrainEvent::Rejected { step, reason, .. } => {
            progress.println(&format!("step {step} rejected ({reason}); retried"));
        }
        _ => {}
    };
    let out = fit(
        &spec,
        &fit_seqs,
        &val_seqs,
        TrainHooks {
            evaluate: None,
            progress: Some(&mut on_event),
            stop,
            checkpoint: checkpoint.map(Path::to_path_buf),
        },
        resume,
    )
    .map_err(|source| PipelineError::Prssm {
        what: "training".into(),
        source,
    })?;
    if out.outcome.interrupted {
        return Err(PipelineError::Interrupted {
            step: out.outcome.state.step,
            checkpoint: checkpoint.map(Path::to_path_buf).unwrap_or_default(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};

    fn tiny_dataset() -> Dataset {
        let mut cfg = SimulationConfig::default();
        cfg.trajectories.n_trajectories = 6;
        cfg.trajectories.n_train = 4;
        cfg.trajectories.seed = 3;
        simulate_dataset(&cfg, &|| {}).unwrap()
    }

    #[test]
    fn validation_split_follows_the_fraction() {
        let ds = tiny_dataset();
        let t = &ds.trajectories[..5];
        let split = |f: f64| {
            let o = TrainingOptions {
                val_fraction: f,
                ..TrainingOptions::default()
            };
            o.split(t).map(|(a, b)| (a.len(), b.len()))
        };
        assert_eq!(split(0.0).unwrap(), (5, 0));
        assert_eq!(split(0.2).unwrap(), (4, 1));
        assert_eq!(split(0.5).unwrap(), (2, 3)); // round(2.5) = 3
        assert_eq!(split(0.99).unwrap(), (1, 4)); // at least one trajectory is fitted
        assert!(split(1.0).is_err() && split(-0.1).is_err());
    }

    #[test]
    fn overrides_reach_the_fit_spec() {
        let o = TrainingOptions {
            dx: Some(6),
            inducing: Some(9),
            particles: Some(4),
            epochs: Some(7),
            batch: Some(2),
            lr: Some(0.2),
            seed: 11,
            ..TrainingOptions::default()
        };
        let s = o.spec();
        assert_eq!((s.model.n_state, s.model.n_inducing), (6, 9));
        assert_eq!((s.particles, s.eval_particles), (4, 4));
        assert_eq!(s.train.budget, Budget::Epochs(7));
        assert_eq!((s.train.batch_size, s.train.lr, s.train.seed), (2, 0.2, 11));
        // No override: the paper preset.
        let p = TrainingOptions::default().spec();
        assert_eq!(p, {
            let mut f = FitSpec::preset(Preset::Paper, 7, 5);
            f.train.checkpoint_every = 10;
            f
        });
    }

    /// The pipeline's LRQSM errors agree with the qs crate's own RMSE (computed there from raw
    /// loads divided by σ), and its sums are consistent: overall² = mean of per-output RMSE²,
    /// ratio = PR-SSM / LRQSM, the windows are the published ones.
    #[test]
    fn metrics_agree_with_independent_computations() {
        let ds = tiny_dataset();
        let lrqsm =
            flapssm_qs::lrqsm::fit_dataset(&ds, Default::default(), &Default::default(), "tiny")
                .unwrap();
        let q = flapssm_qs::lrqsm::predict_dataset(&lrqsm, &ds, InterceptMode::Fitted).unwrap();
        let opts = TrainingOptions {
            dx: Some(5),
            inducing: Some(6),
            particles: Some(3),
            epochs: Some(1),
            val_fraction: 0.0,
            ..TrainingOptions::default()
        };
        let fit = train_prssm(ds.train(), &opts, None, None, &NoProgress, None).unwrap();
        let dir = std::env::temp_dir().join(format!("flapssm-pipeline-{}", std::process::id()));
        let eo = EvalOptions {
            start_sample: 0,
            particles: 3,
            authority: AuthorityConfig {
                grid_points: 20,
                ..AuthorityConfig::default()
            },
            ..EvalOptions::default()
        };
        let r = evaluate(
            &ds,
            "tiny",
            &fit.best,
            &lrqsm,
            &eo,
            &ReportContext::default(),
            &dir,
            &NoProgress,
        )
        .unwrap();
        let lt = r.lrqsm.test.as_ref().unwrap();
        let qt = q.rmse_test.as_ref().unwrap();
        for j in 0..5 {
            assert!((lt.rmse_standardized[j] - qt.standardized[j]).abs() < 1e-10);
            assert!(
                (r.lrqsm.train.rmse_standardized[j]
                    - q.rmse_train.as_ref().unwrap().standardized[j])
                    .abs()
                    < 1e-10
            );
        }
        let pt = r.prssm.test.as_ref().unwrap();
        let ms: f64 = pt.rmse_standardized.iter().map(|v| v * v).sum::<f64>() / 5.0;
        assert!((pt.overall_rmse_standardized - ms.sqrt()).abs() < 1e-12);
        for j in 0..5 {
            assert_eq!(
                r.rmse_ratio[j],
                pt.rmse_standardized[j] / lt.rmse_standardized[j]
            );
        }
        for (t, m) in ds.trajectories.iter().zip(&r.trajectories) {
            let stroke: Vec<f64> = t.euler_rad.iter().map(|e| e[0]).collect();
            let w = published_window(&stroke).unwrap();
            assert_eq!((m.window_start, m.period_samples), (w.first, w.duration));
        }
        assert_eq!(r.authority_findings.len(), 10);
        for f in &r.files {
            assert!(dir.join(f).exists(), "{f}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    /// Regression: a model without normalization statistics (the published one works in
    /// standardized units) used to receive raw inputs. It must predict exactly as the same
    /// model carrying the dataset's training statistics.
    fn a_model_without_statistics_uses_the_dataset_training_statistics() {
        let ds = tiny_dataset();
        let cfg = flapssm_prssm::ModelConfig::new(6, 5, 7, 4);
        let params = flapssm_prssm::Params::init(&cfg, &Default::default(), 3);
        let bare = PrssmModel {
            config: cfg,
            params,
            normalization: None,
            training: serde_json::Value::Null,
        };
        let s = ds.standardization().unwrap();
        let mut with_stats = bare.clone();
        with_stats.normalization = Some(flapssm_prssm::Normalization {
            input_mean: s.mean_u.to_vec(),
            input_std: s.std_u.to_vec(),
            output_mean: s.mean_y.to_vec(),
            output_std: s.std_y.to_vec(),
        });
        let a = predict_prssm(&bare, &ds, 3, 5, &NoProgress).unwrap();
        let b = predict_prssm(&with_stats, &ds, 3, 5, &NoProgress).unwrap();
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.mean, y.mean);
            assert_eq!(x.var, y.var);
        }
        // Raw inputs fed as if standardized would differ.
        let mut raw = bare.clone();
        raw.normalization = Some(flapssm_prssm::Normalization {
            input_mean: vec![0.0; 7],
            input_std: vec![1.0; 7],
            output_mean: vec![0.0; 5],
            output_std: vec![1.0; 5],
        });
        let c = predict_prssm(&raw, &ds, 3, 5, &NoProgress).unwrap();
        assert_ne!(a[0].mean, c[0].mean);
    }

    #[test]
    fn model_of_the_wrong_shape_is_rejected() {
        let ds = tiny_dataset();
        let cfg = flapssm_prssm::ModelConfig::new(4, 2, 3, 5);
        let params = flapssm_prssm::Params::init(&cfg, &Default::default(), 1);
        let m = PrssmModel {
            config: cfg,
            params,
            normalization: None,
            training: serde_json::Value::Null,
        };
        let e = predict_prssm(&m, &ds, 2, 0, &NoProgress).unwrap_err();
        assert!(e.to_string().contains("7 inputs and 5 outputs"), "{e}");
    }
}
