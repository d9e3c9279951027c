//! The evaluation pipeline: any number of load models on a dataset → accuracy metrics, cycle
//! averages, control authority of the latent states, figures and the HTML report.
//!
//! Per trajectory `i` (n samples) and model ([`LoadModel::predict_into`]):
//! - output means (N, N·mm), variances where the model has them, latent means where it has
//!   latent states (the PR-SSM: standardized latent units, `n × D_x`, particle draws seeded by
//!   [`crate::seed::prediction_seed`]`(seed, i)`).
//! - Standardized errors `e = (y − ŷ)/σ_y` with the dataset's training statistics
//!   ([`flapssm_wing::dataset::Dataset::standardization`]), pooled from `start_sample` on (published: the first 93
//!   samples dropped): per-output RMSE, overall `√mean(e²)`, 2.5/97.5 % intervals.
//! - Coefficients `C_F = F/(½ρSU_ref²)`, `C_M = M/(½ρc̄SU_ref²·1000)` per trajectory; the last
//!   full cycle from [`flapssm_wing::cycles::published_window`]; per-trajectory C_Fx/C_Fy RMSE
//!   over it; half-stroke averages and their errors (measured − predicted) with intervals.
//! - Control authority: [`flapssm_analysis::authority`] on (inputs, latent means of the first
//!   model with latent states) from `start_sample` on, every trajectory (training and test),
//!   period = the cycle duration.
//!
//! The first model is the one studied and the second its baseline: `rmse_ratio` is first /
//! second, as the paper's PR-SSM / LRQSM.

use std::path::{Path, PathBuf};

use flapssm_wing::cycles::published_window;
use flapssm_wing::dataset::{OUTPUT_NAMES, ValidDataset};
use serde::{Deserialize, Serialize};

use flapssm_analysis::authority::{
    AuthorityConfig, AuthoritySummary, AuthorityTrajectory, PeakTable, peak_table,
};
use flapssm_analysis::cycles_avg::CycleWindow;
use flapssm_analysis::metrics::{
    CoefficientScales, Histogram, PUBLISHED_START_SAMPLE, PooledErrors,
};
use flapssm_analysis::metrics::{coefficients_of, window_rmse};
use flapssm_analysis::plots::{authority as pa, errors as pe, wing3d};
use flapssm_analysis::stats::Interval;

use crate::error::{JobError, Result, analysis};
use crate::files::{write_json, write_text};
use crate::models::{LoadModel, ModelPrediction, predict_all};
use crate::paper_comparison::{ComparisonRow, compare, fig5_pairs};
use crate::progress::Progress;

mod figures;
mod html;
pub(crate) mod prepared;
mod tables;

use figures::{draw_fig3, draw_training, example_title, example_trajectories};
pub use html::versions;
use html::{ReportFigures, html_report};
use prepared::{ModelTables, Prepared, cycle_errors, pooled, rows, split_metrics};
use tables::{trajectories_csv, write_predictions};

/// Every file [`evaluate`] may write in its output folder (which are written depends on the
/// models and the sets); checked before any work by [`crate::files::check_output_dir`].
pub const EVALUATION_FILES: [&str; 17] = [
    "metrics.json",
    "report.html",
    "trajectories.csv",
    "predictions.npz",
    "authority_summary.json",
    "authority_summary.csv",
    "authority_peaks.csv",
    "fig2c_wing_motion.png",
    "fig3_time_histories.png",
    "fig4a_histograms_train.png",
    "fig4a_histograms_test.png",
    "fig4b_cycle_averages.png",
    "fig5a_hdr.png",
    "fig5a_scatter_x1.png",
    "fig5b_summary.png",
    "training_loss.png",
    "training_rmse.png",
];

/// Display names of the 7 inputs (dataset order).
pub const INPUT_LABELS: [&str; 7] = ["AoA", "|v|", "a_x", "a_y", "a_z", "dα/dt", "d²α/dt²"];
/// Display names of the 5 outputs as coefficients.
pub const COEFFICIENT_LABELS: [&str; 5] = ["C_Fx", "C_Fy", "C_Mx", "C_My", "C_Mz"];
/// Version of `metrics.json` ([`EvaluationReport`]): 2 holds any number of models.
pub const METRICS_VERSION: u32 = 2;

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

