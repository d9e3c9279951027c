//! What an evaluation writes: its settings, the metrics of each model and trajectory, the
//! authority findings and the report's added text; the file names it may write.

use flapssm_analysis::bootstrap::PairedDifference;

use super::controls::{AuthorityControl, ControlLags};
use serde::{Deserialize, Serialize};

use flapssm_analysis::authority::AuthorityConfig;
use flapssm_analysis::hidden::HiddenAuthority;
use flapssm_analysis::metrics::PUBLISHED_START_SAMPLE;
use flapssm_analysis::stats::Interval;

use crate::error::{JobError, Result};

/// Every file [`evaluate`](super::evaluate) may write in its output folder (which are written depends on the
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

/// Settings of [`evaluate`](super::evaluate).
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
    /// the dataset by [`evaluate`](super::evaluate)).
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

/// The authority of one input on the hidden subspace beyond the outputs
/// ([`flapssm_analysis::hidden`]): the paper's latent rows (x7, x8, x10, x12) in a form no
/// change of basis alters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HiddenFinding {
    /// Input name.
    pub input: String,
    /// What the paper says of this input on single hidden states (empty where nothing).
    pub paper: String,
    /// The figures: median R and lag, the chance level, the excess over chance.
    pub subspace: HiddenAuthority,
}

/// Everything [`evaluate`](super::evaluate) computes (written as `metrics.json`).
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
    /// Every input's authority on the hidden subspace of that model (D_x > 5), with its chance
    /// level; empty otherwise.
    #[serde(default)]
    pub hidden_authority: Vec<HiddenFinding>,
    /// The Fig. 3 example trajectories (dataset indices): on the paper's own trajectories the
    /// paper's six, else test trajectories of distinct families.
    #[serde(default)]
    pub example_trajectories: Vec<usize>,
    /// Every endpoint of the paper beside this evaluation's ([`crate::evaluate::paper`]).
    #[serde(default)]
    pub paper_comparison: Vec<ComparisonRow>,
    /// Prediction wall time per model (machine-dependent, unlike everything else here).
    #[serde(default)]
    pub prediction_timing: Vec<PredictionTiming>,
    /// The first model against each other on the test trajectories (training without a test
    /// set): per output the RMSE difference with its paired bootstrap interval.
    #[serde(default)]
    pub comparisons: Vec<PairedComparison>,
    /// The Fig. 5 findings on the outputs beside their controls (the dataset's loads, a
    /// memoryless wing's, the rig stand-in's); empty without the rig's reference or a
    /// latent-state model.
    #[serde(default)]
    pub authority_controls: Vec<AuthorityControl>,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
}

impl EvaluationReport {
    /// The metrics of the model with `key`.
    pub fn model(&self, key: &str) -> Option<&ModelMetrics> {
        self.models.iter().find(|m| m.key == key)
    }
}

/// Model `a` against model `b`: per output `RMSE_a − RMSE_b` (σ units, pooled from
/// `start_sample`) with its paired bootstrap interval over trajectories
/// ([`flapssm_analysis::bootstrap`], [`COMPARISON_DRAWS`] draws at the options' level and
/// seed); negative means `a` is more accurate, "significant" that the interval excludes 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairedComparison {
    /// Key of model `a` (the first model).
    pub a: String,
    /// Key of model `b`.
    pub b: String,
    /// Trajectories resampled (`test`, or `train` without a test set).
    pub split: String,
    /// One per output.
    pub outputs: Vec<PairedDifference>,
}

/// Bootstrap draws of each [`PairedComparison`].
pub const COMPARISON_DRAWS: usize = 2000;

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
    /// The lag statistics of the Fig. 5 controls ([`super::controls`]), when the rig's
    /// reference was given.
    pub control_lags: Option<ControlLags>,
}

/// Where flapssm's value lies against the paper's range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Relation {
    /// Inside the paper's range.
    Inside,
    /// Overlapping it, partly outside.
    Overlaps,
    /// Entirely below it.
    Below,
    /// Entirely above it.
    Above,
}

impl Relation {
    /// flapssm's range `[lo, hi]` against the paper's.
    pub fn of(ours: [f64; 2], paper: [f64; 2]) -> Self {
        if ours[1] < paper[0] {
            Relation::Below
        } else if ours[0] > paper[1] {
            Relation::Above
        } else if ours[0] >= paper[0] && ours[1] <= paper[1] {
            Relation::Inside
        } else {
            Relation::Overlaps
        }
    }

    /// Lower-case words.
    pub fn words(self) -> &'static str {
        match self {
            Relation::Inside => "inside",
            Relation::Overlaps => "overlaps",
            Relation::Below => "below",
            Relation::Above => "above",
        }
    }
}

/// One endpoint, the paper's value beside flapssm's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComparisonRow {
    /// The endpoint in words.
    pub endpoint: String,
    /// Figure and line of [`super::paper::PAPER_TEX`].
    pub source: String,
    /// The paper's value as it states it.
    pub paper: String,
    /// flapssm's value, same measure.
    pub flapssm: String,
    /// flapssm's range against the paper's, where both are ranges.
    pub relation: Option<Relation>,
}