impl EvalOptions {
    /// Checks the settings that do not depend on the dataset (`start_sample` is checked against
    /// the dataset by [`evaluate`]).
    ///
    /// # Errors
    /// [`JobError::Setting`] for no particles, a level outside (0, 100), or authority settings
    /// out of range, named as the user gives them.
    pub fn check(&self) -> Result<()> {
        let bad = |name: &str, value: String, expected: &str| {
            Err(JobError::Setting {
                name: name.into(),
                value,
                expected: expected.into(),
            })
        };
        if self.particles == 0 {
            return bad("particles", "0".into(), "must be at least 1");
        }
        if !(self.level > 0.0 && self.level < 100.0) {
            return bad("level", self.level.to_string(), "must be in (0, 100) %");
        }
        let a = &self.authority;
        if a.num_lags == 0 || a.grid_points < 2 {
            return bad(
                "authority",
                format!("num_lags {}, grid_points {}", a.num_lags, a.grid_points),
                "num_lags ≥ 1 and grid_points ≥ 2",
            );
        }
        for (name, v) in [
            ("authority.max_lag_cycles", a.max_lag_cycles),
            ("authority.bandwidth", a.bandwidth),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(name, v.to_string(), "must be positive and finite");
            }
        }
        if !(a.hdr_mass > 0.0 && a.hdr_mass < 1.0) {
            return bad(
                "authority.hdr_mass",
                a.hdr_mass.to_string(),
                "must be in (0, 1)",
            );
        }
        Ok(())
    }
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
    /// Display name ("PR-SSM", "LRQSM", "ARX", …).
    pub model: String,
    /// File-safe identifier ("prssm", …).
    pub key: String,
    /// Training trajectories.
    pub train: SplitMetrics,
    /// Test trajectories (none when the dataset has no test part).
    pub test: Option<SplitMetrics>,
    /// Half-stroke-average error intervals over training and test together (as the paper).
    pub cycle_average_error_interval_all: Vec<Interval>,
}

/// How long one model took to predict one trajectory: the only machine-dependent numbers of
/// [`EvaluationReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PredictionTiming {
    /// The model's key.
    pub model: String,
    /// Median over trajectories of one prediction's wall time (ms, on one thread of the pool).
    pub median_ms: f64,
}

impl ModelMetrics {
    /// The test metrics, or the training metrics when there is no test set.
    pub fn test_or_train(&self) -> &SplitMetrics {
        self.test.as_ref().unwrap_or(&self.train)
    }
}

/// One model's results on one trajectory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryModelMetrics {
    /// The model's key.
    pub model: String,
    /// Last-cycle RMSE of [C_Fx, C_Fy].
    pub cycle_rmse_cf: [f64; 2],
    /// Overall standardized RMSE from `start_sample` on.
    pub overall_rmse: f64,
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
    /// Each model's results, in the evaluation's model order.
    pub models: Vec<TrajectoryModelMetrics>,
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
    /// [`METRICS_VERSION`].
    pub version: u32,
    /// ValidDataset description (file name or origin).
    pub dataset: String,
    /// Training trajectories.
    pub n_train: usize,
    /// Test trajectories.
    pub n_test: usize,
    /// Settings.
    pub options: EvalOptions,
    /// Each model's accuracy, in the order given.
    pub models: Vec<ModelMetrics>,
    /// Test RMSE ratio first / second model per output (training set when there is no test
    /// set; empty with one model).
    pub rmse_ratio: Vec<f64>,
    /// Per-trajectory results.
    pub trajectories: Vec<TrajectoryMetrics>,
    /// The pairs of Fig. 5 the paper reports, for the first model with latent states: AoA,
    /// a_x, dα/dt and d²α/dt² on the output states x1..x5, d²α/dt² and dα/dt on x7, a_y on
    /// x8, x10 and x12 (those within D_x); empty without a latent-state model.
    pub authority_findings: Vec<AuthorityFinding>,
    /// The Fig. 3 example trajectories (dataset indices): on the paper's own trajectories the
    /// paper's six, else test trajectories of distinct families.
    #[serde(default)]
    pub example_trajectories: Vec<usize>,
    /// Every endpoint of the paper beside this evaluation's ([`crate::paper_comparison`]).
    #[serde(default)]
    pub paper_comparison: Vec<ComparisonRow>,
    /// Prediction wall time per model (machine-dependent, unlike everything else here).
    #[serde(default)]
    pub prediction_timing: Vec<PredictionTiming>,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
}

impl EvaluationReport {
    /// The metrics of the model with `key`.
    pub fn model(&self, key: &str) -> Option<&ModelMetrics> {
        self.models.iter().find(|m| m.key == key)
    }
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
    /// Sections placed after the paper comparison (e.g. the rig check, [`crate::rig`]).
    pub extra_sections: Vec<flapssm_analysis::report::Section>,
}

/// Evaluates `models` on `ds` and writes into `out_dir`: `metrics.json`
/// ([`EvaluationReport`]), `trajectories.csv`, `predictions.npz`, with a latent-state model
/// `authority_summary.{json,csv}` and `authority_peaks.csv`, the figures
/// (`fig2c_wing_motion.png`, `fig3_time_histories.png`, `fig4a_histograms_{train,test}.png`,
/// `fig4b_cycle_averages.png`, with a latent-state model `fig5a_hdr.png`,
/// `fig5a_scatter_x1.png`, `fig5b_summary.png`, with a training history `training_*.png`) and
/// `report.html`. Every file is written atomically.
///
/// # Errors
/// No model, a dataset without outputs or training trajectories, models that do not fit it,
/// trajectories without a full stroke cycle, analysis and I/O errors — each naming its item.
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    ds: &ValidDataset,
    dataset_label: &str,
    models: &[&dyn LoadModel],
    opts: &EvalOptions,
    context: &ReportContext,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<EvaluationReport> {
    check(ds, models, opts)?;
    std::fs::create_dir_all(out_dir).map_err(|source| JobError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let mut predictions = Vec::with_capacity(models.len());
    for m in models {
        progress.start(&format!("predict {}", m.name()), ds.len() as u64);
        predictions.push(predict_all(*m, ds, progress)?);
        progress.finish("");
    }

    progress.start("analyse", 0);
    let prep = prepare(ds, &predictions)?;
    let n_train = ds.n_train.min(ds.len());
    let sets = Sets::new(&prep, n_train);
    let metrics = models
        .iter()
        .enumerate()
        .map(|(k, m)| model_metrics(m.name(), m.key(), k, &sets, opts))
        .collect::<Result<Vec<_>>>()?;
    let rmse_ratio = match &metrics[..] {
        [a, b, ..] => a
            .test_or_train()
            .rmse_standardized
            .iter()
            .zip(&b.test_or_train().rmse_standardized)
            .map(|(a, b)| a / b)
            .collect(),
        _ => Vec::new(),
    };
    let trajectories = trajectory_metrics(ds, models, &prep, n_train, opts)?;
    let latent = models.iter().position(|m| m.n_latent() > 0);
    let authority = latent
        .map(|k| authority(ds, &predictions[k], models[k].n_latent(), &prep, opts))
        .transpose()?;
    progress.finish("");

    progress.start("write outputs", 0);
    let mut files = Vec::new();
    let mut file = |name: &str| {
        files.push(name.to_string());
        out_dir.join(name)
    };
    if let Some(a) = &authority {
        a.write(
            &file("authority_summary.json"),
            &file("authority_summary.csv"),
            &file("authority_peaks.csv"),
        )?;
    }
    write_text(
        &file("trajectories.csv"),
        &trajectories_csv(models, &trajectories),
    )?;
    write_predictions(&file("predictions.npz"), ds, models, &predictions)?;
    let examples = example_trajectories(ds, opts.example_trajectories);
    let figures = draw_figures(
        ds,
        models,
        &prep,
        &sets,
        &trajectories,
        authority.as_ref(),
        opts,
        &examples,
        &mut file,
    )?;
    let mut report = EvaluationReport {
        version: METRICS_VERSION,
        dataset: dataset_label.to_string(),
        n_train,
        n_test: sets.test.len(),
        options: opts.clone(),
        models: metrics,
        rmse_ratio,
        trajectories,
        authority_findings: authority.map(|a| a.findings).unwrap_or_default(),
        example_trajectories: examples,
        paper_comparison: Vec::new(),
        prediction_timing: models
            .iter()
            .zip(&predictions)
            .filter_map(|(m, p)| {
                let wall: Vec<f64> = p.iter().map(|q| 1e3 * q.wall_s).collect();
                let median_ms = flapssm_analysis::stats::median(&wall).ok()?;
                Some(PredictionTiming {
                    model: m.key().into(),
                    median_ms,
                })
            })
            .collect(),
        files: {
            let mut f = files.clone();
            f.retain(|f| figures.written(f));
            f.push("metrics.json".into());
            f.push("report.html".into());
            f
        },
    };
    report.paper_comparison = compare(&report);
    write_json(&out_dir.join("metrics.json"), &report)?;
    let html = html_report(&report, context, figures, models);
    let p_html = out_dir.join("report.html");
    html.write(&p_html)
        .map_err(analysis(p_html.display().to_string()))?;
    progress.finish("");
    Ok(report)
}

/// Checks the inputs once, before any prediction.
fn check(ds: &ValidDataset, models: &[&dyn LoadModel], opts: &EvalOptions) -> Result<()> {
    opts.check()?;
    if !ds.has_outputs() {
        return Err(flapssm_wing::dataset::DatasetError::NoOutputs.into());
    }
    let n_train = ds.n_train.min(ds.len());
    if n_train == 0 {
        return Err(flapssm_wing::dataset::DatasetError::NoTrainingData { n_train }.into());
    }
    if models.is_empty() {
        return Err(JobError::Mismatch {
            what: "models to evaluate".into(),
            expected: "at least one".into(),
            found: "none".into(),
        });
    }
    let n = ds.n_samples();
    if opts.start_sample >= n {
        return Err(JobError::Mismatch {
            what: "start_sample".into(),
            expected: format!("fewer than the {n} samples per trajectory"),
            found: opts.start_sample.to_string(),
        });
    }
    Ok(())
}

/// Each trajectory's window and its measured and predicted tables (standardized and as
/// coefficients).
fn prepare(ds: &ValidDataset, predictions: &[Vec<ModelPrediction>]) -> Result<Vec<Prepared>> {
    let stats = ds.standardization()?;
    let (fluid, wing) = (&ds.meta.fluid, &ds.meta.wing);
    let z = |y: &[f64]| stats.normalize_y_table(y);
    let mut prep = Vec::with_capacity(ds.len());
    for (i, t) in ds.trajectories.iter().enumerate() {
        let what = format!("trajectory {i}");
        let stroke: Vec<f64> = t.euler_rad.iter().map(|e| e[0]).collect();
        let w = published_window(&stroke).map_err(|source| JobError::Cycle {
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
        let models = predictions
            .iter()
            .map(|p| {
                let p = &p[i];
                let std_c = p
                    .var
                    .as_ref()
                    .map(|var| coef(&var.iter().map(|v| v.max(0.0).sqrt()).collect::<Vec<_>>()))
                    .transpose()?;
                Ok(ModelTables {
                    z: z(&p.mean),
                    c: coef(&p.mean)?,
                    std_c,
                })
            })
            .collect::<Result<_>>()?;
        prep.push(Prepared {
            window,
            measured_z: z(measured),
            measured_c: coef(measured)?,
            models,
        });
    }
    Ok(prep)
}

/// The prepared trajectories as training, test and all.
struct Sets<'p> {
    train: Vec<&'p Prepared>,
    test: Vec<&'p Prepared>,
    all: Vec<&'p Prepared>,
}

impl<'p> Sets<'p> {
    fn new(prep: &'p [Prepared], n_train: usize) -> Self {
        Self {
            train: prep[..n_train].iter().collect(),
            test: prep[n_train..].iter().collect(),
            all: prep.iter().collect(),
        }
    }
}

fn model_metrics(
    name: &str,
    key: &str,
    k: usize,
    sets: &Sets<'_>,
    opts: &EvalOptions,
) -> Result<ModelMetrics> {
    Ok(ModelMetrics {
        model: name.into(),
        key: key.into(),
        train: split_metrics(&sets.train, k, opts, &format!("{name} training metrics"))?,
        test: if sets.test.is_empty() {
            None
        } else {
            Some(split_metrics(
                &sets.test,
                k,
                opts,
                &format!("{name} test metrics"),
            )?)
        },
        cycle_average_error_interval_all: cycle_errors(&sets.all, k)?
            .intervals(opts.level)
            .map_err(analysis(format!("{name} cycle averages")))?,
    })
}

fn trajectory_metrics(
    ds: &ValidDataset,
    models: &[&dyn LoadModel],
    prep: &[Prepared],
    n_train: usize,
    opts: &EvalOptions,
) -> Result<Vec<TrajectoryMetrics>> {
    let mut trajectories = Vec::with_capacity(ds.len());
    for (i, (t, p)) in ds.trajectories.iter().zip(prep).enumerate() {
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
            models: models
                .iter()
                .zip(&p.models)
                .map(|(m, q)| {
                    Ok(TrajectoryModelMetrics {
                        model: m.key().into(),
                        cycle_rmse_cf: cyc(&q.c)?,
                        overall_rmse: overall(&q.z)?,
                    })
                })
                .collect::<Result<_>>()?,
        });
    }
    Ok(trajectories)
}

/// The control-authority analysis of one model's latent states.
struct Authority {
    table: PeakTable,
    summary: AuthoritySummary,
    state_names: Vec<String>,
    input_names: Vec<String>,
    findings: Vec<AuthorityFinding>,
}

impl Authority {
    fn write(&self, summary_json: &Path, summary_csv: &Path, peaks_csv: &Path) -> Result<()> {
        self.summary
            .write_json(summary_json)
            .map_err(analysis(summary_json.display().to_string()))?;
        self.summary
            .write_csv(summary_csv)
            .map_err(analysis(summary_csv.display().to_string()))?;
        self.table
            .write_csv(peaks_csv, &self.state_names, &self.input_names)
            .map_err(analysis(peaks_csv.display().to_string()))
    }
}

/// Control authority on the latent means, every trajectory, transient dropped.
fn authority(
    ds: &ValidDataset,
    predictions: &[ModelPrediction],
    dx: usize,
    prep: &[Prepared],
    opts: &EvalOptions,
) -> Result<Authority> {
    let s0 = opts.start_sample;
    let auth_traj: Vec<AuthorityTrajectory<'_>> = ds
        .trajectories
        .iter()
        .zip(predictions)
        .zip(prep)
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
    let findings = fig5_pairs()
        .filter(|&(_, state)| state <= dx)
        .filter_map(|(label, state)| {
            let input = INPUT_LABELS.iter().position(|l| *l == label)?;
            let s = summary.pair(state - 1, input);
            Some(AuthorityFinding {
                input: input_names[input].clone(),
                state: state_names[state - 1].clone(),
                median_abs_r: s.median_abs_r,
                median_lag_cycles: s.median_lag_cycles,
                lag_iqr_cycles: s.lag_iqr_cycles,
                mode_lag_cycles: s.mode_lag_cycles,
                strong: s.strong,
            })
        })
        .collect();
    Ok(Authority {
        table,
        summary,
        state_names,
        input_names,
        findings,
    })
}

/// Draws every figure; `file` names (and records) each file.
#[allow(clippy::too_many_arguments)]
fn draw_figures(
    ds: &ValidDataset,
    models: &[&dyn LoadModel],
    prep: &[Prepared],
    sets: &Sets<'_>,
    trajectories: &[TrajectoryMetrics],
    authority: Option<&Authority>,
    opts: &EvalOptions,
    examples: &[usize],
    file: &mut dyn FnMut(&str) -> PathBuf,
) -> Result<ReportFigures> {
    let n = ds.n_samples();
    let wing = &ds.meta.wing;
    let labels: Vec<String> = examples
        .iter()
        .map(|&i| example_title(ds, i, &trajectories[i]))
        .collect();
    let f_2c = file("fig2c_wing_motion.png");
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
    let f_3 = file("fig3_time_histories.png");
    draw_fig3(&f_3, ds, models, prep, examples, &labels)?;

    let edges = Histogram::uniform_edges(-1.1, 1.1, 0.01);
    let out_names = OUTPUT_NAMES
        .iter()
        .map(|s| format!("{s}/σ"))
        .collect::<Vec<_>>();
    let out_refs: Vec<&str> = out_names.iter().map(String::as_str).collect();
    let mut f_4a = Vec::new();
    for (set, label) in [(&sets.train, "train"), (&sets.test, "test")] {
        if set.is_empty() {
            continue;
        }
        let path = file(&format!("fig4a_histograms_{label}.png"));
        let errors = (0..models.len())
            .map(|k| pooled(set, k, opts.start_sample))
            .collect::<Result<Vec<_>>>()?;
        let labels: Vec<String> = models
            .iter()
            .map(|m| format!("{} {label}", m.name()))
            .collect();
        let series: Vec<pe::ModelErrors<'_>> = labels
            .iter()
            .zip(&errors)
            .map(|(l, e)| pe::ModelErrors {
                label: l,
                errors: &e.errors,
            })
            .collect();
        pe::error_histograms(&path, &out_refs, &series, &edges, opts.level)
            .map_err(analysis("Fig. 4A"))?;
        f_4a.push(path);
    }
    let f_4b = file("fig4b_cycle_averages.png");
    let cycles = (0..models.len())
        .map(|k| cycle_errors(&sets.all, k))
        .collect::<Result<Vec<_>>>()?;
    let series: Vec<pe::ModelCycleAverages<'_>> = models
        .iter()
        .zip(&cycles)
        .map(|(m, c)| pe::ModelCycleAverages {
            label: m.name(),
            observed: &c.observed,
            error: &c.error,
        })
        .collect();
    pe::cycle_average_scatter(
        &f_4b,
        &COEFFICIENT_LABELS,
        &series,
        Some(&[0.75, 0.75, 2.0, 2.0, 2.0]),
        opts.level,
    )
    .map_err(analysis("Fig. 4B"))?;
    let fig5 = match authority {
        Some(a) => {
            let (f_5a, f_5s, f_5b) = (
                file("fig5a_hdr.png"),
                file("fig5a_scatter_x1.png"),
                file("fig5b_summary.png"),
            );
            pa::hdr_contours(&f_5a, &a.summary).map_err(analysis("Fig. 5Ai"))?;
            pa::pair_scatter(&f_5s, &a.table, &a.summary, 0).map_err(analysis("Fig. 5Aii"))?;
            pa::summary_grid(&f_5b, &a.summary).map_err(analysis("Fig. 5B"))?;
            Some((f_5a, f_5s, f_5b))
        }
        None => None,
    };
    let training = models
        .iter()
        .find_map(|m| m.training_history().map(|h| (m.name(), h)));
    let training = match training {
        Some((name, history)) => {
            let (f_loss, f_rmse) = (file("training_loss.png"), file("training_rmse.png"));
            draw_training(&f_loss, &f_rmse, name, history)?.then_some((f_loss, f_rmse))
        }
        None => None,
    };
    Ok(ReportFigures {
        f_2c,
        f_3,
        f_4a_train: f_4a.first().cloned(),
        f_4a_test: f_4a.get(1).cloned(),
        f_4b,
        fig5,
        training,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::Fit;
    use crate::models::arx::ArxSettings;
    use crate::models::lrqsm::LrqsmLoadModel;
    use crate::models::prssm::PrssmLoadModel;
    use crate::progress::NoProgress;
    use crate::test_data::tiny_dataset;
    use crate::train::{TrainingOptions, train_prssm};

    /// The pipeline's LRQSM errors agree with the qs crate's own RMSE (computed there from raw
    /// loads divided by σ), and its sums are consistent: overall² = mean of per-output RMSE²,
    /// ratio = PR-SSM / LRQSM, the windows are the published ones.
    #[test]
    fn metrics_agree_with_independent_computations() {
        let ds = tiny_dataset();
        let lrqsm =
            flapssm_qs::lrqsm::fit_dataset(&ds, Default::default(), &Default::default(), "tiny")
                .unwrap();
        let q =
            flapssm_qs::lrqsm::predict_dataset(&lrqsm, &ds, lrqsm.prediction_intercept).unwrap();
        let opts = TrainingOptions {
            dx: Some(5),
            inducing: Some(6),
            particles: Some(3),
            epochs: Some(1),
            val_fraction: 0.0,
            ..TrainingOptions::default()
        };
        let plan = opts.check().unwrap();
        let fit = train_prssm(ds.train(), &plan, None, None, None, &NoProgress, None).unwrap();
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
        let prssm = PrssmLoadModel::new(&fit.best, &ds, eo.particles, eo.seed).unwrap();
        let lq = LrqsmLoadModel::new(&lrqsm).unwrap();
        let arx = ArxSettings::default()
            .check()
            .unwrap()
            .fit(&ds, &NoProgress)
            .unwrap();
        let r = evaluate(
            &ds,
            "tiny",
            &[&prssm, &lq, &arx],
            &eo,
            &ReportContext::default(),
            &dir,
            &NoProgress,
        )
        .unwrap();
        assert_eq!(
            r.models.iter().map(|m| m.key.as_str()).collect::<Vec<_>>(),
            ["prssm", "lrqsm", "arx"]
        );
        let (rp, rl) = (r.model("prssm").unwrap(), r.model("lrqsm").unwrap());
        let lt = rl.test.as_ref().unwrap();
        let qt = q.rmse_test.as_ref().unwrap();
        for j in 0..5 {
            assert!((lt.rmse_standardized[j] - qt.standardized[j]).abs() < 1e-10);
            assert!(
                (rl.train.rmse_standardized[j] - q.rmse_train.as_ref().unwrap().standardized[j])
                    .abs()
                    < 1e-10
            );
        }
        let pt = rp.test.as_ref().unwrap();
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
        // 4 inputs on x1..x5; with D_x 5 there is no x7..x12.
        assert_eq!(r.authority_findings.len(), 20);
        // The paper beside us: each endpoint from the report's own numbers.
        let row = |prefix: &str| {
            r.paper_comparison
                .iter()
                .find(|c| c.endpoint.starts_with(prefix))
                .unwrap_or_else(|| panic!("no row {prefix}: {:#?}", r.paper_comparison))
        };
        let ex = &r.example_trajectories;
        assert!(!ex.is_empty() && ex.iter().all(|&i| i >= r.n_train));
        let cfx: Vec<f64> = ex
            .iter()
            .map(|&i| r.trajectories[i].models[0].cycle_rmse_cf[0])
            .collect();
        let (lo, hi) = (
            cfx.iter().copied().fold(f64::INFINITY, f64::min),
            cfx.iter().copied().fold(0.0, f64::max),
        );
        let fig3 = row("C_Fx RMSE, PR-SSM");
        assert!(
            fig3.flapssm.starts_with(&format!("{lo:.2}–{hi:.2} (")),
            "{fig3:?}"
        );
        assert_eq!(fig3.paper, "0.11–0.21");
        let bound = pt
            .error_interval
            .iter()
            .map(|i| i.lo.abs().max(i.hi.abs()))
            .fold(0.0, f64::max);
        let fig4a = row("95 % error bounds over the 5 outputs (σ), PR-SSM, test");
        assert!(
            fig4a.flapssm.ends_with(&format!("–{bound:.2}")),
            "{fig4a:?}"
        );
        let c = &rl.cycle_average_error_interval_all[1];
        let fig4b = row("95 % interval of half-stroke-average C_Fy errors, LRQSM");
        assert!(
            fig4b
                .flapssm
                .starts_with(&format!("[{:.2}, {:.2}]", c.lo, c.hi))
        );
        assert_eq!(fig4b.paper, "[-0.20, 0.20]");
        for prefix in [
            "C_Fy RMSE, LRQSM",
            "C_Fx RMSE ratio LRQSM / PR-SSM",
            "C_Fy RMSE ratio LRQSM / PR-SSM",
            "95 % error bounds over the 5 outputs (σ), LRQSM, training",
            "AoA → the outputs",
            "a_x → the outputs",
            "d²α/dt² → the outputs",
            "prediction of one trajectory, PR-SSM",
        ] {
            row(prefix);
        }
        assert!(
            r.paper_comparison
                .iter()
                .all(|c| !c.endpoint.contains("x7"))
        );
        assert!(
            r.prediction_timing
                .iter()
                .any(|t| t.model == "prssm" && t.median_ms > 0.0)
        );
        let written: EvaluationReport =
            serde_json::from_slice(&std::fs::read(dir.join("metrics.json")).unwrap()).unwrap();
        assert_eq!(written.paper_comparison, r.paper_comparison);
        for f in &r.files {
            assert!(dir.join(f).exists(), "{f}");
        }
        let csv = std::fs::read_to_string(dir.join("trajectories.csv")).unwrap();
        assert!(csv.lines().next().unwrap().ends_with(
            "prssm_rmse_cfx,prssm_rmse_cfy,lrqsm_rmse_cfx,lrqsm_rmse_cfy,arx_rmse_cfx,arx_rmse_cfy,\
             prssm_overall_rmse_std,lrqsm_overall_rmse_std,arx_overall_rmse_std"
        ));
        std::fs::remove_dir_all(&dir).ok();

        // One model without latent states: no authority analysis, no Fig. 5, no ratio.
        let dir = std::env::temp_dir().join(format!("flapssm-one-model-{}", std::process::id()));
        let r = evaluate(
            &ds,
            "tiny",
            &[&arx],
            &eo,
            &ReportContext::default(),
            &dir,
            &NoProgress,
        )
        .unwrap();
        assert!(r.authority_findings.is_empty() && r.rmse_ratio.is_empty());
        assert!(
            !r.files
                .iter()
                .any(|f| f.starts_with("fig5") || f.starts_with("authority"))
        );
        for f in &r.files {
            assert!(dir.join(f).exists(), "{f}");
        }
        std::fs::remove_dir_all(&dir).ok();
        let e = evaluate(
            &ds,
            "tiny",
            &[],
            &eo,
            &ReportContext::default(),
            &dir,
            &NoProgress,
        )
        .unwrap_err();
        assert!(e.to_string().contains("models to evaluate"), "{e}");
    }

    #[test]
    fn evaluation_settings_are_checked_and_named() {
        let err = |o: EvalOptions| o.check().unwrap_err().to_string();
        assert!(EvalOptions::default().check().is_ok());
        let e = err(EvalOptions {
            particles: 0,
            ..EvalOptions::default()
        });
        assert!(e.contains("setting particles = 0"), "{e}");
        let e = err(EvalOptions {
            level: 100.0,
            ..EvalOptions::default()
        });
        assert!(e.contains("setting level = 100"), "{e}");
        let e = err(EvalOptions {
            authority: AuthorityConfig {
                hdr_mass: 1.5,
                ..AuthorityConfig::default()
            },
            ..EvalOptions::default()
        });
        assert!(e.contains("authority.hdr_mass"), "{e}");
    }
}
